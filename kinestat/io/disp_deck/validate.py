"""The rules a DISP deck obeys (Nadkarni App. I, Table A1-1), in one place.

Each ``*_problem`` function returns why a value is invalid, or None; the data model
(:mod:`.model`) raises it as an :class:`~kinestat.errors.InputError`, the reader
(:mod:`.reader`) as a :class:`~kinestat.errors.ParseError` naming the card and columns.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.joints import PRISMATIC_PITCH_THRESHOLD

#: Data sets present in a deck for each analysis type MS (Nadkarni Table A1-1).
SETS_BY_MS: dict[int, tuple[str, ...]] = {
    0: ("ONE", "TWO", "FOUR", "FIVE"),
    1: ("ONE", "TWO"),
    2: ("ONE", "FOUR", "FIVE"),
    3: ("ONE", "TWO", "FOUR", "FIVE"),
    4: ("ONE", "TWO", "FOUR", "FIVE"),
    5: ("ONE", "THREE", "FOUR", "FIVE"),
    6: ("ONE", "TWO", "FOUR", "FIVE"),
}

_MS_MEANING = {
    0: "displacement analysis type II (screw path)",
    1: "screw axes between consecutive body positions",
    2: "mechanism position data in the global frame (TRANSM)",
    3: "MS = 1 and MS = 2 together",
    4: "displacement analysis type III (hand point on a straight line)",
    5: "displacement analysis type IV (operator commands)",
    6: "displacement analysis type I (general, Ex. 4)",
}

#: DISP's limit on the number of joints in SET FOUR (Nadkarni App. I).
MAX_JOINTS = 15
#: DISP's limit on the number of body positions in SET TWO (Nadkarni App. I).
MAX_POSITIONS = 99
#: The pitch the thesis's decks write for a prismatic joint (any PH > 1e5 means prismatic).
PRISMATIC_MARKER = 999999.0

_GUIDANCE_MS = (0, 4, 5, 6)  # analyses that move a six-joint manipulator
_HAND7_MS = (0, 4, 6)  # may give the first hand position by the seventh joint (all-zero cards)
_I5_RANGE = (-9999, 99999)
_POINT_NAMES = ("origin", "point on +z", "point on +x side")
_FIVE_NAMES = ("origin of x*(1)", "point on +z of joint 1", "point on the normal a1 (+x)")


def _finite_float(value, what: str) -> float:
    if isinstance(value, (str, bytes, bool)):
        raise InputError(f"{what} must be a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise InputError(f"{what} must be finite, got {x!r}")
    return x + 0.0  # -0.0 -> 0.0


def _int_value(value, what: str) -> int:
    if isinstance(value, bool):
        raise InputError(f"{what} must be an integer, got {value!r}")
    try:
        return operator.index(value)
    except TypeError:
        raise InputError(f"{what} must be an integer, got {value!r}") from None


def _pitch_problem(pitch: float) -> str | None:
    if pitch < -PRISMATIC_PITCH_THRESHOLD:
        return (
            f"pitch {pitch:g} is neither a screw pitch (|PH| <= 1e5) nor DISP's prismatic "
            "marker (PH > 1e5): write 999999.00 for a prismatic joint"
        )
    return None


def _direction_problem(d: Sequence[float]) -> str | None:
    if max(abs(c) for c in d) == 0.0:
        return "direction DC is the zero vector: give the direction R of the motion"
    return None


def _frame_problem(points: np.ndarray) -> str | None:
    """Why three points (origin, +z point, +x-side point) do not fix a frame, or None."""
    scale = float(np.max(np.abs(points)))
    if scale == 0.0:
        return "all three points are zero"
    q = points / scale
    z = q[1] - q[0]
    nz = float(np.linalg.norm(z))
    if nz <= 1e-12:  # distances below ~1e4 rounding errors of the largest coordinate
        return "the point on +z coincides with the origin point"
    if float(np.linalg.norm(np.cross(z / nz, q[2] - q[0]))) <= 1e-12:
        return "the third point lies on the z axis (the three points are collinear)"
    return None


def _np_problem(ms: int, np_: int) -> str | None:
    lo, hi = _I5_RANGE
    if not lo <= np_ <= hi:
        return f"NP = {np_} does not fit the I5 field ({lo}..{hi})"
    if ms == 5 and np_ < 1:
        return f"NP = {np_}: MS = 5 needs NP >= 1 operator commands (SET THREE cards)"
    if ms in (0, 1, 3, 4, 6):
        what = "body positions" if ms in (1, 3) else "hand positions (initial and targets)"
        if np_ < 2:
            return f"NP = {np_}: MS = {ms} needs NP >= 2 {what}"
        if np_ > MAX_POSITIONS:
            return f"NP = {np_} exceeds DISP's limit of {MAX_POSITIONS} positions"
    return None


def _it_problem(it: int) -> str | None:
    if not 0 <= it <= _I5_RANGE[1]:
        return f"IT = {it}: the number of steps must be 0 (automatic) .. {_I5_RANGE[1]}"
    return None


def _io_problem(io: int) -> str | None:
    if io not in (0, 1):
        return f"IO = {io}: the information level must be 0 (complete) or 1 (restricted)"
    return None


def _ms_problem(ms: int) -> str | None:
    if ms not in SETS_BY_MS:
        return f"MS = {ms} is not an analysis type: use 0..6 (Table A1-1)"
    return None


def _n_problem(ms: int, n: int, hand7: bool) -> str | None:
    if not 1 <= n <= MAX_JOINTS:
        return f"N = {n}: the number of joints must be 1..{MAX_JOINTS} (DISP's limit)"
    if ms == 5 and n < 7:
        return (
            f"N = {n}: MS = 5 has no SET TWO, so the hand must be defined by a seventh "
            "(imaginary) joint: give N >= 7"
        )
    if hand7 and n < 7:
        return (
            f"N = {n}: SET TWO's first three cards are zero, which means 'initial hand given "
            "by the seventh joint': give N >= 7 or the first hand position's points"
        )
    if ms in _GUIDANCE_MS and n < 6:
        return f"N = {n}: MS = {ms} moves a six-joint manipulator: give N >= 6"
    return None


def _raise_if(problem: str | None) -> None:
    if problem:
        raise InputError(problem)
