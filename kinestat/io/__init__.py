"""Files at the edges: DISP card decks (:mod:`kinestat.io.disp_deck`), model and platform files.

The DISP deck API is re-exported here; the other formats are imported from their modules.
"""

from __future__ import annotations

from kinestat.io.disp_deck import (
    DeckJoint,
    DispDeck,
    OperatorCommand,
    deck_warnings,
    embedded_deck,
    list_embedded_decks,
    parse_deck,
    read_deck,
    write_deck,
)

__all__ = [
    "DeckJoint",
    "DispDeck",
    "OperatorCommand",
    "deck_warnings",
    "embedded_deck",
    "list_embedded_decks",
    "parse_deck",
    "read_deck",
    "write_deck",
]
