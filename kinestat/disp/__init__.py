"""The DISP program (Nadkarni 1977, App. I): deck -> model -> run -> record.

- :mod:`.deck` — the chain and hand of a deck, its stages, :func:`run_deck` for every MS,
  :func:`disp_options` (DISP's behaviour by default)
- :mod:`.record` — the JSON records (:func:`deck_json`, :func:`result_record`)
- :mod:`.steps` — DISP's inferred step count when IT = 0 (:func:`disp_step_count`)

Layer 3: imports io, serial, mechanism, spatial. See docs/guidance.md and docs/disp-decks.md.
"""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'deck': [
            'DeckRun', 'deck_initial_hand', 'deck_joints', 'deck_model', 'deck_screws',
            'deck_stages', 'disp_options', 'run_deck',
        ],
        'record': ['deck_json', 'result_record'],
        'steps': ['disp_step_count', 'stage_motion'],
    },
)
