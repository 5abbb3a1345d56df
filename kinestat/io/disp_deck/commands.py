"""SET THREE operator commands (MS = 5; Nadkarni App. I, eqs. 4-21, 4-22): the data type and
the one parser/validator shared by decks and ``kinestat guide --command``."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from kinestat.errors import InputError
from kinestat.io.disp_deck.validate import _direction_problem, _finite_float, _int_value


@dataclass(frozen=True)
class OperatorCommand:
    """One SET THREE card (MS = 5): NTY, DC(1..3), DD, THA (Nadkarni App. I, eqs. 4-21, 4-22).

    ``nty`` 0: ``direction`` R is in the global frame; 1: in the frame fixed on the hand.
    ``distance`` is d (deck length unit), ``angle_deg`` is θ in degrees.
    """

    nty: int
    direction: tuple[float, float, float]
    distance: float
    angle_deg: float

    def __post_init__(self) -> None:
        nty = _int_value(self.nty, "command NTY")
        if nty not in (0, 1):
            raise InputError(
                f"command NTY must be 0 (global frame) or 1 (hand frame), got {nty}"
            )
        object.__setattr__(self, "nty", nty)
        try:
            comps = tuple(self.direction)
        except TypeError:
            raise InputError(
                f"command direction must be three numbers, got {self.direction!r}"
            ) from None
        if len(comps) != 3:
            raise InputError(f"command direction must have 3 components, got {len(comps)}")
        d = tuple(_finite_float(c, "command direction") for c in comps)
        problem = _direction_problem(d)
        if problem:
            raise InputError(f"command {problem}")
        object.__setattr__(self, "direction", d)
        object.__setattr__(self, "distance", _finite_float(self.distance, "command distance"))
        object.__setattr__(self, "angle_deg", _finite_float(self.angle_deg, "command angle"))

    @property
    def frame(self) -> str:
        """'global' (NTY = 0) or 'hand' (NTY = 1)."""
        return "global" if self.nty == 0 else "hand"

    @property
    def angle(self) -> float:
        """θ in radians."""
        return math.radians(self.angle_deg)


_KEYS = {"frame": "frame", "nty": "frame", "dir": "dir", "direction": "dir", "d": "d",
         "distance": "d", "angle": "angle", "angle_deg": "angle"}
_SPLIT = re.compile(r",(?=\s*[A-Za-z_]+\s*=)")


def parse_number(text: str, what: str) -> float:
    """A finite number from ``text``; ``InputError`` naming ``what`` otherwise."""
    try:
        x = float(text)
    except ValueError:
        raise InputError(f"{what}: {text!r} is not a number") from None
    if not math.isfinite(x):
        raise InputError(f"{what}: must be finite, got {text!r}")
    return x


def parse_key_values(text: str, what: str, keys: dict[str, str] = _KEYS) -> dict[str, str]:
    """``"k=v, k=v, …"`` (values may hold commas) → ``{canonical key: value}``; ``keys`` maps
    each accepted spelling (lower case) to its canonical key."""
    out: dict[str, str] = {}
    for part in _SPLIT.split(text.strip()):
        if "=" not in part:
            raise InputError(f"{what} {text!r}: expected key=value items, got {part!r}")
        k, v = (s.strip() for s in part.split("=", 1))
        key = keys.get(k.lower())
        if key is None:
            raise InputError(f"{what} {text!r}: unknown key {k!r}; use "
                             f"{', '.join(sorted(set(keys.values())))}")
        out[key] = v
    return out


def parse_operator_command(text: str, what: str = "command") -> OperatorCommand:
    """One operator command (type IV, eqs. 4-21, 4-22) from text, validated by
    :class:`OperatorCommand`: either ``frame=global|hand, dir=x,y,z, d=…, angle=…`` (angle in
    degrees, d and angle default to 0) or the six numbers of a SET THREE card
    ``NTY DCx DCy DCz DD THA`` (blank- or comma-separated).

    >>> parse_operator_command("frame=hand, dir=1,0,0, d=-1, angle=15")
    OperatorCommand(nty=1, direction=(1.0, 0.0, 0.0), distance=-1.0, angle_deg=15.0)
    >>> parse_operator_command("0 0 0 1 4 -30").frame
    'global'
    """
    if not isinstance(text, str):
        raise InputError(f"{what} must be text, got {type(text).__name__}")
    if "=" not in text:
        vals = [parse_number(t, what) for t in text.replace(",", " ").split()]
        if len(vals) != 6 or vals[0] not in (0.0, 1.0):
            raise InputError(f"{what} {text!r}: expected 'NTY DCx DCy DCz DD THA' with NTY 0 "
                             "or 1, or key=value items")
        return OperatorCommand(int(vals[0]), tuple(vals[1:4]), vals[4], vals[5])
    kv = parse_key_values(text, what)
    frame = kv.get("frame", "global").lower()
    nty = {"global": 0, "hand": 1, "0": 0, "1": 1}.get(frame)
    if nty is None:
        raise InputError(f"{what} {text!r}: frame must be 'global' or 'hand', got {frame!r}")
    if "dir" not in kv:
        raise InputError(f"{what} {text!r}: give the direction, e.g. dir=0,0,1")
    direction = [parse_number(t, f"{what} dir") for t in kv["dir"].split(",") if t.strip()]
    if len(direction) != 3:
        raise InputError(f"{what} {text!r}: dir needs 3 comma-separated numbers, got "
                         f"{kv['dir']!r}")
    try:
        distance = parse_number(kv.get("d", "0"), f"{what} d")
        return OperatorCommand(nty, tuple(direction), distance,
                               parse_number(kv.get("angle", "0"), f"{what} angle"))
    except InputError as exc:
        raise InputError(f"{what} {text!r}: {exc}") from None
