"""Single-pose entries of the closed-form kernels (:mod:`kinestat.serial.analytic._cf_kernels`):
one pose ``T (1, 4, 4)``, the outputs in the shapes of a one-pose result (``q (8, 6)``, the
others ``(8,)``), the number of solutions returned. A single call is a few µs, and the
leading pose axis of the batch kernels' outputs cost an indexing step per array to drop."""

from __future__ import annotations

import numba as nb

from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._cf_kernels import _pieper_pose, _three_parallel_pose, _unpack


@nb.njit(**_OPTS)
def pieper_one(Kp, T, tol, wrist_tol, q, valid, pos, rot, sing, sign, fam):
    """:func:`~kinestat.serial.analytic._cf_batch.pieper_serial` on one pose without Newton
    steps: the count, or negative where the pose is not orthonormal to rounding or a candidate
    needs Newton steps (the caller takes the full path)."""
    C, T0inv, W, P, w, s, x6 = _unpack(Kp)
    return _pieper_pose(0, C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, 1e-6, None,
                        q[None], None, valid[None], pos[None],
                        rot[None], sing[None], sign[None],
                        fam[None])


@nb.njit(**_OPTS)
def three_parallel_one(Kp, T, tol, wrist_tol, q, valid, pos, rot, sing, sign, fam):
    """:func:`~kinestat.serial.analytic._cf_batch.three_parallel_serial` on one pose without
    Newton steps, ``sing``, ``sign``, ``fam`` set to no family (False, 0, NaN): the count, or
    negative as :func:`pieper_one`, also where a θ1 branch is near the wrist-singular set
    (whose families the full path adds)."""
    C, T0inv, W, P, p56, xh, sg = _unpack(Kp)
    near = sing[:1]  # the kernel's flag, in the first slot, cleared below
    cnt = _three_parallel_pose(0, C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol, 1e-6, None,
                               q[None], None, valid[None],
                               pos[None], rot[None], near)
    if near[0]:
        return -1
    for k in range(8):
        sing[k] = False
        sign[k] = 0.0
        fam[k] = float("nan")
    return cnt
