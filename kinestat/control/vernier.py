"""Robot axis counts and the vernier: joint angles from counts and back, and the search among
the count vectors next to an ideal one for the tool point nearest a target (Vibhute 2011 §4;
see :mod:`kinestat.control.controller`'s docstring for why: one count is ~0.02 mm at the tool,
0.2 N of force on the platform; the search resolves the target to ~0.1 µm).

For the thesis's PUMA 762 the search runs compiled
(:func:`kinestat.serial.puma762._cycle_kernels.grid_nearest`, :func:`vernier_pick`); any other
arm takes the NumPy formulation (:func:`vernier_costs`, :func:`vernier_generic`), which is also
the reference the compiled search is tested against.
"""

from __future__ import annotations

import itertools
import math
import weakref
from typing import TYPE_CHECKING

import numpy as np

from kinestat.control._cycle_kernels import puma_counts_kernel, vernier_tables_kernel
from kinestat.control.arm import Puma762Arm
from kinestat.control.model import ControlModel
from kinestat.hardware.puma762_axes import round_half_away
from kinestat.serial.puma762._cycle_kernels import grid_nearest
from kinestat.serial.puma762.params import AXIS_OFFSET

if TYPE_CHECKING:
    from kinestat.control.controller import Target

__all__ = ["AXIS_OFFSETS", "OFFSETS", "VERNIER_SCALES", "ZERO_OFFSETS", "axis5_residual",
           "axis_counts_to_q", "q_to_axis_counts", "vernier_costs", "vernier_generic",
           "vernier_pick", "vernier_tables", "vernier_tables_one", "puma_move_one"]


def axis_counts_to_q(model: ControlModel, counts) -> np.ndarray:
    """Joint angles (radians) from robot axis counts (``axis = counts · resolution``)."""
    deg = np.asarray(counts, dtype=float) * model.axis_deg_per_count
    return model.arm.q_from_axis(np.radians(deg))


def q_to_axis_counts(model: ControlModel, axis_rad) -> np.ndarray:
    return round_half_away(np.degrees(axis_rad) / model.axis_deg_per_count)


def axis5_residual(model: ControlModel, counts: np.ndarray, counts_now: np.ndarray) -> np.ndarray:
    """Axis-5 counts left over by the 4 → 5 compensation (physical − commanded target)."""
    kappa = model.coupling * (counts[..., 3] - counts_now[3])
    return round_half_away(-kappa) + kappa


# Vernier candidates: ±4 counts on axes 1-3 (they move the tool point along S6 by ~1-15 µm per
# count, so their combinations resolve ~0.1 µm), ±1 on the wrist axes 4-5, axis 6 as is (it
# turns the tool about its own axis).
OFFSETS = np.array([(a, b, c, d, e, 0) for a, b, c in itertools.product(range(-4, 5), repeat=3)
                     for d, e in itertools.product((-1, 0, 1), repeat=2)], dtype=np.int64)
#: the same grid per axis (axes 1-3, 4, 5; axis 6 as is), in the order of OFFSETS' rows
AXIS_OFFSETS = (np.arange(-4, 5), np.arange(-4, 5), np.arange(-4, 5), np.arange(-1, 2),
                 np.arange(-1, 2))
ZERO_OFFSETS = tuple(np.zeros(1, dtype=np.int64) for _ in range(5))
#: the vernier's cost scales: 1 µm along S6, 0.05 mm across it, 0.01° of tilt
VERNIER_SCALES = (1e-3, 0.05, math.radians(0.01))


def grid_rows(offsets) -> tuple[np.ndarray, int]:
    """The count offsets of :func:`vernier_tables`' rows (axes 1-3's values in the first
    rows, the wrist's n4·n5 combinations in the last) and the grid's centre index; made once
    per offsets tuple."""
    got = _GRID_ROWS_CACHE.get(id(offsets))
    if got is None:
        n4, n5 = len(offsets[3]), len(offsets[4])
        rows = max(len(o) for o in offsets[:3]) + n4 * n5
        off = np.zeros((rows, 6), dtype=np.int64)
        for j in range(3):
            off[:len(offsets[j]), j] = offsets[j]
        off[rows - n4 * n5:, 3] = np.repeat(offsets[3], n5)
        off[rows - n4 * n5:, 4] = np.tile(offsets[4], n4)
        centre = 0
        for o in offsets:
            centre = centre * len(o) + int(np.flatnonzero(o == 0)[0])
        got = _GRID_ROWS_CACHE[id(offsets)] = (off, centre)
    return got


_GRID_ROWS_CACHE: dict[int, tuple[np.ndarray, int]] = {}


def vernier_tables(model: ControlModel, c0: np.ndarray, counts_now, offsets) -> tuple:
    """cos/sin of the joint angles of the vernier's grid around the counts ``c0`` (axes 1-3,
    4; axis 5 for each axis-4 value, with the axis-5 rounding the 4 → 5 compensation leaves;
    axis 6 as is), computed as :func:`axis_counts_to_q` computes them for the whole grid."""
    n4, n5 = len(offsets[3]), len(offsets[4])
    off, _ = grid_rows(offsets)
    cand = c0 + off
    phys = cand.astype(float)
    phys[:, 4] += axis5_residual(model, cand, np.asarray(counts_now))
    q = axis_counts_to_q(model, phys)
    cs = np.stack([np.cos(q), np.sin(q)], axis=-1)  # (rows, 6, 2)
    w = cs[len(off) - n4 * n5:]
    return (np.ascontiguousarray(cs[:len(offsets[0]), 0]),
            np.ascontiguousarray(cs[:len(offsets[1]), 1]),
            np.ascontiguousarray(cs[:len(offsets[2]), 2]),
            np.ascontiguousarray(w[::n5, 3]),
            np.ascontiguousarray(w[:, 4].reshape(n4, n5, 2)),
            np.ascontiguousarray(cs[0, 5]))


_AXIS_OFFSET = np.array(AXIS_OFFSET)  # writeable: the kernel compiles for one array type


def vernier_tables_one(model: ControlModel, c0: np.ndarray, counts_now, offsets) -> tuple:
    """:func:`vernier_tables` for the PUMA 762's axis conventions, compiled
    (:func:`kinestat.control._cycle_kernels.vernier_tables_kernel`: the same operations in the
    same order; equal to the NumPy tables where the kernel's cos/sin are NumPy's, as on the
    reference machine, and to the last bit otherwise)."""
    off, _ = grid_rows(offsets)
    return vernier_tables_kernel(np.asarray(c0, dtype=np.int64), off, len(offsets[0]),
                                 len(offsets[1]), len(offsets[2]), len(offsets[3]),
                                 len(offsets[4]), float(counts_now[3]), model.coupling,
                                 _resolution(model), _AXIS_OFFSET)


def _resolution(model: ControlModel) -> np.ndarray:
    """``model.axis_deg_per_count`` as a writeable C array (the kernel's one signature)."""
    r = model.axis_deg_per_count
    return r if r.flags.writeable and r.flags.c_contiguous else np.array(r, dtype=float)


def vernier_pick(model: ControlModel, target: Target, c0: np.ndarray, counts_now,
                  offsets) -> tuple[int, float]:
    """The index (in the grid ``offsets``' row order, :data:`OFFSETS` for the full grid) of
    the count vector whose tool point best realises ``target`` and its offset along S6 (mm):
    the compiled grid search :func:`kinestat.serial.puma762._cycle_kernels.grid_nearest` on
    the compiled tables (:func:`vernier_tables_one`)."""
    _, centre = grid_rows(offsets)
    p6, tp, ts = (np.array(v, dtype=float) for v in (model.tool_point_6, target.tool_point,
                                                      target.s6))  # writeable, C order
    k, along, _ = grid_nearest(*vernier_tables_one(model, c0, counts_now, offsets), p6, tp, ts,
                               *VERNIER_SCALES, centre)
    return int(k), float(along)


_LIMITS_RAD: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _limits_rad(model: ControlModel) -> tuple[np.ndarray, np.ndarray]:
    """The model's axis limits in radians, (lower (6,), upper (6,)), made once per model (its
    limits are frozen and checked by :class:`ControlModel`)."""
    got = _LIMITS_RAD.get(model)
    if got is None:
        L = np.asarray(model.limits_deg, dtype=float)
        got = _LIMITS_RAD[model] = (np.ascontiguousarray(np.radians(L[:, 0])),
                                    np.ascontiguousarray(np.radians(L[:, 1])))
    return got


def puma_move_one(model: ControlModel, target: Target, q_now, counts_now,
                  vernier: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The thesis's PUMA 762 moved onto ``target`` in one compiled call
    (:func:`kinestat.control._cycle_kernels.puma_counts_kernel`): ``(counts, q, F_6T)``, the
    axis counts :func:`kinestat.control.controller._solve_counts` chooses (with the vernier
    when asked), their joint angles (:func:`axis_counts_to_q`) and the flange pose. None
    where the reverse analysis or the selection fails (the caller's NumPy path then raises
    its error) and for any other arm. Equal to the three calls it replaces where the kernel's
    cos and sin are NumPy's (as on the reference machine), and to the last bits otherwise."""
    if type(model.arm) is not Puma762Arm:  # the thesis's arm only (its kernels)
        return None
    lo, hi = _limits_rad(model)
    offsets = AXIS_OFFSETS if vernier else ZERO_OFFSETS
    off, centre = grid_rows(offsets)
    counts = np.empty(6, dtype=np.int64)
    q_new = np.empty(6)
    T = np.empty((4, 4))
    p6, tp, ts, ta, q = (np.array(v, dtype=float) for v in (
        model.tool_point_6, target.tool_point, target.s6, target.a67, q_now))
    ok, _ = puma_counts_kernel(tp, ts, ta, p6, q, _AXIS_OFFSET, lo, hi, _resolution(model),
                               float(model.coupling), float(counts_now[3]), off,
                               len(offsets[0]), len(offsets[1]), len(offsets[2]),
                               len(offsets[3]), len(offsets[4]), centre, *VERNIER_SCALES,
                               counts, q_new, T)
    return (counts, q_new, T) if ok else None


def vernier_costs(model: ControlModel, target: Target, c0, counts_now,
                  vernier: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The candidates ``c0 + OFFSETS`` (or ``c0`` alone), their cost and offset along S6 (mm),
    every candidate through the arm's forward analysis (NumPy)."""
    c0 = np.asarray(c0)
    cand = c0 + OFFSETS if vernier else c0[None, :]
    phys = cand.astype(float)
    phys[:, 4] += axis5_residual(model, cand, np.asarray(counts_now))
    fwd = model.arm.forward(axis_counts_to_q(model, phys), model.tool_point_6)
    d = fwd.tool_point - target.tool_point
    along = d @ target.s6
    lateral = np.linalg.norm(d - along[:, None] * target.s6, axis=1)
    tilt = np.arccos(np.clip(fwd.s6 @ target.s6, -1.0, 1.0))
    s_along, s_lat, s_tilt = VERNIER_SCALES
    cost = (along / s_along) ** 2 + (lateral / s_lat) ** 2 + (tilt / s_tilt) ** 2
    return cand, cost, along


def vernier_generic(model: ControlModel, target: Target, c0: np.ndarray, counts_now,
                    vernier: bool) -> tuple[np.ndarray, float]:
    """The vernier for any arm: (counts, offset along S6 in mm) of the cheapest candidate of
    :func:`vernier_costs` (the compiled search's cost)."""
    cand, cost, along = vernier_costs(model, target, c0, counts_now, vernier)
    k = int(np.argmin(cost))
    return cand[k], float(along[k])
