"""Compiled (Numba) kernels of the numerical inverse kinematics (:mod:`kinestat.serial.ik`).

One target at a time, in registers and a few small per-target buffers, exactly the iteration
of the NumPy reference (:mod:`kinestat.serial._reference`): the SE(3) error
``[log(R_t Rᵀ)^∨; δp/L]``, the damped least-squares (Levenberg–Marquardt) step on the space
Jacobian with its velocity rows moved to the end point, projection into the joint limits, the
stall tests and random restarts, and the final verdict from the forward kinematics of the
returned configuration. The targets are spread over the cores with ``prange``; each draws its
restarts from its own counter-based random stream (SplitMix64 keyed by the seed and the
target's index), so the result does not depend on the number of threads or on how the batch
is chunked.

FK and Jacobian come from :mod:`kinestat.serial._kernels` (the same inlined steps). Compiled on
first use and cached on disk (``cache=True``, in ``__pycache__``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.serial._kernels import PRISMATIC, _jac_column, _start, _step
from kinestat.serial._lm_constants import (
    CHECK_EVERY,
    MU_DOWN,
    MU_MIN,
    MU_STALL,
    MU_START,
    MU_UP,
    POLISHED,
    STALL_RATIO,
    TARGET_LAST_ROW_TOL,
    TARGET_ORTHO_TOL,
    WITHIN,
)
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial._numba_options import PI as _PI
from kinestat.serial._numba_options import SQRT8 as _SQRT8
from kinestat.serial._numba_options import TWO_PI as _TWO_PI

# pose validation codes
POSE_OK = 0
POSE_NONFINITE = 1
POSE_NOT_RIGID = 2
POSE_LAST_ROW = 3

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)
_U30 = np.uint64(30)
_U27 = np.uint64(27)
_U31 = np.uint64(31)
_U11 = np.uint64(11)
_INV53 = 1.0 / 9007199254740992.0  # 2**-53


# -- random stream (SplitMix64, Steele, Lea & Flood 2014) ----------------------------------------
@nb.njit(**_OPTS)
def _mix(z):
    z = (z ^ (z >> _U30)) * _MIX1
    z = (z ^ (z >> _U27)) * _MIX2
    return z ^ (z >> _U31)


@nb.njit(**_OPTS)
def _uniform(state):
    """Next state and a uniform double in [0, 1)."""
    state = state + _GOLDEN
    return state, float(_mix(state) >> _U11) * _INV53


# -- pose checks ---------------------------------------------------------------------------------
@nb.njit(**_OPTS)
def validate_poses(T):
    """First offending pose of ``T (N, 4, 4)`` as ``(code, index)``, checked in the reference's
    order: any non-finite entry; then a rotation part not orthonormal or with |det − 1| beyond
    ``TARGET_ORTHO_TOL``; then a last row other than [0, 0, 0, 1] (to ``TARGET_LAST_ROW_TOL``)."""
    N = T.shape[0]
    for k in range(N):
        for i in range(4):
            for j in range(4):
                if not math.isfinite(T[k, i, j]):
                    return POSE_NONFINITE, k
    for k in range(N):
        dev = 0.0
        for i in range(3):
            for j in range(3):
                s = T[k, i, 0] * T[k, j, 0] + T[k, i, 1] * T[k, j, 1] + T[k, i, 2] * T[k, j, 2]
                dev = max(dev, abs(s - (1.0 if i == j else 0.0)))
        det = (T[k, 0, 0] * (T[k, 1, 1] * T[k, 2, 2] - T[k, 1, 2] * T[k, 2, 1])
               - T[k, 0, 1] * (T[k, 1, 0] * T[k, 2, 2] - T[k, 1, 2] * T[k, 2, 0])
               + T[k, 0, 2] * (T[k, 1, 0] * T[k, 2, 1] - T[k, 1, 1] * T[k, 2, 0]))
        if dev > TARGET_ORTHO_TOL or abs(det - 1.0) > TARGET_ORTHO_TOL:
            return POSE_NOT_RIGID, k
    for k in range(N):
        if (abs(T[k, 3, 0]) > TARGET_LAST_ROW_TOL or abs(T[k, 3, 1]) > TARGET_LAST_ROW_TOL
                or abs(T[k, 3, 2]) > TARGET_LAST_ROW_TOL
                or abs(T[k, 3, 3] - 1.0) > TARGET_LAST_ROW_TOL):
            return POSE_LAST_ROW, k
    return POSE_OK, -1


@nb.njit(**_OPTS)
def _nearest_rotation(M, R):
    """The rotation nearest ``M[:3, :3]`` (its orthogonal polar factor U Vᵀ) into ``R (3, 3)``.

    Newton's iteration ``X ← (X + X⁻ᵀ)/2`` (Higham 1986), quadratically convergent; the input
    is orthonormal to 1e-6, so three or four steps reach rounding level.
    """
    for i in range(3):
        for j in range(3):
            R[i, j] = M[i, j]
    for _ in range(8):
        a, b, c = R[0, 0], R[0, 1], R[0, 2]
        d, e, f = R[1, 0], R[1, 1], R[1, 2]
        g, h, i_ = R[2, 0], R[2, 1], R[2, 2]
        # cofactor matrix / det = X^{-T}
        c00 = e * i_ - f * h
        c01 = f * g - d * i_
        c02 = d * h - e * g
        c10 = c * h - b * i_
        c11 = a * i_ - c * g
        c12 = b * g - a * h
        c20 = b * f - c * e
        c21 = c * d - a * f
        c22 = a * e - b * d
        det = a * c00 + b * c01 + c * c02
        change = 0.0
        n00 = 0.5 * (a + c00 / det)
        n01 = 0.5 * (b + c01 / det)
        n02 = 0.5 * (c + c02 / det)
        n10 = 0.5 * (d + c10 / det)
        n11 = 0.5 * (e + c11 / det)
        n12 = 0.5 * (f + c12 / det)
        n20 = 0.5 * (g + c20 / det)
        n21 = 0.5 * (h + c21 / det)
        n22 = 0.5 * (i_ + c22 / det)
        change = max(abs(n00 - a), abs(n01 - b), abs(n02 - c), abs(n10 - d), abs(n11 - e),
                     abs(n12 - f), abs(n20 - g), abs(n21 - h), abs(n22 - i_))
        R[0, 0], R[0, 1], R[0, 2] = n00, n01, n02
        R[1, 0], R[1, 1], R[1, 2] = n10, n11, n12
        R[2, 0], R[2, 1], R[2, 2] = n20, n21, n22
        if change <= 1e-16:
            break


# -- the SE(3) error -----------------------------------------------------------------------------
@nb.njit(**_OPTS)
def _rotvec(m00, m01, m02, m10, m11, m12, m20, m21, m22):
    """Rotation vector (axis × angle, angle in [0, π]) of a rotation matrix: via the unit
    quaternion (Shepperd 1978, the method of SciPy's ``Rotation.from_matrix``) and
    ``2 atan2(|v|, w)`` (SciPy's ``as_rotvec``, with its series for small angles)."""
    tr = m00 + m11 + m22
    if tr >= m00 and tr >= m11 and tr >= m22:
        x = m21 - m12
        y = m02 - m20
        z = m10 - m01
        w = 1.0 + tr
    elif m00 >= m11 and m00 >= m22:
        x = 1.0 - tr + 2.0 * m00
        y = m10 + m01
        z = m20 + m02
        w = m21 - m12
    elif m11 >= m22:
        x = m01 + m10
        y = 1.0 - tr + 2.0 * m11
        z = m21 + m12
        w = m02 - m20
    else:
        x = m02 + m20
        y = m12 + m21
        z = 1.0 - tr + 2.0 * m22
        w = m10 - m01
    nq = math.sqrt(x * x + y * y + z * z + w * w)
    if w < 0.0:
        nq = -nq
    x /= nq
    y /= nq
    z /= nq
    w /= nq
    angle = 2.0 * math.atan2(math.sqrt(x * x + y * y + z * z), w)
    if angle <= 1e-3:
        a2 = angle * angle
        scale = 2.0 + a2 / 12.0 + 7.0 * a2 * a2 / 2880.0
    else:
        scale = angle / math.sin(0.5 * angle)
    return scale * x, scale * y, scale * z


@nb.njit(**_OPTS)
def _error(t, R, pt, inv_L, e):
    """``e = [log(R_t Rᵀ)^∨; (p_t − p)/L]`` for the end pose ``t`` (12 values, row-major 3x4);
    returns the squared cost ``|e|²``."""
    r00, r01, r02, p0, r10, r11, r12, p1, r20, r21, r22, p2 = t
    # M = R_t · Rᵀ
    m00 = R[0, 0] * r00 + R[0, 1] * r01 + R[0, 2] * r02
    m01 = R[0, 0] * r10 + R[0, 1] * r11 + R[0, 2] * r12
    m02 = R[0, 0] * r20 + R[0, 1] * r21 + R[0, 2] * r22
    m10 = R[1, 0] * r00 + R[1, 1] * r01 + R[1, 2] * r02
    m11 = R[1, 0] * r10 + R[1, 1] * r11 + R[1, 2] * r12
    m12 = R[1, 0] * r20 + R[1, 1] * r21 + R[1, 2] * r22
    m20 = R[2, 0] * r00 + R[2, 1] * r01 + R[2, 2] * r02
    m21 = R[2, 0] * r10 + R[2, 1] * r11 + R[2, 2] * r12
    m22 = R[2, 0] * r20 + R[2, 1] * r21 + R[2, 2] * r22
    wx, wy, wz = _rotvec(m00, m01, m02, m10, m11, m12, m20, m21, m22)
    e[0] = wx
    e[1] = wy
    e[2] = wz
    e[3] = (pt[0] - p0) * inv_L
    e[4] = (pt[1] - p1) * inv_L
    e[5] = (pt[2] - p2) * inv_L
    return wx * wx + wy * wy + wz * wz + e[3] * e[3] + e[4] * e[4] + e[5] * e[5]


@nb.njit(**_OPTS)
def _fk_jac(C, kinds, pitch, q, J):
    """End pose (12 values) and space Jacobian ``J (6, n)`` in one pass."""
    t = _start(C[0])
    for i in range(q.shape[0]):
        _jac_column(t, kinds[i], pitch[i], J, i)
        t = _step(C[i + 1], kinds[i], pitch[i], q[i], t)
    return t


@nb.njit(**_OPTS)
def _fk(C, kinds, pitch, q):
    t = _start(C[0])
    for i in range(q.shape[0]):
        t = _step(C[i + 1], kinds[i], pitch[i], q[i], t)
    return t


# -- one damped least-squares step ---------------------------------------------------------------
@nb.njit(**_OPTS)
def _ldl_solve(A, x, damp, n):
    """Solve ``(A + damp I) y = x`` in place for the symmetric ``A`` given by its lower
    triangle, by ``L D Lᵀ`` (no square roots); the factor overwrites the lower triangle (the
    diagonal holds 1/D). False when a pivot is not positive (not positive definite in floating
    point)."""
    for j in range(n):
        d = A[j, j] + damp
        for k in range(j):
            d -= A[j, k] * A[j, k] * A[k, k]
        if not d > 0.0:
            return False
        inv_d = 1.0 / d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k] * A[k, k]
            A[i, j] = s * inv_d
        A[j, j] = d
    for i in range(n):
        s = x[i]
        for k in range(i):
            s -= A[i, k] * x[k]
        x[i] = s
    for i in range(n):
        x[i] /= A[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= A[k, i] * x[k]
        x[i] = s
    return True


@nb.njit(**_OPTS)
def _damped_step(J, t, e, mu, L, inv_L, kinds, free, Js, A, x):
    """``δq`` into ``x``: ``(JᵀJ + μ s I) δx = Jᵀ e`` with ``J = [J_ω; (J_v − p × J_ω)/L] · D``
    (prismatic columns scaled by ``D = L``), ``s = trace(JᵀJ)/n``, ``δq = D δx`` — the
    reference's ``damped_step``, solved by Cholesky. ``Js (n, 6)`` holds the scaled Jacobian
    transposed, ``A (n, n)`` the factor; ``free (n,)`` multiplies ``D`` (0: a joint blocked on
    a limit, :func:`_block`). False when the system is not positive definite in floating
    point or the step is not finite (the step is then rejected)."""
    n = J.shape[1]
    px, py, pz = t[3], t[7], t[11]
    for j in range(n):
        wx, wy, wz = J[0, j], J[1, j], J[2, j]
        D = (L if kinds[j] == PRISMATIC else 1.0) * free[j]
        sv = inv_L * D
        Js[j, 0] = wx * D
        Js[j, 1] = wy * D
        Js[j, 2] = wz * D
        Js[j, 3] = (J[3, j] - (py * wz - pz * wy)) * sv
        Js[j, 4] = (J[4, j] - (pz * wx - px * wz)) * sv
        Js[j, 5] = (J[5, j] - (px * wy - py * wx)) * sv
    e0, e1, e2, e3, e4, e5 = e[0], e[1], e[2], e[3], e[4], e[5]
    tr = 0.0
    for a in range(n):
        a0, a1, a2, a3, a4, a5 = Js[a, 0], Js[a, 1], Js[a, 2], Js[a, 3], Js[a, 4], Js[a, 5]
        for b in range(a + 1):
            A[a, b] = (a0 * Js[b, 0] + a1 * Js[b, 1] + a2 * Js[b, 2] + a3 * Js[b, 3]
                       + a4 * Js[b, 4] + a5 * Js[b, 5])
        tr += A[a, a]
        x[a] = a0 * e0 + a1 * e1 + a2 * e2 + a3 * e3 + a4 * e4 + a5 * e5
    damp = mu * max(tr / n, 1e-12)
    # n = 6 (the usual arm) with constant trip counts: the loops unroll
    solved = _ldl_solve(A, x, damp, 6) if n == 6 else _ldl_solve(A, x, damp, n)
    if not solved:
        return False
    ok = True
    for j in range(n):
        if kinds[j] == PRISMATIC:
            x[j] *= L
        x[j] *= free[j]
        if not math.isfinite(x[j]):
            ok = False
    return ok


@nb.njit(**_OPTS)
def _block(q, dq, kinds, lo, hi, free):
    """The reference's ``blocked_joints``: ``free[j] = 0`` for each joint on a limit that the
    step ``dq`` pushes it beyond (prismatic, or revolute with less than a turn of range);
    True when any is."""
    any_blocked = False
    for j in range(q.shape[0]):
        bounded = kinds[j] == PRISMATIC or hi[j] - lo[j] < _TWO_PI
        if bounded and ((q[j] <= lo[j] and dq[j] < 0) or (q[j] >= hi[j] and dq[j] > 0)):
            free[j] = 0.0
            any_blocked = True
    return any_blocked


# -- joint limits --------------------------------------------------------------------------------
@nb.njit(**_OPTS)
def _project(q, ref, kinds, lo, hi, limits, out):
    """``wrap_joints(model, q, ref)``: a rotating joint goes to its whole-turn shift inside the
    limits nearest ``ref`` (else to [−π, π) about ``ref``), then every joint is clipped; with
    ``limits`` False, ``q`` unchanged."""
    for j in range(q.shape[0]):
        v = q[j]
        if limits:
            if kinds[j] != PRISMATIC:
                d = v - ref[j]
                # within half a turn of ref: v is its own wrapped value (to rounding); inside
                # the limits it is then the nearest shift, every other one being > π away
                base = v if -_PI <= d < _PI else ref[j] + (d + _PI) % _TWO_PI - _PI
                v = base
                if not (base >= lo[j] and base <= hi[j]):
                    bestd = np.inf
                    for m in range(-3, 4):
                        c = base + m * _TWO_PI
                        if c >= lo[j] and c <= hi[j]:
                            dc = abs(c - ref[j])
                            if dc < bestd:
                                bestd = dc
                                v = c
            v = min(max(v, lo[j]), hi[j])
        out[j] = v


@nb.njit(**_OPTS)
def _random_q(state, kinds, lo, hi, L, out):
    """A random configuration within the limits (a rotating joint with no finite limit, or
    more than a turn of range, gets one turn), as the reference's ``_random_q``."""
    for j in range(out.shape[0]):
        rot = kinds[j] != PRISMATIC
        lo_f = lo[j] if math.isfinite(lo[j]) else (-_PI if rot else -L)
        hi_f = hi[j] if math.isfinite(hi[j]) else (_PI if rot else L)
        span = min(hi_f - lo_f, _TWO_PI) if rot else hi_f - lo_f
        state, u = _uniform(state)
        out[j] = lo_f + u * span
    return state


# -- one target ----------------------------------------------------------------------------------
@nb.njit(**_OPTS)
def _solve(C, kinds, pitch, lo, hi, q0, M, L, pos_tol, rot_tol, max_iter, restarts, limits,
           state, q_out):
    """Levenberg–Marquardt with restarts for one target pose ``M (4, 4)`` from ``q0``; the best
    configuration goes to ``q_out``. Returns (position error, rotation error, success,
    iterations, attempts), the verdict taken from the forward kinematics of ``q_out``."""
    n = q0.shape[0]
    inv_L = 1.0 / L
    pos_tol_s = pos_tol / L
    R = np.empty((3, 3))
    _nearest_rotation(M, R)
    pt = np.empty(3)
    pt[0], pt[1], pt[2] = M[0, 3], M[1, 3], M[2, 3]
    q = np.empty(n)
    qn = np.empty(n)
    qt = np.empty(n)
    dq = np.empty(n)
    J = np.empty((6, n))
    Jn = np.empty((6, n))
    Js = np.empty((n, 6))
    A = np.empty((n, n))
    e = np.empty(6)
    en = np.empty(6)
    free = np.ones(n)

    _project(q0, q0, kinds, lo, hi, limits, q)
    t = _fk_jac(C, kinds, pitch, q, J)
    cost = _error(t, R, pt, inv_L, e)
    best_cost = cost
    for j in range(n):
        q_out[j] = q[j]
    mu = MU_START
    checkpoint = np.inf
    it_total = 0
    it_attempt = 0
    attempts = 1
    while True:
        pe = math.sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5])
        re = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
        within = pe <= WITHIN * pos_tol_s and re <= WITHIN * rot_tol
        done = pe <= POLISHED * pos_tol_s and re <= POLISHED * rot_tol
        accept = False
        if not done:
            stepped = _damped_step(J, t, e, mu, L, inv_L, kinds, free, Js, A, dq)
            if stepped and limits and _block(q, dq, kinds, lo, hi, free):
                # a joint on a limit the step pushes it beyond: solve without it
                stepped = _damped_step(J, t, e, mu, L, inv_L, kinds, free, Js, A, dq)
                for j in range(n):
                    free[j] = 1.0
            if stepped:
                for j in range(n):
                    qt[j] = q[j] + dq[j]
                _project(qt, q, kinds, lo, hi, limits, qn)
                tn = _fk_jac(C, kinds, pitch, qn, Jn)
                cost_n = _error(tn, R, pt, inv_L, en)
                if cost_n < cost:
                    accept = True
                    for j in range(n):  # copies: swapping arrays costs reference counting
                        q[j] = qn[j]
                        for r in range(6):
                            J[r, j] = Jn[r, j]
                    for r in range(6):
                        e[r] = en[r]
                    t = tn
                    cost = cost_n
                    if cost < best_cost:
                        best_cost = cost
                        for j in range(n):
                            q_out[j] = q[j]
            it_total += 1
            it_attempt += 1
        mu = max(mu / MU_DOWN, MU_MIN) if accept else mu * MU_UP
        check = it_attempt % CHECK_EVERY == 0 and not done
        slow = check and cost > STALL_RATIO * checkpoint
        if check:
            checkpoint = cost
        stalled = (not done and not within
                   and (mu > MU_STALL or slow or it_attempt >= max_iter))
        restart = stalled and attempts <= restarts
        done = done or (within and (not accept or it_attempt >= max_iter))
        if done or (stalled and not restart):
            break
        if restart:
            state = _random_q(state, kinds, lo, hi, L, qt)
            _project(qt, q0, kinds, lo, hi, limits, q)
            mu = MU_START
            checkpoint = np.inf
            it_attempt = 0
            attempts += 1
            t = _fk_jac(C, kinds, pitch, q, J)
            cost = _error(t, R, pt, inv_L, e)
            if cost < best_cost:
                best_cost = cost
                for j in range(n):
                    q_out[j] = q[j]
    # the verdict: forward kinematics of the answer against the (projected) target
    inside = True
    for j in range(n):
        if limits:
            inside = inside and q_out[j] >= lo[j] and q_out[j] <= hi[j]
        elif kinds[j] != PRISMATIC:
            q_out[j] = (q_out[j] + _PI) % _TWO_PI - _PI
    t = _fk(C, kinds, pitch, q_out)
    dp = math.sqrt((t[3] - pt[0]) ** 2 + (t[7] - pt[1]) ** 2 + (t[11] - pt[2]) ** 2)
    d2 = ((t[0] - R[0, 0]) ** 2 + (t[1] - R[0, 1]) ** 2 + (t[2] - R[0, 2]) ** 2
          + (t[4] - R[1, 0]) ** 2 + (t[5] - R[1, 1]) ** 2 + (t[6] - R[1, 2]) ** 2
          + (t[8] - R[2, 0]) ** 2 + (t[9] - R[2, 1]) ** 2 + (t[10] - R[2, 2]) ** 2)
    rot = 2.0 * math.asin(min(math.sqrt(d2) / _SQRT8, 1.0))
    ok = dp <= pos_tol and rot <= rot_tol and inside
    return dp, rot, ok, it_total, attempts


@nb.njit(**_OPTS)
def _target(k, C, kinds, pitch, lo, hi, Q0, Tt, L, pos_tol, rot_tol, max_iter, restarts,
            limits, seed, offset, q_out, success, pos, rot, iters, attempts):
    q0 = Q0[k] if Q0.shape[0] > 1 else Q0[0]
    state = _mix(seed ^ (np.uint64(offset + k) * _GOLDEN))
    dp, ra, ok, it, att = _solve(C, kinds, pitch, lo, hi, q0, Tt[k], L, pos_tol, rot_tol,
                                 max_iter, restarts, limits, state, q_out[k])
    pos[k] = dp
    rot[k] = ra
    success[k] = ok
    iters[k] = it
    attempts[k] = att


@nb.njit(parallel=True, **_OPTS)
def ik_batch(C, kinds, pitch, lo, hi, Q0, Tt, L, pos_tol, rot_tol, max_iter, restarts, limits,
             seed, offset, q_out, success, pos, rot, iters, attempts):
    """Solve every target ``Tt (N, 4, 4)`` (validated) from ``Q0 (N or 1, n)`` in parallel,
    into ``q_out (N, n)``, ``success``, ``pos``, ``rot``, ``iters``, ``attempts`` ``(N,)``.
    Target k's restarts use the random stream keyed by ``(seed, offset + k)``."""
    for k in nb.prange(Tt.shape[0]):
        _target(k, C, kinds, pitch, lo, hi, Q0, Tt, L, pos_tol, rot_tol, max_iter, restarts,
                limits, seed, offset, q_out, success, pos, rot, iters, attempts)


@nb.njit(**_OPTS)
def ik_serial(C, kinds, pitch, lo, hi, Q0, Tt, L, pos_tol, rot_tol, max_iter, restarts, limits,
              seed, offset, q_out, success, pos, rot, iters, attempts):
    """:func:`ik_batch` on one thread (small batches: no thread start-up)."""
    for k in range(Tt.shape[0]):
        _target(k, C, kinds, pitch, lo, hi, Q0, Tt, L, pos_tol, rot_tol, max_iter, restarts,
                limits, seed, offset, q_out, success, pos, rot, iters, attempts)
