"""Coordinated moves: every axis of a move starts and finishes together.

The thesis's galil_control.m (Vibhute App. D.5) sets each axis's speed to ``|Δ| / 4`` counts/s
(clamped to [10, max]) with fixed accelerations: the axes cruise for about 4 s but their
ramps differ, and clamped axes finish early or late. :func:`coordinated_move_plan` makes the
axes' profiles similar instead: with ``Δ_i`` the counts axis ``i`` moves, every moving axis
gets speed ``v_i = s |Δ_i|`` and acceleration = deceleration ``a_i = r |Δ_i|``, one ``s`` and
one ``r`` for the move, as large as the axes' limits allow::

    s = min_i v_max,i / |Δ_i|,     r = min_i a_max,i / |Δ_i|

so each axis's trapezoid is the same time profile scaled by ``|Δ_i|`` — they start together
(one ``BG``), reach cruise together and finish together, and the slowest axis (relative to
its limits) moves at its limit.

Rounding: speeds and accelerations are sent with the Galil client's 4 decimals
(:func:`kinestat.devices.galil.GalilClient.move_absolute`), each rounded UP to 1e-4 so that
no axis exceeds the plan's time by more than ~1e-4 / v_i of it; a controller that only
takes whole counts/s would make an axis's duration differ by at most ``0.5 / v_i`` of the
move's (the log records what was sent). Axes that do not move keep their maximum speed and
acceleration.

:func:`move_plan` chooses between this (``"coordinated"``, the default of ``kinestat
control``), the thesis's rule (``"thesis"``: :func:`kinestat.devices.galil.thesis_move_plan`
without its +5-count nudge, which would leave the axis 5 counts from the command) and the
profile's maxima (``"max"``).
"""

from __future__ import annotations

import math
from typing import Literal, get_args

import numpy as np

from kinestat.devices.galil import MovePlan, thesis_move_plan
from kinestat.errors import InputError
from kinestat.robots.puma762.axes import as_axes6

__all__ = ["MoveRule", "MOVE_RULES", "coordinated_move_plan", "move_plan", "limit_accel"]

MoveRule = Literal["coordinated", "thesis", "max"]
"""How a move's per-axis speeds are chosen (see the module docstring)."""
MOVE_RULES: tuple[str, ...] = get_args(MoveRule)


def _up4(x: np.ndarray) -> np.ndarray:
    return np.ceil(np.asarray(x) * 1e4 - 1e-6) / 1e4


def coordinated_move_plan(current, target, speed_max, accel_max) -> MovePlan:
    """Per-axis ``SP`` and ``AC``/``DC`` so that the axes of the move ``current → target``
    (counts A..F) start and finish together (module docstring).

    >>> p = coordinated_move_plan([0] * 6, [1000, 500, 0, 0, 0, 0], [100] * 6, [1000] * 6)
    >>> p.speed[:2].tolist(), p.accel[:2].tolist()
    ([100.0, 50.0], [1000.0, 500.0])
    """
    cur = as_axes6(current, "coordinated_move_plan current")
    tgt = as_axes6(target, "coordinated_move_plan target")
    vmax = np.broadcast_to(np.asarray(speed_max, dtype=float), (6,))
    amax = np.broadcast_to(np.asarray(accel_max, dtype=float), (6,))
    if np.any(vmax <= 0) or np.any(amax <= 0):
        raise InputError("coordinated_move_plan: speed and acceleration limits must be > 0")
    d = np.abs(tgt - cur)
    moving = d > 0
    speed, accel = vmax.astype(float).copy(), amax.astype(float).copy()
    if np.any(moving):
        s = float(np.min(vmax[moving] / d[moving]))
        r = float(np.min(amax[moving] / d[moving]))
        speed[moving] = np.minimum(_up4(s * d[moving]), vmax[moving])
        accel[moving] = np.minimum(_up4(r * d[moving]), amax[moving])
    return MovePlan(np.rint(tgt).astype(np.int64), speed, accel, accel.copy())


def move_plan(rule: MoveRule, current, target, speed_max, accel_max) -> MovePlan:
    """The plan of one move under ``rule`` ("coordinated", "thesis" or "max")."""
    if rule == "coordinated":
        return coordinated_move_plan(current, target, speed_max, accel_max)
    if rule == "thesis":
        return thesis_move_plan(current, target, nudge=False)
    if rule == "max":
        acc = np.broadcast_to(np.asarray(accel_max, dtype=float), (6,)).copy()
        return MovePlan(np.rint(as_axes6(target, "move target")).astype(np.int64),
                        np.broadcast_to(np.asarray(speed_max, dtype=float), (6,)).copy(), acc,
                        acc.copy())
    raise InputError(f"move rule must be one of {MOVE_RULES}, got {rule!r}")


def limit_accel(plan: MovePlan, current, rate: float | None) -> MovePlan:
    """``plan`` with each moving axis's acceleration and deceleration at most ``rate`` times
    its travel (``rate`` in 1/s², counts/s² per count moved; rounded up to 1e-4 as above).
    Under a coordinated plan every point of the arm then accelerates at most ``rate`` times its
    own displacement: a controller that must not shake what the arm carries gives the rate
    its largest acceleration over the move's largest displacement. ``None``: ``plan`` as it is.

    >>> p = coordinated_move_plan([0] * 6, [1000, 500, 0, 0, 0, 0], [100] * 6, [1000] * 6)
    >>> limit_accel(p, [0] * 6, 0.25).accel[:3].tolist()
    [250.0, 125.0, 1000.0]
    """
    if rate is None:
        return plan
    r = float(rate)
    if not (math.isfinite(r) and r > 0.0):
        raise InputError(f"limit_accel: the acceleration rate must be a positive number of "
                         f"1/s², got {rate!r}")
    d = np.abs(np.asarray(plan.target, dtype=float) - as_axes6(current, "limit_accel current"))
    cap = np.where(d > 0, _up4(r * d), np.inf)
    return plan._replace(accel=np.minimum(np.asarray(plan.accel, dtype=float), cap),
                         decel=np.minimum(np.asarray(plan.decel, dtype=float), cap))
