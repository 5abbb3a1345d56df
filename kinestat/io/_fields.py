"""Checked fields of parsed TOML/JSON documents, shared by the model, platform and axes files.

Each helper takes the value, the ``source`` (file name) and the ``field`` it came from, and
raises :class:`~kinestat.errors.ParseError` naming both; extra keyword arguments (``card=``)
are passed on to the error.
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.errors import ParseError
from kinestat.mechanism.joints import JOINT_KINDS

__all__ = ["number", "numbers", "string", "choice", "short_repr", "matrix", "refuse_unknown",
           "joint_type_and_pitch", "MAX_MAGNITUDE"]

MAX_MAGNITUDE = 1e12
"""Largest magnitude a number in these files may have. No length (mm), angle, pitch,
stiffness (N/mm) or count in a model, platform, axes or calibration file comes near it;
beyond ~1e154 a product of two overflows to inf in the kinematics (a NumPy warning, then an
error far from the field), so a larger value is refused here, naming its field."""


def _too_big(v: int) -> str:
    """The message for an integer too large for a float (without echoing its digits)."""
    return f"expected a finite number, got an integer of {len(str(abs(v)))} digits (too large)"


def number(v, source: str, field: str, **where) -> float:
    """A finite number (not a bool); an integer too large for a float is refused, not a crash.

    >>> number(10 ** 400, "a.toml", "x")
    Traceback (most recent call last):
    kinestat.errors.ParseError: a.toml, field x: expected a finite number, got an integer of \
401 digits (too large)
    >>> number(1.7e308, "a.toml", "x")
    Traceback (most recent call last):
    kinestat.errors.ParseError: a.toml, field x: 1.7e+308 is implausibly large (the limit is \
1e+12 in the file's units)
    """
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ParseError(f"expected a number, got {short_repr(v)}", file=source, field=field,
                         **where)
    try:
        x = float(v)
    except OverflowError:
        raise ParseError(_too_big(v), file=source, field=field, **where) from None
    if not math.isfinite(x):
        raise ParseError(f"expected a finite number, got {v!r}", file=source, field=field,
                         **where)
    if abs(x) > MAX_MAGNITUDE:
        raise ParseError(f"{x:.3g} is implausibly large (the limit is {MAX_MAGNITUDE:.0e} in "
                         "the file's units)", file=source, field=field, **where)
    return x


def short_repr(v, limit: int = 80) -> str:
    """``repr(v)`` cut to ``limit`` characters (a fuzzed value can be megabytes long)."""
    try:
        text = repr(v)
    except (ValueError, RecursionError):  # a huge integer, a deeply nested list
        return f"a {type(v).__name__}"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def numbers(v, n: int, source: str, field: str, scalar_ok: bool = True):
    """A list of ``n`` finite numbers, or (``scalar_ok``) one number returned as a float."""
    if scalar_ok and not isinstance(v, list):
        return number(v, source, field)
    if not isinstance(v, list) or len(v) != n:
        what = f"a number or a list of {n} numbers" if scalar_ok else f"a list of {n} numbers"
        raise ParseError(f"expected {what}, got {short_repr(v)}", file=source, field=field)
    return [number(x, source, f"{field}[{i}]") for i, x in enumerate(v)]


def string(v, source: str, field: str) -> str:
    """A string."""
    if not isinstance(v, str):
        raise ParseError(f"expected a string, got {short_repr(v)}", file=source, field=field)
    return v


def choice(v, allowed, source: str, field: str, what: str | None = None) -> str:
    """One of the strings ``allowed`` (anything else, a list or a table included, is refused).

    >>> choice([], ("deg", "rad"), "a.toml", "angle_unit")
    Traceback (most recent call last):
    kinestat.errors.ParseError: a.toml, field angle_unit: angle_unit must be one of \
['deg', 'rad'], got []
    """
    if not isinstance(v, str) or v not in allowed:
        raise ParseError(f"{what or field} must be one of {sorted(allowed)}, got {short_repr(v)}",
                         file=source, field=field)
    return v


def unit(doc: dict, key: str, source: str, example: str, allowed=None) -> str:
    """The unit named by ``key``: required (units are never guessed), a string, and one of
    ``allowed`` when given. ``example`` is the line to add, quoted in the error.

    >>> unit({"angle_unit": "rad"}, "angle_unit", "a.toml", 'angle_unit = "deg"', ("deg", "rad"))
    'rad'
    >>> unit({}, "length_unit", "a.toml", 'length_unit = "mm"')
    Traceback (most recent call last):
    ...
    kinestat.errors.ParseError: a.toml, field length_unit: missing 'length_unit': units are never \
guessed; add a line such as length_unit = "mm"
    """
    if key not in doc:
        raise ParseError(f"missing {key!r}: units are never guessed; add a line such as {example}",
                         file=source, field=key)
    return string(doc[key], source, key) if allowed is None else choice(doc[key], allowed,
                                                                        source, key)


def matrix(v, source: str, field: str, shape: tuple[int, int]) -> np.ndarray:
    """A finite array of ``shape`` (e.g. a 4x4 pose)."""
    try:
        a = np.array(v, dtype=float)
    except (TypeError, ValueError, OverflowError, RecursionError) as exc:
        raise ParseError(f"expected a {shape[0]}x{shape[1]} array of numbers", file=source,
                         field=field) from exc
    if a.shape != shape or not np.all(np.isfinite(a)):
        raise ParseError(f"expected a finite {shape[0]}x{shape[1]} array, got shape {a.shape}",
                         file=source, field=field)
    if np.any(np.abs(a) > MAX_MAGNITUDE):
        raise ParseError(f"an entry is implausibly large (the limit is {MAX_MAGNITUDE:.0e} in "
                         "the file's units)", file=source, field=field)
    return a


def refuse_unknown(table: dict, known, source: str, what: str = "keys", **where) -> None:
    """Refuse keys of ``table`` outside ``known`` (a typo must not be silently ignored)."""
    unknown = set(table) - set(known)
    if unknown:
        raise ParseError(f"unknown {what} {sorted(unknown)}; expected some of {sorted(known)}",
                         file=source, **where)


def joint_type_and_pitch(entry: dict, source: str, where: str) -> tuple[str, float]:
    """``type`` (default revolute) and ``pitch`` (default 0) of a joint/axis table.

    A screw joint needs a non-zero pitch (length per radian); the others take none.
    """
    kind = entry.get("type", "revolute")
    if not isinstance(kind, str) or kind not in JOINT_KINDS:
        raise ParseError(f"unknown joint type {short_repr(kind)}; expected revolute, prismatic or "
                         "screw", file=source, field=f"{where}.type")
    pitch = number(entry.get("pitch", 0.0), source, f"{where}.pitch")
    if kind == "screw" and pitch == 0.0:
        raise ParseError("a screw joint needs a non-zero pitch", file=source,
                         field=f"{where}.pitch")
    if kind != "screw" and pitch != 0.0:
        raise ParseError(f"pitch is only for screw joints, not {kind} (write type = \"screw\")",
                         file=source, field=f"{where}.pitch")
    return kind, pitch
