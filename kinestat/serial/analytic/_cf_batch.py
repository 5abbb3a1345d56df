"""Batch entries of the closed-form kernels (:mod:`kinestat.serial.analytic._cf_kernels`): N
poses over the cores (``prange``, the solutions as cosines and sines) or on one thread (small
batches, the angles). Apart from the per-pose kernels they call, so that a first single call
(:mod:`kinestat.serial.analytic._cf_single`) sets none of them up.
"""

from __future__ import annotations

import math

import numba as nb

from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._cf_kernels import _pieper_pose, _three_parallel_pose, _unpack

__all__ = ["pieper_batch", "pieper_serial", "three_parallel_batch", "three_parallel_serial"]


@nb.njit(parallel=True, **_OPTS)
def pieper_batch(Kp, T, tol, wrist_tol, dedup, newton, out_c, out_s, out_valid, out_pos, out_rot,
                 out_sing, out_sign, out_fam, out_cnt):
    """Spherical-wrist closed form for N poses into the (uninitialised) outputs, the solutions
    as cosines ``out_c`` and sines ``out_s`` (NaN in empty slots; angles by
    :func:`~kinestat.serial.analytic.closed_form.angles_from_pairs`); ``out_cnt (N,)`` the
    number of solutions, or minus the pose's status
    (:func:`~kinestat.serial.analytic._cf_kernels._pose_status`: a pose not orthonormal to
    rounding is not solved, the caller checks and projects it). ``newton``: Newton steps for
    a candidate that misses tol."""
    C, T0inv, W, P, w, s, x6 = _unpack(Kp)
    ch = 2.0 * math.sin(0.5 * dedup)
    for n in nb.prange(T.shape[0]):
        out_cnt[n] = _pieper_pose(n, C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, ch, newton,
                                  out_c, out_s, out_valid, out_pos, out_rot, out_sing, out_sign,
                                  out_fam)


@nb.njit(**_OPTS)
def pieper_serial(Kp, T, tol, wrist_tol, dedup, newton, out_q, out_valid, out_pos, out_rot,
                  out_sing, out_sign, out_fam, out_cnt):
    """:func:`pieper_batch` on one thread (small batches: no thread start-up), the angles
    into ``out_q``; ``newton`` None: a pose whose candidate needs Newton steps is handed back
    (:data:`~kinestat.serial.analytic._cf_storage.HANDED_BACK`)."""
    C, T0inv, W, P, w, s, x6 = _unpack(Kp)
    for n in range(T.shape[0]):
        out_cnt[n] = _pieper_pose(n, C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, dedup, newton,
                                  out_q, None, out_valid, out_pos, out_rot, out_sing, out_sign,
                                  out_fam)


@nb.njit(parallel=True, **_OPTS)
def three_parallel_batch(Kp, T, tol, wrist_tol, dedup, newton, out_c, out_s, out_valid, out_pos,
                         out_rot, out_cnt, out_near):
    """Three-parallel-axes (UR-type) closed form for N poses, the solutions as cosines and
    sines (as :func:`pieper_batch`); ``out_cnt (N,)`` the number of solutions (or minus the
    pose's status), ``out_near (N,)`` a θ1 branch is near the wrist-singular set (axis 6
    within 1e-6 of parallel to axes 2-4: where :mod:`~kinestat.serial.analytic.families`
    looks)."""
    C, T0inv, W, P, p56, xh, sg = _unpack(Kp)
    ch = 2.0 * math.sin(0.5 * dedup)
    for n in nb.prange(T.shape[0]):
        out_cnt[n] = _three_parallel_pose(n, C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol,
                                          ch, newton, out_c, out_s, out_valid, out_pos, out_rot,
                                          out_near)


@nb.njit(**_OPTS)
def three_parallel_serial(Kp, T, tol, wrist_tol, dedup, newton, out_q, out_valid, out_pos, out_rot,
                          out_cnt, out_near):
    """:func:`three_parallel_batch` on one thread, the angles into ``out_q``."""
    C, T0inv, W, P, p56, xh, sg = _unpack(Kp)
    for n in range(T.shape[0]):
        out_cnt[n] = _three_parallel_pose(n, C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol,
                                          dedup, newton, out_q, None, out_valid, out_pos,
                                          out_rot, out_near)
