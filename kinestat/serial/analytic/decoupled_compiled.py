"""The decoupled solver (three R/P positioning joints, a spherical wrist) by its compiled kernel
(:mod:`kinestat.serial.analytic._decoupled_kernels`): the same steps and slots as the NumPy
reference :func:`kinestat.serial.analytic.decoupled.solve_decoupled`, batched over the cores,
with a bound single-pose call for ``ik_all``."""

from __future__ import annotations

import sys
from functools import lru_cache

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.mechanism.joints import JointKind
from kinestat.serial.analytic import decoupled as _ref
from kinestat.serial.analytic._common import _ENTRY, call_compiled, reasons
from kinestat.serial.analytic.closed_form import _WRIST_TOL
from kinestat.serial.analytic.result import IKAllResult

__all__ = ["solve_decoupled_compiled", "bind_one"]

_PARALLEL_MIN = 64  # smaller batches run on one thread
K = 8


def _kernels():
    mod = sys.modules.get("kinestat.serial.analytic._decoupled_kernels")
    if mod is None:
        from kinestat.serial.analytic import _decoupled_kernels as mod  # lazy: Numba start-up
    return mod


@lru_cache(maxsize=64)
def kernel_args(model: ChainModel) -> tuple:
    """The pose-independent kernel arguments of ``model``: packed floats, the integer codes
    (kinds of joints 1-3, the joint-2 mode, the FK joint kinds, the revolute mask) and the
    Chebyshev fit of a prismatic joint 3."""
    Km = _kernels()
    pl = _ref.plan(model)
    ax = pl.axes
    Kp = Km.pack(np.asarray(model.constants), pl.T0_inv, ax.w, ax.r, pl.wrist, pl.r1, pl.r2,
                 pl.G, pl.e, pl.u, _ref._perp(ax.w[5]), float(ax.scale))
    jk = [int(JointKind.from_name(j.kind)) for j in model.joints]
    ints = np.array([0 if k == "R" else 1 for k in pl.kinds] + [Km.MODES[pl.mode]] + jk
                    + [0 if k else 1 for k in model.prismatic], dtype=np.int64)
    return (Kp, ints, np.ascontiguousarray(_ref._CHEB_T), np.ascontiguousarray(_ref._CHEB_FIT),
            np.ascontiguousarray(_ref._CHEB_TO_POWER))


def _outputs(N: int):
    return (np.empty((N, K, 6)), np.empty((N, K), dtype=bool), np.empty((N, K)),
            np.empty((N, K)), np.empty((N, K), dtype=bool), np.empty((N, K)), np.empty((N, K)),
            np.empty(N, dtype=np.int64), np.empty(N, dtype=bool))


def _reasons(cnt: np.ndarray, placed: np.ndarray) -> np.ndarray:
    r = reasons(cnt, _ref._REASON)
    r[(cnt == 0) & placed] = _ref._REASON_WRIST
    return r


def solve_decoupled_compiled(model: ChainModel, T: np.ndarray, *, tol: float = 1e-9,
                             wrist_tol: float = _WRIST_TOL,
                             shape: tuple[int, ...] | None = None) -> IKAllResult:
    """:func:`~kinestat.serial.analytic.decoupled.solve_decoupled` by the compiled kernel for
    rigid poses ``T (N, 4, 4)`` (C-contiguous float64); ``shape``: the batch shape of the
    result (default ``(N,)``; ``()`` for one pose)."""
    Km = _kernels()
    N = T.shape[0]
    out = _outputs(N)
    args = kernel_args(model) + (T, float(tol), float(wrist_tol), 1e-6) + out
    if N >= _PARALLEL_MIN:
        Km.solve_batch(*args)
    else:
        call_compiled(Km.solve_serial, *args)
    q, valid, pos, rot, sing, sign, fam, cnt, placed = out
    if shape == ():
        return IKAllResult.build_one(q, valid, pos, rot, sing, sign, fam, (3, 5), cnt,
                                     _reasons(cnt, placed)[0], _ref.METHOD, tol)
    return IKAllResult.build((N,) if shape is None else shape, q=q, valid=valid,
                             position_error=pos, rotation_error=rot, singular=sing,
                             family_sign=sign, family_value=fam, family_joints=(3, 5),
                             n_solutions=cnt, reason=_reasons(cnt, placed), method=_ref.METHOD,
                             tol=tol)


def bind_one(model: ChainModel, check_entry):
    """The single-pose call for ``ik_all``'s fast path (as
    :func:`kinestat.serial.analytic.general6r.bind_one`): ``one(T (1, 4, 4) plain, tol)`` or
    None where the full call must run (a pose not orthonormal to rounding)."""
    entry = _ENTRY.get((_kernels().solve_serial, None))
    if entry is None or check_entry is None:
        return None
    fixed = kernel_args(model)
    wrist_tol = float(_WRIST_TOL)

    def one(T, tol):
        bad, n_project = check_entry(T, 1e-6)
        if bad >= 0 or n_project:
            return None
        out = _outputs(1)
        entry(*fixed, T, tol, wrist_tol, 1e-6, *out)
        q, valid, pos, rot, sing, sign, fam, cnt, placed = out
        return IKAllResult.build_one(q, valid, pos, rot, sing, sign, fam, (3, 5), cnt,
                                     _reasons(cnt, placed)[0], _ref.METHOD, tol)
    return one
