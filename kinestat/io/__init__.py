"""Files at the edges, and model loading. The model layers below never read files.

- :mod:`~kinestat.io.library` — ``load``/``list_models`` (embedded models or TOML files) and the
  embedded 2011 prototype platform (:func:`~kinestat.io.library.prototype`).
- :mod:`~kinestat.io.model_toml` — TOML model files (read, write, round trip).
- :mod:`~kinestat.io.platform_toml` — TOML platform files.
- :mod:`~kinestat.io.axes_file` — axes files (joint axes in the world frame, for dh-from-axes).
- :mod:`~kinestat.io.urdf` — URDF export and import of serial chains.
- :mod:`~kinestat.io.posefile` — pose files (JSON, TOML or plain numbers).
- :mod:`~kinestat.io.disp_deck` — DISP card decks (Nadkarni 1977).
- :mod:`~kinestat.io.textfile` — the text reader and atomic writer every format uses.
- :mod:`~kinestat.io.jsonable` — numpy results to JSON-ready values.
- ``kinestat.io._fields`` — checked fields of parsed TOML/JSON documents (private).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
    from kinestat.io.axes_file import loads_axes, read_axes_file
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
    from kinestat.io.library import list_models, load, prototype
    from kinestat.io.model_toml import dumps_model, loads_model, read_model, write_model
    from kinestat.io.platform_toml import (
        dumps_platform,
        loads_platform,
        read_platform,
        write_platform,
    )
    from kinestat.io.posefile import read_pose_file
    from kinestat.io.urdf import from_urdf, read_urdf, to_urdf

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "loads_axes": ("kinestat.io.axes_file", "loads_axes"),
    "read_axes_file": ("kinestat.io.axes_file", "read_axes_file"),
    "DeckJoint": ("kinestat.io.disp_deck", "DeckJoint"),
    "DispDeck": ("kinestat.io.disp_deck", "DispDeck"),
    "OperatorCommand": ("kinestat.io.disp_deck", "OperatorCommand"),
    "deck_warnings": ("kinestat.io.disp_deck", "deck_warnings"),
    "embedded_deck": ("kinestat.io.disp_deck", "embedded_deck"),
    "list_embedded_decks": ("kinestat.io.disp_deck", "list_embedded_decks"),
    "parse_deck": ("kinestat.io.disp_deck", "parse_deck"),
    "read_deck": ("kinestat.io.disp_deck", "read_deck"),
    "write_deck": ("kinestat.io.disp_deck", "write_deck"),
    "list_models": ("kinestat.io.library", "list_models"),
    "load": ("kinestat.io.library", "load"),
    "prototype": ("kinestat.io.library", "prototype"),
    "dumps_model": ("kinestat.io.model_toml", "dumps_model"),
    "loads_model": ("kinestat.io.model_toml", "loads_model"),
    "read_model": ("kinestat.io.model_toml", "read_model"),
    "write_model": ("kinestat.io.model_toml", "write_model"),
    "dumps_platform": ("kinestat.io.platform_toml", "dumps_platform"),
    "loads_platform": ("kinestat.io.platform_toml", "loads_platform"),
    "read_platform": ("kinestat.io.platform_toml", "read_platform"),
    "write_platform": ("kinestat.io.platform_toml", "write_platform"),
    "read_pose_file": ("kinestat.io.posefile", "read_pose_file"),
    "from_urdf": ("kinestat.io.urdf", "from_urdf"),
    "read_urdf": ("kinestat.io.urdf", "read_urdf"),
    "to_urdf": ("kinestat.io.urdf", "to_urdf"),
}

__all__ = [
    "DeckJoint",
    "DispDeck",
    "OperatorCommand",
    "deck_warnings",
    "dumps_model",
    "dumps_platform",
    "embedded_deck",
    "from_urdf",
    "list_embedded_decks",
    "list_models",
    "load",
    "loads_axes",
    "loads_model",
    "loads_platform",
    "parse_deck",
    "prototype",
    "read_axes_file",
    "read_deck",
    "read_model",
    "read_platform",
    "read_pose_file",
    "read_urdf",
    "to_urdf",
    "write_deck",
    "write_model",
    "write_platform",
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
