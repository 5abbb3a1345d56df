"""All IK solutions of a 6R arm whose axes 2, 3, 4 meet at one point (a spherical joint
mid-chain), in closed form by the compiled kernel :mod:`kinestat.serial.analytic._middle_kernels`
(the decoupled solver's elimination on the positioning chain of joints 5, 6 and 1; see there).
Axes 3, 4, 5 meeting: the reversed chain (:mod:`kinestat.serial.analytic.reversed_chain`) has
axes 2, 3, 4 meeting."""

from __future__ import annotations

import sys
from functools import lru_cache

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic import decoupled as _dec
from kinestat.serial.analytic._common import call_compiled, reasons
from kinestat.serial.analytic.closed_form import _WRIST_TOL
from kinestat.serial.analytic.geometry import HomeAxes, cross3, home_axes, meet, norm3, parallel
from kinestat.serial.analytic.result import IKAllResult

__all__ = ["METHOD", "middle_point", "solve_middle"]

METHOD = "middle-wrist"
_PARALLEL_MIN = 64
_REASON = ("no real solution: the pose is out of reach (no root of the eliminant of joints 5, "
           "6, 1 places the meeting point of axes 2-4, or that joint cannot turn to the "
           "orientation)")


def _kernels():
    mod = sys.modules.get("kinestat.serial.analytic._middle_kernels")
    if mod is None:
        from kinestat.serial.analytic import _middle_kernels as mod  # lazy: Numba start-up
    return mod


def middle_point(model: ChainModel, tol: float = 1e-9):
    """The point where axes 2, 3, 4 meet (at q = 0), or None; None also where the joints 5, 6
    cannot take the elimination (axes 5, 6 coincide)."""
    if model.n != 6 or any(j.kind != "revolute" for j in model.joints):
        return None
    ax = home_axes(model)
    c = meet(ax, 1, 2, tol)
    if c is None or norm3(cross3(c - ax.r[3], ax.w[3])) > tol * ax.scale:
        return None
    if parallel(ax, 1, 3, tol) or parallel(ax, 2, 3, tol):
        return None
    if parallel(ax, 4, 5, tol) and norm3(cross3(ax.r[5] - ax.r[4], ax.w[4])) <= tol * ax.scale:
        return None
    return c


@lru_cache(maxsize=64)
def kernel_args(model: ChainModel) -> tuple:
    """The kernel's pose-independent arguments (see ``_middle_kernels._pose``)."""
    from kinestat.serial.analytic import _decoupled_kernels as Kd  # lazy: Numba start-up

    ax = home_axes(model)
    c = middle_point(model)
    order = [4, 5, 0, 1, 2, 3]
    sub = HomeAxes(w=ax.w[order], r=np.vstack([ax.r[[4, 5, 0]], np.repeat(c[None], 3, 0)]),
                   T0=ax.T0, scale=ax.scale)
    r1, r2 = _dec._feet(sub)  # the elimination of joints 5, 6 (an RR pair)
    W = sub.w
    e = np.stack([_dec._perp(W[1]), np.cross(W[1], _dec._perp(W[1]))])
    G = np.stack([e @ W[0], 2.0 * (e @ (r2 - r1))])
    mode = "row0" if parallel(sub, 0, 1) else \
        "row1" if np.linalg.norm(r2 - r1) <= 1e-9 * ax.scale else "full"
    Kp = Kd.pack(np.asarray(model.constants), np.linalg.inv(ax.T0), W, sub.r, c, r1, r2, G, e,
                 np.zeros((2, 3)), _dec._perp(W[5]), float(ax.scale))
    ints = np.array([0, 0, 0, Kd.MODES[mode]] + [0] * 6 + [1] * 6, dtype=np.int64)
    return (Kp, ints, np.ascontiguousarray(_dec._CHEB_T), np.ascontiguousarray(_dec._CHEB_FIT),
            np.ascontiguousarray(_dec._CHEB_TO_POWER))


def solve_middle(model: ChainModel, T: np.ndarray, *, tol: float = 1e-9,
                 shape: tuple[int, ...] | None = None) -> IKAllResult:
    """All solutions (8 slots) of the middle-wrist ``model`` for rigid poses ``T (N, 4, 4)``
    (C-contiguous float64); ``shape`` the result's batch shape (default ``(N,)``)."""
    Km = _kernels()
    N = T.shape[0]
    out = (np.empty((N, 8, 6)), np.empty((N, 8), dtype=bool), np.empty((N, 8)),
           np.empty((N, 8)), np.empty((N, 8), dtype=bool), np.empty((N, 8)), np.empty((N, 8)),
           np.empty(N, dtype=np.int64))
    args = kernel_args(model) + (T, float(tol), float(_WRIST_TOL), 1e-6) + out
    if N >= _PARALLEL_MIN:
        Km.solve_batch(*args)
    else:
        call_compiled(Km.solve_serial, *args)
    q, valid, pos, rot, sing, sign, fam, cnt = out
    if shape == ():
        return IKAllResult.build_one(q, valid, pos, rot, sing, sign, fam, (1, 3), cnt,
                                     _REASON if cnt[0] == 0 else "", METHOD, tol)
    return IKAllResult.build((N,) if shape is None else shape, q=q, valid=valid,
                             position_error=pos, rotation_error=rot, singular=sing,
                             family_sign=sign, family_value=fam, family_joints=(1, 3),
                             n_solutions=cnt, reason=reasons(cnt, _REASON), method=METHOD,
                             tol=tol)
