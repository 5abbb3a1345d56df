"""The DISP program (Nadkarni 1977, App. I): deck -> model -> run -> record.

- :mod:`.deck` — the chain and hand of a deck, its stages, :func:`run_deck` for every MS,
  :func:`disp_options` (DISP's behaviour by default)
- :mod:`.record` — the JSON records (:func:`deck_json`, :func:`result_record`)

Layer 3: imports io, serial, mechanism, spatial. See docs/guidance.md and docs/disp-decks.md.
"""

from __future__ import annotations

from kinestat.disp.deck import (
    DeckRun,
    deck_initial_hand,
    deck_joints,
    deck_model,
    deck_screws,
    deck_stages,
    disp_options,
    run_deck,
)
from kinestat.disp.record import deck_json, result_record

__all__ = [
    "DeckRun",
    "deck_initial_hand",
    "deck_joints",
    "deck_json",
    "deck_model",
    "deck_screws",
    "deck_stages",
    "disp_options",
    "result_record",
    "run_deck",
]
