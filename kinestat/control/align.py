"""The press's align turn: S6 onto the measured force about the tool point, damped where a
turn overshot and capped per cycle (:func:`kinestat.control.controller.decide`).

Pure functions of vectors; rotation vectors in radians, fixed frame.
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.control.cycle import cross3

__all__ = ["MAX_ALIGN_TURN_DEG", "OVERSHOOT_RATIO", "MIN_ALIGN_GAIN", "turn_vector",
           "align_gain"]


def turn_vector(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation vector (3,) (radians) of the smallest rotation taking unit ``a`` onto
    unit ``b`` (zero when they are parallel)."""
    axis = cross3(a, b)
    s = float(np.linalg.norm(axis))
    if s < 1e-15:
        return np.zeros(3)
    return axis * (math.atan2(s, float(a @ b)) / s)


MAX_ALIGN_TURN_DEG = 20.0
"""The largest align turn of S6 in one cycle (degrees): a workpiece met far off the tool axis is
turned onto in steps (a 40° turn at once moves the wrist beyond the envelope's 30° per
command). The default plane's first turn, 13.5° at a light first contact, is made at once."""
OVERSHOOT_RATIO = 0.5
"""An align turn overshot when the next misalignment points back against it by more than this
fraction of the turn (:func:`align_gain`)."""
MIN_ALIGN_GAIN = 0.125
"""The smallest fraction of the misalignment an align turn makes (three halvings)."""


def align_gain(gain: float, last_turn, misalignment) -> float:
    """The fraction of the misalignment ``misalignment`` (rotation vector from S6 onto the
    measured force, radians) that the next align turn makes, after the turn ``last_turn``
    (rotation vector, or None when the last move was not an align turn) made with ``gain``.

    On a plane a turn of S6 about the tool point onto the force lands on it: the normal does
    not move. On a frictionless curved surface of curvature κ the turn δ also slides the free
    tip across the surface by about B δ (the platform's soft mode), where the normal differs by
    κ B δ; the whole turn then lands κ B e past the normal, and for κ B ≥ 1 the turns alternate
    for good (a frictionless R = 200 mm cylinder at 4 N: ±2.35° a cycle, docs/control.md
    "The press on a curved workpiece"). The turn that lands on the normal is e / (1 + κ B).
    Without measuring κ B: a turn overshot when the new misalignment points back along it by
    more than ``OVERSHOOT_RATIO`` of the turn (κ B > ½ at the whole turn); the gain then halves
    (down to ``MIN_ALIGN_GAIN``), otherwise it grows back by a quarter (up to 1).

    >>> align_gain(1.0, [0.0, 0.0, 0.04], [0.0, 0.0, -0.04])   # overshot by the whole turn
    0.5
    >>> align_gain(0.5, [0.0, 0.0, 0.04], [0.0, 0.0, 0.01])    # short of it: grows back
    0.625
    >>> align_gain(1.0, None, [0.0, 0.0, 0.04])                 # no turn before
    1.0
    """
    if last_turn is None:
        return float(gain)
    t = np.asarray(last_turn, dtype=float)
    size = float(np.linalg.norm(t))
    if not size > 0.0:
        return float(gain)
    back = -float(np.asarray(misalignment, dtype=float) @ t) / size
    if back > OVERSHOOT_RATIO * size:
        return max(0.5 * float(gain), MIN_ALIGN_GAIN)
    return min(1.25 * float(gain), 1.0)
