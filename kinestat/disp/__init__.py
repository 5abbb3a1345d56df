"""The DISP program (Nadkarni 1977, App. I): deck -> model -> run -> record.

- :mod:`.deck` — the chain and hand of a deck, its stages, :func:`run_deck` for every MS,
  :func:`disp_options` (DISP's behaviour by default)
- :mod:`.record` — the JSON records (:func:`deck_json`, :func:`result_record`)

Layer 3: imports io, serial, mechanism, spatial. See docs/guidance.md and docs/disp-decks.md.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
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

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "DeckRun": ("kinestat.disp.deck", "DeckRun"),
    "deck_initial_hand": ("kinestat.disp.deck", "deck_initial_hand"),
    "deck_joints": ("kinestat.disp.deck", "deck_joints"),
    "deck_model": ("kinestat.disp.deck", "deck_model"),
    "deck_screws": ("kinestat.disp.deck", "deck_screws"),
    "deck_stages": ("kinestat.disp.deck", "deck_stages"),
    "disp_options": ("kinestat.disp.deck", "disp_options"),
    "run_deck": ("kinestat.disp.deck", "run_deck"),
    "deck_json": ("kinestat.disp.record", "deck_json"),
    "result_record": ("kinestat.disp.record", "result_record"),
}

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


def __getattr__(name: str) -> Any:
    """Load a public name's module on first use (PEP 562): importing the package stays cheap."""
    where = _LAZY.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = importlib.import_module(where[0])
    value = module if where[1] is None else getattr(module, where[1])
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
