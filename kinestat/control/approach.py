"""The approach to the start pose: a move longer than the envelope's per-command step is split
into a sequence of joint-space commands, each within the step and the axis limits.

From the home position (``kinestat home``: axes 0°, 90°, 90°, 0°, 0°, 0°) the thesis's start
pose is up to ~120° away on an axis, four times the envelope's 30° per command. The approach
interpolates the axis counts linearly (a straight line in joint space, which stays inside the
axis limits' box) and cuts it into ``n`` equal commands, ``n`` chosen so that every axis, and
axis 5's MOTOR step with the axis 4 → 5 compensation the motion controller adds
(Vibhute App. D.9), stays within the tuning's ``approach_step_fraction``
(:class:`~kinestat.control.tuning.Tuning`) of the limit. Every command is then checked by
:func:`kinestat.control.envelope.check_command` (limits, step) against the one before it;
the device side checks the sent counts again and verifies each move by read-back.

The joint-space path is NOT checked for collisions (the controller does not know the
workpiece): approach from a pose where the straight joint-space path to the start pose is
clear, as the thesis's operator did.
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.control.envelope import Envelope, check_command
from kinestat.control.model import ControlModel
from kinestat.control.tuning import TUNING, Tuning
from kinestat.robots.puma762.axes import round_half_away

__all__ = ["approach_waypoints", "check_approach"]

def approach_waypoints(envelope: Envelope, model: ControlModel, counts_now,
                       counts_goal, tuning: Tuning = TUNING) -> np.ndarray:
    """The approach's commands, shape (n, 6) whole axis counts, the last one ``counts_goal``.

    ``n`` = ceil(largest step / (``tuning.approach_step_fraction`` · max_joint_step_deg)),
    with axis 5's step counted as |Δ5| + |coupling|·|Δ4| (degrees); ``n`` = 1 for a short move.

    >>> from kinestat.control.model import ControlModel
    >>> from kinestat.parallel.platform import special_6_6
    >>> m = ControlModel(platform=special_6_6(), mount=np.eye(4),
    ...                  tool_point_6=np.array([0.0, 0.0, 235.0]))
    >>> now = np.zeros(6, dtype=np.int64)
    >>> goal = np.round(np.array([40, 0, 0, 0, 0, 0]) / m.axis_deg_per_count).astype(np.int64)
    >>> approach_waypoints(Envelope(), m, now, goal).shape
    (3, 6)
    """
    now = np.asarray(counts_now, dtype=np.int64)
    goal = np.asarray(counts_goal, dtype=np.int64)
    res = np.asarray(model.axis_deg_per_count, dtype=float)
    step_deg = np.abs(goal - now) * res
    step_deg[4] += abs(float(model.coupling)) * step_deg[3] * res[4] / res[3]
    per = tuning.approach_step_fraction * envelope.max_joint_step_deg
    n = max(1, math.ceil(float(np.max(step_deg)) / per - 1e-12))
    s = np.arange(1, n + 1, dtype=float)[:, None] / n
    wps = round_half_away(now + s * (goal - now)).astype(np.int64)
    wps[-1] = goal
    return wps


def check_approach(envelope: Envelope, model: ControlModel, counts_now,
                   waypoints) -> list[str]:
    """Violations of the approach: each command against the axis limits and against the one
    before it (the per-command step), as ``"approach k/n: …"``."""
    res = np.asarray(model.axis_deg_per_count, dtype=float)
    prev = np.asarray(counts_now, dtype=float) * res
    out: list[str] = []
    n = len(waypoints)
    for k, wp in enumerate(waypoints, 1):
        deg = np.asarray(wp, dtype=float) * res
        out += [f"approach {k}/{n}: {v}" for v in check_command(envelope, model, deg, prev, None)]
        prev = deg
    return out
