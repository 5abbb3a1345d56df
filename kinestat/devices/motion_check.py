"""After a move: do the encoders read what was commanded? (Checked before any ``DP``.)

A move is verified against the read-back positions (``TP``) before the axis-5 encoder is
redefined (``DP``, the thesis's axis 4 -> 5 procedure, Vibhute App. D.9). A disagreement is a
fault — a stale reply taken for a position, a lost command, a stalled axis — and stops the run;
redefining the encoder would hide it for good.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from kinestat.errors import DeviceError
from kinestat.robots.puma762.axes import AXES

__all__ = ["POSITION_TOLERANCE_COUNTS", "check_arrival"]

POSITION_TOLERANCE_COUNTS = 3
"""Largest |read-back − commanded| per axis after a completed move, encoder counts. A DMC ends a
point-to-point move on its target within the servo's following error (a count or two when
tuned); 3 counts is 0.004–0.04° depending on the axis."""


def check_arrival(commanded: Any, actual: Any, tolerance: float = POSITION_TOLERANCE_COUNTS,
                  what: str = "move") -> None:
    """Raise :class:`DeviceError` naming the axes whose read-back differs from the command by
    more than ``tolerance`` counts.

    >>> check_arrival([0, 10, 0, 0, 0, 0], [0, 12, 0, 0, 0, 0])
    >>> try:
    ...     check_arrival([0, 10, 0, 0, 0, 0], [0, 20, 0, 0, 0, 0])
    ... except DeviceError as exc:
    ...     print(str(exc)[:69])
    after the move the encoders disagree with the command: axis B read 20
    """
    c = np.asarray(commanded, dtype=float).reshape(6)
    a = np.asarray(actual, dtype=float).reshape(6)
    bad = [k for k in range(6) if not abs(a[k] - c[k]) <= tolerance]
    if bad:
        parts = ", ".join(f"axis {AXES[k]} read {a[k]:.0f}, commanded {c[k]:.0f}" for k in bad)
        raise DeviceError(f"after the {what} the encoders disagree with the command: {parts} "
                          f"(tolerance {tolerance:g} counts); not redefining any encoder (DP), "
                          "stopping")
