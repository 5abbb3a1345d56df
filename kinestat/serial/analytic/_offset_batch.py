"""Batch entries of the offset-shoulder closed form
(:mod:`kinestat.serial.analytic._offset_kernels`): N poses over the cores or on one thread, as
:mod:`kinestat.serial.analytic._cf_batch` for the meeting shoulder (apart from the per-pose
kernel, so that a first single call sets none of them up).
"""

from __future__ import annotations

import math

import numba as nb

from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._offset_kernels import _offset_pose, _unpack

__all__ = ["offset_batch", "offset_serial"]


@nb.njit(parallel=True, **_OPTS)
def offset_batch(Kp, T, tol, wrist_tol, dedup, newton, out_c, out_s, out_valid, out_pos, out_rot,
                 out_sing, out_sign, out_fam, out_cnt):
    """Spherical wrist, offset shoulder: N poses into the (uninitialised) outputs, the
    solutions as cosines and sines; ``out_cnt (N,)`` the number of solutions (or minus the
    pose's status), as :func:`kinestat.serial.analytic._cf_batch.pieper_batch`."""
    C, T0inv, W, P, w, x6, G = _unpack(Kp)
    ch = 2.0 * math.sin(0.5 * dedup)
    for n in nb.prange(T.shape[0]):
        out_cnt[n] = _offset_pose(n, C, T, T0inv, W, P, w, x6, G, tol, wrist_tol, ch, newton,
                                  out_c, out_s, out_valid, out_pos, out_rot, out_sing, out_sign,
                                  out_fam)


@nb.njit(**_OPTS)
def offset_serial(Kp, T, tol, wrist_tol, dedup, newton, out_q, out_valid, out_pos, out_rot,
                  out_sing, out_sign, out_fam, out_cnt):
    """:func:`offset_batch` on one thread (small batches: no thread start-up), the angles
    into ``out_q``."""
    C, T0inv, W, P, w, x6, G = _unpack(Kp)
    for n in range(T.shape[0]):
        out_cnt[n] = _offset_pose(n, C, T, T0inv, W, P, w, x6, G, tol, wrist_tol, dedup, newton,
                                  out_q, None, out_valid, out_pos, out_rot, out_sing, out_sign,
                                  out_fam)
