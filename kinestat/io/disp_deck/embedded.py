"""The decks of the thesis's seven numerical illustrations (Nadkarni 1977, Appendix II)."""

from __future__ import annotations

from importlib import resources

from kinestat.errors import InputError
from kinestat.io.disp_deck.model import DispDeck
from kinestat.io.disp_deck.reader import parse_deck

_EMBEDDED: dict[str, str] = {
    "illustration1": "MS = 1: screw axes between three body positions (Table A2-1)",
    "illustration2": "MS = 2: manipulator configuration #1 in the global frame (Table A2-3)",
    "illustration3": "MS = 3: Illustrations 1 and 2 in one run (Table A2-4, expanded)",
    "illustration4": "MS = 0: screw-path guidance of configuration #1 (Table A2-5, expanded)",
    "illustration5": "MS = 4: straight-line guidance of configuration #2 (Table A2-8, as printed)",
    "illustration5-corrected": "Illustration 5 with a7 = 1.00 (Table A2-7) for the printed 0.00",
    "illustration5-published": "Illustration 5 as Table A2-9 implies: b2 = (15, -10, 20), IT = 27",
    "illustration6": "MS = 5: two operator commands (Table A2-10, expanded, as printed)",
    "illustration6-corrected": "Illustration 6 with a7 = 1.00 (Table A2-7) for the printed 0.00",
    "illustration7": "MS = 6: general guidance to a target (Table A2-12, expanded; NP = 2)",
    "illustration7-corrected": "Illustration 7 with a7 = 1.00 (Table A2-7) for the printed 0.00",
}


def _decks_dir():
    return resources.files("kinestat").joinpath("data", "decks")


def list_embedded_decks() -> dict[str, str]:
    """Names of the embedded thesis decks, each with a one-line description."""
    present = {
        p.name.removesuffix(".dat") for p in _decks_dir().iterdir() if p.name.endswith(".dat")
    }
    return {name: desc for name, desc in _EMBEDDED.items() if name in present}


def _embedded_name(name: str) -> str:
    if not isinstance(name, str):
        raise InputError(f"an embedded deck name is a string, got {type(name).__name__}")
    key = name.strip().lower().removesuffix(".dat")
    if key not in _EMBEDDED:
        raise InputError(
            f"no embedded DISP deck named {name!r}; available: {', '.join(_EMBEDDED)}"
        )
    return key


def embedded_deck_text(name: str) -> str:
    """The card images of an embedded deck (e.g. ``"illustration5"``), as stored."""
    key = _embedded_name(name)
    return _decks_dir().joinpath(f"{key}.dat").read_text(encoding="ascii")


def embedded_deck(name: str) -> DispDeck:
    """Load an embedded thesis deck: ``"illustration1"`` … ``"illustration7"`` (Nadkarni
    App. II) or a ``"-corrected"``/``"-published"`` variant (see :func:`list_embedded_decks`)."""
    key = _embedded_name(name)
    return parse_deck(embedded_deck_text(key), source=f"kinestat/data/decks/{key}.dat")
