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

__all__ = ["number", "numbers", "string", "matrix", "refuse_unknown",
           "joint_type_and_pitch"]

def number(v, source: str, field: str, **where) -> float:
    """A finite number (not a bool)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ParseError(f"expected a number, got {v!r}", file=source, field=field, **where)
    x = float(v)
    if not math.isfinite(x):
        raise ParseError(f"expected a finite number, got {v!r}", file=source, field=field,
                         **where)
    return x


def numbers(v, n: int, source: str, field: str, scalar_ok: bool = True):
    """A list of ``n`` finite numbers, or (``scalar_ok``) one number returned as a float."""
    if scalar_ok and not isinstance(v, list):
        return number(v, source, field)
    if not isinstance(v, list) or len(v) != n:
        what = f"a number or a list of {n} numbers" if scalar_ok else f"a list of {n} numbers"
        raise ParseError(f"expected {what}, got {v!r}", file=source, field=field)
    return [number(x, source, f"{field}[{i}]") for i, x in enumerate(v)]


def string(v, source: str, field: str) -> str:
    """A string."""
    if not isinstance(v, str):
        raise ParseError(f"expected a string, got {v!r}", file=source, field=field)
    return v


def matrix(v, source: str, field: str, shape: tuple[int, int]) -> np.ndarray:
    """A finite array of ``shape`` (e.g. a 4x4 pose)."""
    try:
        a = np.array(v, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParseError(f"expected a {shape[0]}x{shape[1]} array of numbers", file=source,
                         field=field) from exc
    if a.shape != shape or not np.all(np.isfinite(a)):
        raise ParseError(f"expected a finite {shape[0]}x{shape[1]} array, got shape {a.shape}",
                         file=source, field=field)
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
    if kind not in JOINT_KINDS:
        raise ParseError(f"unknown joint type {kind!r}; expected revolute, prismatic or screw",
                         file=source, field=f"{where}.type")
    pitch = number(entry.get("pitch", 0.0), source, f"{where}.pitch")
    if kind == "screw" and pitch == 0.0:
        raise ParseError("a screw joint needs a non-zero pitch", file=source,
                         field=f"{where}.pitch")
    if kind != "screw" and pitch != 0.0:
        raise ParseError(f"pitch is only for screw joints, not {kind} (write type = \"screw\")",
                         file=source, field=f"{where}.pitch")
    return kind, pitch
