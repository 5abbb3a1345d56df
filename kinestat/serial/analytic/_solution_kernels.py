"""Compiled steps every all-solutions kernel shares (closed forms and the general 6R): wrapping,
verification of a candidate by forward kinematics, Newton polishing, de-duplication and storage
into the caller's output arrays.

FK and the Jacobian are the serial kernels' scalar steps (:func:`kinestat.serial._kernels._step`
and ``_jac_column``: the running transform in twelve scalars), so no chain code is duplicated
here. Nothing allocates except the caller-provided scratch of :func:`polish`.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.mechanism.joints import JointKind
from kinestat.serial._kernels import _jac_column, _start, _step
from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial._numba_options import PI, SQRT8, TWO_PI
from kinestat.spatial._elimination import eliminate

REVOLUTE = int(JointKind.REVOLUTE)


@nb.njit(**_INLINE)
def wrap(x):
    """``x`` wrapped to [-π, π) (no division for values already there)."""
    if -PI <= x < PI:
        return x
    return x - TWO_PI * math.floor((x + PI) / TWO_PI)


@nb.njit(**_INLINE)
def angle_distance(a, b):
    """``|wrap(a − b)|`` for a, b already in [-π, π)."""
    d = abs(a - b)
    return TWO_PI - d if d > PI else d


@nb.njit(**_INLINE)
def pose_errors(t, Tn):
    """Position and rotation-angle error of the 12-scalar transform t against ``Tn (4, 4)``."""
    pos = math.sqrt((t[3] - Tn[0, 3]) ** 2 + (t[7] - Tn[1, 3]) ** 2 + (t[11] - Tn[2, 3]) ** 2)
    d2 = 0.0
    for i in range(3):
        for j in range(3):
            d2 += (t[4 * i + j] - Tn[i, j]) ** 2
    return pos, _two_asin(math.sqrt(d2) / SQRT8)


@nb.njit(**_INLINE)
def _two_asin(x):
    """``2 asin(min(x, 1))`` for x ≥ 0; below 1e-4 by its series ``x + x³/6 + 3x⁵/40 +
    5x⁷/112`` (the next term is 35x⁹/1152: relative 3e-34, below rounding)."""
    if x < 1e-4:
        x2 = x * x
        return 2.0 * x * (1.0 + x2 * (1.0 / 6.0 + x2 * (3.0 / 40.0 + x2 * (5.0 / 112.0))))
    return 2.0 * math.asin(min(x, 1.0))


@nb.njit(**_INLINE)
def _fk_jac(C, q, J):
    """End pose (12 scalars) and the space Jacobian into ``J (6, 6)`` at ``q (6,)``."""
    t = _start(C[0])
    for i in range(6):
        _jac_column(t, REVOLUTE, 0.0, J, i)
        t = _step(C[i + 1], REVOLUTE, 0.0, q[i], t)
    return t


@nb.njit(**_INLINE)
def _twist_error(t, Tn, e):
    """First-order spatial twist ``[ω; v_O]`` taking t to Tn (``Tn ≈ (I + [ξ]) F``) into e;
    returns its norm."""
    r = (t[0], t[1], t[2], t[4], t[5], t[6], t[8], t[9], t[10])
    # dR = R_T R_Fᵀ; only the skew part is needed
    m10 = Tn[1, 0] * r[0] + Tn[1, 1] * r[1] + Tn[1, 2] * r[2]
    m01 = Tn[0, 0] * r[3] + Tn[0, 1] * r[4] + Tn[0, 2] * r[5]
    m20 = Tn[2, 0] * r[0] + Tn[2, 1] * r[1] + Tn[2, 2] * r[2]
    m02 = Tn[0, 0] * r[6] + Tn[0, 1] * r[7] + Tn[0, 2] * r[8]
    m21 = Tn[2, 0] * r[3] + Tn[2, 1] * r[4] + Tn[2, 2] * r[5]
    m12 = Tn[1, 0] * r[6] + Tn[1, 1] * r[7] + Tn[1, 2] * r[8]
    w0 = 0.5 * (m21 - m12)
    w1 = 0.5 * (m02 - m20)
    w2 = 0.5 * (m10 - m01)
    p0, p1, p2 = t[3], t[7], t[11]
    e[0] = w0
    e[1] = w1
    e[2] = w2
    e[3] = Tn[0, 3] - p0 - (w1 * p2 - w2 * p1)
    e[4] = Tn[1, 3] - p1 - (w2 * p0 - w0 * p2)
    e[5] = Tn[2, 3] - p2 - (w0 * p1 - w1 * p0)
    s = 0.0
    for i in range(6):
        s += e[i] * e[i]
    return math.sqrt(s)


@nb.njit(**_INLINE)
def scratch():
    """The scratch :func:`polish` needs (allocate once per pose, not per root)."""
    return np.empty((3, 6, 7)), np.empty((4, 6))


@nb.njit(**_OPTS)
def polish(C, Tn, q, iters, Ms, Vs):
    """Newton steps ``J δq = ξ`` (Nadkarni eq. 4-11) with backtracking (halved until the twist
    error drops) on ``q (6,)`` in place; returns the (position, rotation) errors of the final
    q. ``Ms (3, 6, 7)``, ``Vs (4, 6)``: scratch (:func:`scratch`)."""
    J, Jn, Jc = Ms[0, :, :6], Ms[1, :, :6], Ms[2]
    e, en_v, qn = Vs[0], Vs[1], Vs[3]
    t = _fk_jac(C, q, J)
    en = _twist_error(t, Tn, e)
    # element loops, not slice assignments: those carry Numba's shape-mismatch error path,
    # whose message formatting doubles the compiled code every caller's cache loads
    for _ in range(iters):
        if en < 1e-15:
            break
        for i in range(6):
            for j in range(6):
                Jc[i, j] = J[i, j]
            Jc[i, 6] = e[i]
        if eliminate(Jc, 6, 0.0, None) < 1e-14:  # [J | e] → [· | δq]
            break
        step = 1.0
        moved = False
        nn = en
        tn = t
        for _half in range(6):  # backtracking: full Newton step, then halves
            for i in range(6):
                qn[i] = q[i] + step * Jc[i, 6]
            tn = _fk_jac(C, qn, Jn)
            nn = _twist_error(tn, Tn, en_v)
            if nn < en:
                moved = True
                break
            step *= 0.5
        if not moved:
            break
        for i in range(6):
            q[i] = qn[i]
            e[i] = en_v[i]
            for j in range(6):
                J[i, j] = Jn[i, j]
        en = nn
        t = tn
    return pose_errors(t, Tn)


@nb.njit(**_INLINE)
def store(n, q, pos, rot, dedup, out_q, out_valid, out_pos, out_rot, cnt):
    """Store the verified q (6-tuple) into slot ``cnt`` of pose n, wrapped, unless it repeats a
    stored solution (every joint within ``dedup``) or the slots are full; returns the new
    count."""
    q = (wrap(q[0]), wrap(q[1]), wrap(q[2]), wrap(q[3]), wrap(q[4]), wrap(q[5]))
    for j in range(cnt):
        dmax = 0.0
        for i in range(6):
            dmax = max(dmax, angle_distance(q[i], out_q[n, j, i]))
        if dmax < dedup:
            return cnt
    if cnt >= out_q.shape[1]:
        return cnt
    for i in range(6):
        out_q[n, cnt, i] = q[i]
    out_valid[n, cnt] = True
    out_pos[n, cnt] = pos
    out_rot[n, cnt] = rot
    return cnt + 1
