"""Compiled (Numba) kernel of the Raghavan–Roth general 6R solver: one pose per iteration of a
``prange`` loop, the same steps as :mod:`kinestat.serial.analytic.general6r` (which stays the
NumPy reference and the fallback for poses the kernel flags).

Per pose: the right side of RR eq. 4 from the pose link (15x15 rigid action), the SVD of Q, the
12x12 matrix quadratic, the eigenvalues of its 24x24 companion (LAPACK dgeev), the power-product
vector of each real root by inverse iteration, back-substitution, θ6, Newton polishing against
FK and verification. Flags: 0 solved, 1 Q rank deficient, 2 A2 ill-conditioned (the caller
reruns the pose with the generalised eigenproblem).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba import types
from numba.np.linalg import _LAPACK

# LAPACK dgeev through Numba's own binding (cacheable, unlike a ctypes pointer)
_rgeev = _LAPACK().numba_ez_rgeev(types.float64)

_OPTS = {"cache": True, "nogil": True, "error_model": "numpy"}

FLAG_OK = 0
FLAG_DEFICIENT = 1
FLAG_ILL_CONDITIONED = 2


@nb.njit(inline="always", **_OPTS)
def _mm(A, B):
    """Matrix product by loops (tiny matrices: BLAS calls cost more than the arithmetic)."""
    n, k = A.shape
    m = B.shape[1]
    out = np.zeros((n, m))
    for i in range(n):
        for t in range(k):
            a = A[i, t]
            if a != 0.0:
                for j in range(m):
                    out[i, j] += a * B[t, j]
    return out


@nb.njit(inline="always", **_OPTS)
def _mv(A, x):
    """Matrix-vector product by loops."""
    n, k = A.shape
    out = np.zeros(n)
    for i in range(n):
        acc = 0.0
        for t in range(k):
            acc += A[i, t] * x[t]
        out[i] = acc
    return out


@nb.njit(inline="always", **_OPTS)
def _mtm(A, B):
    """``Aᵀ B`` by loops."""
    k, n = A.shape
    m = B.shape[1]
    out = np.zeros((n, m))
    for t in range(k):
        for i in range(n):
            a = A[t, i]
            for j in range(m):
                out[i, j] += a * B[t, j]
    return out


@nb.njit(inline="always", **_OPTS)
def _mtv(A, x):
    """``Aᵀ x`` by loops."""
    k, n = A.shape
    out = np.zeros(n)
    for t in range(k):
        for i in range(n):
            out[i] += A[t, i] * x[t]
    return out


@nb.njit(**_OPTS)
def _gauss(A, B):
    """Solve ``A X = B`` in place (B ← X) by Gaussian elimination with partial pivoting; A is
    overwritten. Returns the smallest |pivot| relative to the largest |entry| of A; pivots below
    1e-17 of it are replaced by that size so X stays finite (inverse iteration relies on it)."""
    n = A.shape[0]
    m = B.shape[1]
    big = 0.0
    for i in range(n):
        for j in range(n):
            big = max(big, abs(A[i, j]))
    if big == 0.0:
        return 0.0
    small = np.inf
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(A[i, k]) > abs(A[p, k]):
                p = i
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
            for j in range(m):
                B[k, j], B[p, j] = B[p, j], B[k, j]
        piv = A[k, k]
        small = min(small, abs(piv) / big)
        if abs(piv) < 1e-17 * big:  # (near) singular: a tiny pivot keeps X finite
            piv = 1e-17 * big if piv >= 0.0 else -1e-17 * big
            A[k, k] = piv
        for i in range(k + 1, n):
            f = A[i, k] / piv
            if f != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= f * A[k, j]
                for j in range(m):
                    B[i, j] -= f * B[k, j]
    for k in range(n - 1, -1, -1):
        for j in range(m):
            acc = B[k, j]
            for i in range(k + 1, n):
                acc -= A[k, i] * B[i, j]
            B[k, j] = acc / A[k, k]
    return small


@nb.njit(**_OPTS)
def _rigid_action_inv(T, M):
    """``M = rigid_action(T⁻¹)`` (see ``_rr_algebra.rigid_action``), T rigid 4x4."""
    M[:, :] = 0.0
    R = np.empty((3, 3))
    t = np.empty(3)
    for i in range(3):
        for j in range(3):
            R[i, j] = T[j, i]
    for i in range(3):
        t[i] = -(R[i, 0] * T[0, 3] + R[i, 1] * T[1, 3] + R[i, 2] * T[2, 3])
    tt = t[0] * t[0] + t[1] * t[1] + t[2] * t[2]
    tx = np.array([[0.0, -t[2], t[1]], [t[2], 0.0, -t[0]], [-t[1], t[0], 0.0]])
    txR = _mm(tx, R)
    tR = np.empty(3)
    for j in range(3):
        tR[j] = t[0] * R[0, j] + t[1] * R[1, j] + t[2] * R[2, j]
    M[0, 0] = 1.0
    M[7, 7] = 1.0
    M[8, 8] = 1.0
    M[7, 0] = tt
    for i in range(3):
        M[1 + i, 0] = t[i]
        M[7, 1 + i] = 2.0 * tR[i]
        M[8, 4 + i] = tR[i]
        M[12 + i, 8] = -2.0 * t[i]
        for j in range(3):
            M[1 + i, 1 + j] = R[i, j]
            M[4 + i, 4 + j] = R[i, j]
            M[9 + i, 9 + j] = R[i, j]
            M[12 + i, 12 + j] = R[i, j]
            M[9 + i, 4 + j] = txR[i, j]
            M[12 + i, 9 + j] = -2.0 * txR[i, j]
            M[12 + i, 4 + j] = tt * R[i, j] - 2.0 * t[i] * tR[j]


@nb.njit(**_OPTS)
def _apply_d(a, sign, v, out):
    """``out = D_a v`` for the joint-rotation basis (a = 0: constant, 1: cos, 2: sin part)."""
    out[:] = 0.0
    if a == 0:
        out[0] = v[0]
        out[7] = v[7]
        out[8] = v[8]
        for b in (1, 4, 9, 12):
            out[b + 2] = v[b + 2]
    elif a == 1:
        for b in (1, 4, 9, 12):
            out[b] = v[b]
            out[b + 1] = v[b + 1]
    else:
        for b in (1, 4, 9, 12):
            out[b] = -sign * v[b + 1]
            out[b + 1] = sign * v[b]


@nb.njit(**_OPTS)
def _zc(th, C, G):
    """``G ← G · Rz(th) · C``."""
    c = math.cos(th)
    s = math.sin(th)
    Z = np.zeros((4, 4))
    Z[0, 0] = c
    Z[0, 1] = -s
    Z[1, 0] = s
    Z[1, 1] = c
    Z[2, 2] = 1.0
    Z[3, 3] = 1.0
    return _mm(_mm(G, Z), C)


@nb.njit(**_OPTS)
def _fk_jac(C, q, J):
    """FK ``T`` of the revolute chain ``C0 Z1 C1 … Z6 C6`` and its space Jacobian into J."""
    G = C[0].copy()
    for i in range(6):
        w0, w1, w2 = G[0, 2], G[1, 2], G[2, 2]
        r0, r1, r2 = G[0, 3], G[1, 3], G[2, 3]
        J[0, i] = w0
        J[1, i] = w1
        J[2, i] = w2
        J[3, i] = -(w1 * r2 - w2 * r1)
        J[4, i] = -(w2 * r0 - w0 * r2)
        J[5, i] = -(w0 * r1 - w1 * r0)
        G = _zc(q[i], C[i + 1], G)
    return G


@nb.njit(**_OPTS)
def _twist_err(F, T, e):
    """First-order spatial twist from F to T; returns its norm."""
    dR = _mm(T[:3, :3], F[:3, :3].T)
    w0 = 0.5 * (dR[2, 1] - dR[1, 2])
    w1 = 0.5 * (dR[0, 2] - dR[2, 0])
    w2 = 0.5 * (dR[1, 0] - dR[0, 1])
    p0, p1, p2 = F[0, 3], F[1, 3], F[2, 3]
    e[0] = w0
    e[1] = w1
    e[2] = w2
    e[3] = T[0, 3] - p0 - (w1 * p2 - w2 * p1)
    e[4] = T[1, 3] - p1 - (w2 * p0 - w0 * p2)
    e[5] = T[2, 3] - p2 - (w0 * p1 - w1 * p0)
    return math.sqrt(np.sum(e * e))


@nb.njit(**_OPTS)
def _polish(C, T, q, iters):
    """Newton steps ``J δq = ξ`` with backtracking (halved until the error drops); returns the
    (position, rotation) errors of the final q (updated in place)."""
    J = np.empty((6, 6))
    e = np.empty(6)
    F = _fk_jac(C, q, J)
    en = _twist_err(F, T, e)
    Jn = np.empty((6, 6))
    en_v = np.empty(6)
    for _ in range(iters):
        if en < 1e-15:
            break
        Jc = J.copy()
        dq = e.copy().reshape((6, 1))
        if _gauss(Jc, dq) < 1e-14:
            break
        step = 1.0
        moved = False
        for _half in range(6):  # backtracking: full Newton step, then halves
            qn = q + step * dq[:, 0]
            Fn = _fk_jac(C, qn, Jn)
            nn = _twist_err(Fn, T, en_v)
            if nn < en:
                moved = True
                break
            step *= 0.5
        if not moved:
            break
        q[:] = qn
        J[:, :] = Jn
        e[:] = en_v
        en = nn
        F = Fn
    pos = math.sqrt((F[0, 3] - T[0, 3]) ** 2 + (F[1, 3] - T[1, 3]) ** 2
                    + (F[2, 3] - T[2, 3]) ** 2)
    d = math.sqrt(np.sum((F[:3, :3] - T[:3, :3]) ** 2))
    rot = 2.0 * math.asin(min(d / (2.0 * math.sqrt(2.0)), 1.0))
    return pos, rot


@nb.njit(**_OPTS)
def _right_side(M1, Ts, Rh):
    """``Rh (15, 9)``: invariants of ``Z2⁻¹ M1⁻¹ Z1⁻¹ (p, l)`` of the target Ts, column a*3+b
    multiplying ``m_a(θ1) m_b(θ2)``."""
    MA = np.empty((15, 15))
    _rigid_action_inv(M1, MA)
    p = Ts[:3, 3]
    l = Ts[:3, 2]  # noqa: E741
    pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
    pl = p[0] * l[0] + p[1] * l[1] + p[2] * l[2]
    f = np.empty(15)
    f[0] = 1.0
    f[7] = pp
    f[8] = pl
    x = np.array([p[1] * l[2] - p[2] * l[1], p[2] * l[0] - p[0] * l[2],
                  p[0] * l[1] - p[1] * l[0]])
    for i in range(3):
        f[1 + i] = p[i]
        f[4 + i] = l[i]
        f[9 + i] = x[i]
        f[12 + i] = pp * l[i] - 2.0 * pl * p[i]
    u = np.empty(15)
    o = np.empty(15)
    for a in range(3):
        _apply_d(a, -1.0, f, u)
        w = _mv(MA, u)
        for b in range(3):
            _apply_d(b, -1.0, w, o)
            Rh[:, a * 3 + b] = o


@nb.njit(**_OPTS)
def _pencil(L, H3, Rh, A, Lt):
    """Fill ``A (3, 12, 12)`` and ``Lt (14, 27)``; returns (U, s, Vt, flag)."""
    Lt[:, :] = L
    for i in range(14):
        Lt[i, 0] -= Rh[i + 1, 0]
    Q = np.ascontiguousarray(Rh[1:, 1:])
    U, s, Vt = np.linalg.svd(Q)
    if s[7] <= 1e-10 * s[0]:
        return U, s, Vt, FLAG_DEFICIENT
    E = np.ascontiguousarray(U[:, 8:].T) @ Lt @ H3  # (6, 27)
    A[:, :, :] = 0.0
    for k in range(3):
        for e in range(6):
            for m in range(9):
                A[k, e, m] = E[e, k * 9 + m]
                A[k, 6 + e, 3 + m] = E[e, k * 9 + m]
    return U, s, Vt, FLAG_OK


@nb.njit(**_OPTS)
def _companion_eigvals(A):
    """Eigenvalues of ``A2 x² + A1 x + A0`` (A normalised in place) through the 24x24 companion
    with ``A2⁻¹`` (LAPACK dgeev, eigenvalues only); ``ok`` False when A2 is ill-conditioned."""
    sc = np.max(np.abs(A))
    A /= sc
    X = np.concatenate((A[0], A[1]), axis=1)
    wr = np.empty(24)
    wi = np.empty(24)
    if _gauss(A[2].copy(), X) < 1e-10 or not np.all(np.isfinite(X)) or np.max(np.abs(X)) > 1e10:
        return wr, wi, False
    Mc = np.zeros((24, 24))  # stored transposed (LAPACK is column-major): same eigenvalues
    for i in range(12):
        Mc[12 + i, i] = 1.0
        for j in range(24):
            Mc[j, 12 + i] = -X[i, j]
    dummy = np.empty(1)
    info = _rgeev(ord("d"), ord("N"), ord("N"), 24, Mc.ctypes, 24, wr.ctypes, wi.ctypes,
                  dummy.ctypes, 1, dummy.ctypes, 1)
    return wr, wi, info == 0


_B0 = np.array([0.31, -0.72, 0.55, 0.13, -0.94, 0.67, -0.28, 0.81, -0.46, 0.19, 0.73, -0.35])


@nb.njit(**_OPTS)
def _sigma(A, x):
    """``A2 x² + A1 x + A0`` (or, for |x| > 1, the same divided by x², better scaled)."""
    if abs(x) <= 1.0:
        return A[0] + x * A[1] + (x * x) * A[2]
    y = 1.0 / x
    return A[2] + y * A[1] + (y * y) * A[0]


@nb.njit(**_OPTS)
def _null_vector(A, x):
    """The power-product vector: a null vector of ``A2 x² + A1 x + A0`` by two steps of
    inverse iteration (the matrix is singular at an eigenvalue)."""
    v = _B0.copy().reshape((12, 1))
    for _ in range(2):
        _gauss(_sigma(A, x), v)
        v /= math.sqrt(np.sum(v * v))
    return np.ascontiguousarray(v[:, 0])


@nb.njit(**_OPTS)
def _ratio(v, axis):
    """Least-squares ratio along ``axis`` (0: x4, 1: x5) of the power products v (4, 3)."""
    num = 0.0
    den = 0.0
    if axis == 0:
        for i in range(3):
            for j in range(3):
                num += v[i + 1, j] * v[i, j]
                den += v[i, j] * v[i, j]
    else:
        for i in range(4):
            for j in range(2):
                num += v[i, j + 1] * v[i, j]
                den += v[i, j] * v[i, j]
    return num / den if den > 0 else np.nan


@nb.njit(**_OPTS)
def _angles(x3, vec, off, L, Lt, U, s, Vt, links, Ts, th):
    """θ (6,) of the loop from a real root x3 and its power products; False if not usable."""
    v = vec.reshape((4, 3))
    x4 = _ratio(v, 0)
    x5 = _ratio(v, 1)
    if not (np.isfinite(x4) and np.isfinite(x5)):
        return False
    ph3 = 2.0 * math.atan(x3)
    ph4 = 2.0 * math.atan(x4)
    ph5 = 2.0 * math.atan(x5)
    m = np.empty(27)
    c3, s3 = math.cos(ph3), math.sin(ph3)
    c4, s4 = math.cos(ph4), math.sin(ph4)
    c5, s5 = math.cos(ph5), math.sin(ph5)
    m3 = (1.0, c3, s3)
    m4 = (1.0, c4, s4)
    m5 = (1.0, c5, s5)
    for a in range(3):
        for b in range(3):
            for c in range(3):
                m[a * 9 + b * 3 + c] = m3[a] * m4[b] * m5[c]
    rhs = _mv(Lt, m)
    coef = _mtv(U[:, :8], rhs)
    for j in range(8):
        coef[j] = coef[j] / s[j] if s[j] > 1e-12 * s[0] else 0.0
    S = _mtv(Vt, coef)
    th[0] = math.atan2(S[5], S[2])
    th[1] = math.atan2(S[1], S[0])
    th[2] = ph3 + off[0]
    th[3] = ph4 + off[1]
    th[4] = ph5 + off[2]
    G = np.eye(4)
    for i in range(5):
        G = _zc(th[i], links[i], G)
    R6 = _mtm(G[:3, :3], Ts[:3, :3])
    th[5] = math.atan2(R6[1, 0] - R6[0, 1], R6[0, 0] + R6[1, 1])
    return True


@nb.njit(**_OPTS)
def _wrap(x):
    return (x + math.pi) % (2.0 * math.pi) - math.pi


@nb.njit(**_OPTS)
def _solve_pose(n, C, T, M1, Ts, links_fixed, L, H3, off, order, sign, tol, iters, dedup,
                out_q, out_valid, out_pos, out_rot, flags):
    Rh = np.empty((15, 9))
    _right_side(M1[n], Ts[n], Rh)
    A = np.empty((3, 12, 12))
    Lt = np.empty((14, 27))
    U, s, Vt, flag = _pencil(L, H3, Rh, A, Lt)
    if flag != FLAG_OK:
        flags[n] = flag
        return
    wr, wi, ok = _companion_eigvals(A)
    if not ok:
        flags[n] = FLAG_ILL_CONDITIONED
        return
    links = np.empty((5, 4, 4))
    links[0] = M1[n]
    links[1:] = links_fixed
    th = np.empty(6)
    q = np.empty(6)
    cnt = 0
    K = out_q.shape[1]
    for k in range(24):
        if not abs(wi[k]) <= 1e-6 * (1.0 + abs(wr[k])):
            continue
        vec = _null_vector(A, wr[k])
        if not _angles(wr[k], vec, off, L, Lt, U, s, Vt, links, Ts[n], th):
            continue
        for i in range(6):
            q[order[i]] = sign * th[i]
        pos, rot = _polish(C, T[n], q, iters)
        if not (pos <= tol and rot <= tol):
            continue
        for i in range(6):
            q[i] = _wrap(q[i])
        dup = False
        for j in range(min(cnt, K)):
            dmax = 0.0
            for i in range(6):
                dmax = max(dmax, abs(_wrap(q[i] - out_q[n, j, i])))
            if dmax < dedup:
                dup = True
                break
        if dup or cnt >= K:
            continue
        out_q[n, cnt] = q
        out_valid[n, cnt] = True
        out_pos[n, cnt] = pos
        out_rot[n, cnt] = rot
        cnt += 1
    flags[n] = FLAG_OK


@nb.njit(parallel=True, **_OPTS)
def solve_batch(C, T, M1, Ts, links_fixed, L, H3, off, order, sign, tol, iters, dedup,
                out_q, out_valid, out_pos, out_rot, flags):
    """All solutions of N poses (see the module docstring); outputs pre-filled by the caller
    (q NaN, valid False, errors NaN)."""
    for n in nb.prange(T.shape[0]):
        _solve_pose(n, C, T, M1, Ts, links_fixed, L, H3, off, order, sign, tol, iters, dedup,
                    out_q, out_valid, out_pos, out_rot, flags)


@nb.njit(**_OPTS)
def solve_serial(C, T, M1, Ts, links_fixed, L, H3, off, order, sign, tol, iters, dedup,
                 out_q, out_valid, out_pos, out_rot, flags):
    """:func:`solve_batch` on one thread (small batches: no thread start-up)."""
    for n in range(T.shape[0]):
        _solve_pose(n, C, T, M1, Ts, links_fixed, L, H3, off, order, sign, tol, iters, dedup,
                    out_q, out_valid, out_pos, out_rot, flags)
