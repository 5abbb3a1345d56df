"""Compiled (Numba) kernels of the special 6-6 all-mode forward kinematics.

(Over 600 lines on purpose: the three stages share many small ``inline="always"`` helpers, and
Numba's on-disk cache is keyed per source file — splitting them would make stale caches likely.)

The computation of :func:`kinestat.parallel.fk.fk_all` (its NumPy reference is
``fk._fk_all_reference``), in three stages
per chunk of leg-length sets:

1. compiled, parallel over the sets: the reduction to the equivalent 3-3 (Vibhute 2011
   §2.1.1), the circles and pair equations of the three top vertices and the degree-8
   polynomial in ``w = tan²(θ_R/2)`` (sampled at the 9th roots of unity, coefficients by a
   9-point DFT) — written out as :mod:`kinestat.parallel.fk33` does, then its companion matrix;
2. NumPy: the companion matrices' eigenvalues (``numpy.linalg.eigvals`` on the stack, as the
   reference, so the roots come in the same order and the modes fill the same slots);
3. compiled, parallel over the sets: the fold angles of the real roots, the partner angles,
   the candidate poses, their Newton polish on the six real legs, the distinct verified modes
   with their mirror images through the base plane (polished and checked too), in 16 slots.

Scalar code per set, no temporaries beyond one chunk (:data:`CHUNK`). Compiled on first use and
cached on disk (``cache=True``, in ``__pycache__``). :func:`kinestat.parallel.fk.fk_all` always
runs them; its private NumPy reference finds the same modes, polished to the same tolerance.
The mirror pairs can sit in another slot order: it follows the order in which the eigenvalue
solver returns the roots, and the polynomial's coefficients (a direct 9-point DFT here, NumPy's
FFT there) differ in the last bits.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor

import numba as nb
import numpy as np

from kinestat.parallel._fk_tolerances import COMBO_TOL, IMAG_TOL, SIG_TOL

_OPTS = {"cache": True, "fastmath": False, "nogil": True, "error_model": "numpy"}

#: leg-length sets per chunk (bounded temporaries: about 1 kB per set besides the outputs)
CHUNK = 4096
_PARALLEL_MIN = 16  # smaller batches run on one thread (starting the workers costs more)
_NSLOT = 16
_NCAND = 32
# tolerances shared with the NumPy path (kinestat.parallel.fk33), defined once
_COMBO_TOL = COMBO_TOL
_IMAG_TOL = IMAG_TOL
_SIG_TOL = SIG_TOL

# flags of stage 1
_FEASIBLE = 1
_REVERSED = 2
_LEAD_OK = 4


# -- geometry (stage 1 and 3) ----------------------------------------------------------------------
@nb.njit(**_OPTS)
def _circles(G, sq_nd, cen, rad, rad2):
    """Circle centres ``cen (3, 3)``, radii ``rad (3,)`` and radii² of R, S, T for the
    nondimensional squared 3-3 lengths ``sq_nd`` = [or, os, ps, pt, qt, qr] / scale²
    (``fk33._circle``). ``G`` rows 0..2 per circle: a (3), e (3), n (3), d, and the indices of
    (la2, lb2) in ``sq_nd``."""
    for i in range(3):
        g = G[i]
        d = g[9]
        la2 = sq_nd[int(g[10])]
        lb2 = sq_nd[int(g[11])]
        s = (la2 - lb2 + d * d) / (2 * d)
        for j in range(3):
            cen[i, j] = g[j] + s * g[3 + j]
        r2 = la2 - s * s
        rad2[i] = r2
        rad[i] = math.sqrt(max(r2, 0.0))


@nb.njit(**_OPTS)
def _pair(G, cen, rad, u, v, d2, K, P):
    """``fk33.pair_coefficients`` of circles u and v: K (5,) and (A, B, C, D, E) into P (5,)."""
    dc0 = cen[u, 0] - cen[v, 0]
    dc1 = cen[u, 1] - cen[v, 1]
    dc2 = cen[u, 2] - cen[v, 2]
    nu = G[u, 6:9]
    nv = G[v, 6:9]
    ru = rad[u]
    rv = rad[v]
    K0 = (dc0 * dc0 + dc1 * dc1 + dc2 * dc2) + ru * ru + rv * rv - d2
    K1 = 2 * ru * (dc0 * nu[0] + dc1 * nu[1] + dc2 * nu[2])
    K2 = -2 * rv * (dc0 * nv[0] + dc1 * nv[1] + dc2 * nv[2])
    K3 = -2 * ru * rv * (nu[0] * nv[0] + nu[1] * nv[1] + nu[2] * nv[2])
    K4 = -2 * ru * rv
    K[0], K[1], K[2], K[3], K[4] = K0, K1, K2, K3, K4
    P[0] = K0 - K1 - K2 + K3
    P[1] = K0 - K1 + K2 - K3
    P[2] = K0 + K1 - K2 - K3
    P[3] = 4 * K4
    P[4] = K0 + K1 + K2 + K3


@nb.njit(**_OPTS)
def _setup(G, sides2, scale, minvt, cvec, order, L):
    """Squared 3-3 lengths ``sq (6,)`` of the leg lengths ``L`` (model order), the circles
    (``cen (3, 3)``, ``rad``, ``rad2 (3,)``) and the three pair equations (rows of ``K, P
    (3, 5)``: f1 = RS, f2 = TR, f3 = ST); returns ``finite, cen, rad, rad2, K, P`` (finite:
    False if the lengths are not)."""
    sq = np.empty(6)
    cen = np.empty((3, 3))
    rad = np.empty(3)
    rad2 = np.empty(3)
    K = np.empty((3, 5))
    P = np.empty((3, 5))
    finite = True
    for j in range(6):
        s = 0.0
        for i in range(6):
            li = L[order[i]]
            s += (li * li + cvec[i]) * minvt[i, j]
        sq[j] = s
        finite = finite and math.isfinite(s)
    inv_s2 = 1.0 / (scale * scale)
    nd = np.empty(6)
    for j in range(6):
        nd[j] = sq[j] * inv_s2
    _circles(G, nd, cen, rad, rad2)
    _pair(G, cen, rad, 0, 1, sides2[0], K[0], P[0])  # f1: R (u = x), S (v = y)
    _pair(G, cen, rad, 2, 0, sides2[2], K[1], P[1])  # f2: T (u = z), R (v = x)
    _pair(G, cen, rad, 1, 2, sides2[1], K[2], P[2])  # f3: S (u = y), T (v = z)
    return finite, cen, rad, rad2, K, P


@nb.njit(**_OPTS)
def _polynomial(P, W, X, coef):
    """``fk33.fk33_polynomial``: the degree-8 polynomial in w (ascending, 9 coefficients)."""
    A1, B1, C1, D1, E1 = P[0, 0], P[0, 1], P[0, 2], P[0, 3], P[0, 4]
    A2, B2, C2, D2, E2 = P[1, 0], P[1, 1], P[1, 2], P[1, 3], P[1, 4]
    A3, B3, C3, D3, E3 = P[2, 0], P[2, 1], P[2, 2], P[2, 3], P[2, 4]
    samples = np.empty(9, dtype=np.complex128)
    for k in range(5):
        w = W[k]
        x = X[k]
        u2 = A1 * w + C1
        u1 = D1 * x
        u0 = B1 * w + E1
        p0 = u2 * E3 - u0 * B3
        p2 = u2 * C3 - u0 * A3
        q0 = -u1 * B3
        q1 = u2 * D3
        q2 = -u1 * A3
        r0 = u1 * E3
        r1 = -u0 * D3
        r2 = u1 * C3
        g0 = p0 * p0 - q0 * r0
        g1 = -(q0 * r1 + q1 * r0)
        g2 = 2 * p0 * p2 - (q0 * r2 + q1 * r1 + q2 * r0)
        g3 = -(q1 * r2 + q2 * r1)
        g4 = p2 * p2 - q2 * r2
        a = A2 * w + B2
        b = D2 * x
        c = C2 * w + E2
        ab = a * b
        ac = a * c
        bb = b * b
        gs = (g0, g1, g2, g3, g4)
        qs = (1.0 + 0j, -b, bb - 2 * ac, -bb * b + 3 * ab * c,
              bb * bb - 4 * ab * b * c + 2 * ac * ac)
        a2 = a * a
        apow = (1.0 + 0j, a, a2, a2 * a, a2 * a2)
        c2 = c * c
        cpow = (1.0 + 0j, c, c2, c2 * c, c2 * c2)
        res = 0j
        for j in range(5):
            for m in range(j, 5):
                res += gs[j] * gs[m] * apow[4 - m] * cpow[j] * qs[m - j]
        samples[k] = res
    for k in range(1, 5):
        samples[9 - k] = samples[k].conjugate()
    for m in range(9):
        s = 0.0
        for k in range(9):
            ang = -2.0 * math.pi * ((k * m) % 9) / 9.0
            s += samples[k].real * math.cos(ang) - samples[k].imag * math.sin(ang)
        coef[m] = s / 9.0


@nb.njit(**_OPTS)
def _companion(G, sides2, scale, minvt, cvec, order, W, X, L, C):
    """Stage 1 for one set: the companion matrix ``C (8, 8)`` of its fold-angle polynomial,
    prepared as ``fk33._root_angles`` does; returns the flags (feasible, reversed, leading
    coefficient nonzero)."""
    coef = np.empty(9)
    finite, cen, rad, rad2, K, P = _setup(G, sides2, scale, minvt, cvec, order, L)
    feasible = finite and rad2[0] >= -1e-12 and rad2[1] >= -1e-12 and rad2[2] >= -1e-12
    _polynomial(P, W, X, coef)
    big = 0.0
    ok = True
    for m in range(9):
        if not math.isfinite(coef[m]):
            ok = False
        big = max(big, abs(coef[m]))
    if not ok or big == 0.0:  # bad: the reference solves the polynomial 1 + w + … instead
        feasible = False
        for m in range(9):
            coef[m] = 1.0
        big = 1.0
    for m in range(9):
        coef[m] /= big
    rev = abs(coef[8]) < abs(coef[0])
    if rev:
        for m in range(4):
            coef[m], coef[8 - m] = coef[8 - m], coef[m]
    lead_ok = abs(coef[8]) > 0
    if not lead_ok:
        for m in range(9):
            coef[m] = 1.0
    for i in range(8):
        for j in range(8):
            C[i, j] = 0.0
    for i in range(1, 8):
        C[i, i - 1] = 1.0
    for i in range(8):
        C[i, 7] = -coef[i] / coef[8]
    return (_FEASIBLE if feasible else 0) | (_REVERSED if rev else 0) | (
        _LEAD_OK if lead_ok else 0)


@nb.njit(parallel=True, **_OPTS)
def stage1(G, sides2, scale, minvt, cvec, order, W, X, L, comp, flags):
    """:func:`_companion` for every set of ``L (N, 6)`` into ``comp (N, 8, 8)`` and
    ``flags (N,)``."""
    for k in nb.prange(L.shape[0]):
        flags[k] = _companion(G, sides2, scale, minvt, cvec, order, W, X, L[k], comp[k])


@nb.njit(**_OPTS)
def stage1_serial(G, sides2, scale, minvt, cvec, order, W, X, L, comp, flags):
    """:func:`stage1` on one thread (small batches: no thread start-up)."""
    for k in range(L.shape[0]):
        flags[k] = _companion(G, sides2, scale, minvt, cvec, order, W, X, L[k], comp[k])


# -- poses, legs, Newton (stage 3) ---------------------------------------------------------------
@nb.njit(**_OPTS)
def _partner(K, c_fixed, s_fixed, fixed_is_u, out):
    """``fk33._solve_partner``: both angles of the partner point."""
    K0, K1, K2, K3, K4 = K[0], K[1], K[2], K[3], K[4]
    if fixed_is_u:
        alpha, beta, gamma = K2 + K3 * c_fixed, K4 * s_fixed, -(K0 + K1 * c_fixed)
    else:
        alpha, beta, gamma = K1 + K3 * c_fixed, K4 * s_fixed, -(K0 + K2 * c_fixed)
    phi = math.atan2(beta, alpha)
    rr = math.hypot(alpha, beta)
    if rr > 0:
        ratio = gamma / rr
        if ratio < -1.0:
            ratio = -1.0
        elif ratio > 1.0:
            ratio = 1.0
        da = math.acos(ratio) if not math.isnan(ratio) else np.nan
    else:
        da = np.nan
    out[0] = phi + da
    out[1] = phi - da


@nb.njit(**_OPTS)
def _triangle_pose(tri, Ft_inv, T):
    """``triangle_frame(tri) @ Ft_inv`` into T (4, 4); tri rows R, S, T in the base frame."""
    x0 = tri[1, 0] - tri[0, 0]
    x1 = tri[1, 1] - tri[0, 1]
    x2 = tri[1, 2] - tri[0, 2]
    v0 = tri[2, 0] - tri[0, 0]
    v1 = tri[2, 1] - tri[0, 1]
    v2 = tri[2, 2] - tri[0, 2]
    z0 = x1 * v2 - x2 * v1
    z1 = x2 * v0 - x0 * v2
    z2 = x0 * v1 - x1 * v0
    nx = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    nz = math.sqrt(z0 * z0 + z1 * z1 + z2 * z2)
    x0 /= nx
    x1 /= nx
    x2 /= nx
    z0 /= nz
    z1 /= nz
    z2 /= nz
    y0 = z1 * x2 - z2 * x1
    y1 = z2 * x0 - z0 * x2
    y2 = z0 * x1 - z1 * x0
    F = ((x0, y0, z0, tri[0, 0]), (x1, y1, z1, tri[0, 1]), (x2, y2, z2, tri[0, 2]))
    for i in range(3):
        for j in range(4):
            T[i, j] = (F[i][0] * Ft_inv[0, j] + F[i][1] * Ft_inv[1, j]
                       + F[i][2] * Ft_inv[2, j] + F[i][3] * Ft_inv[3, j])
    T[3, 0], T[3, 1], T[3, 2], T[3, 3] = 0.0, 0.0, 0.0, 1.0


@nb.njit(**_OPTS)
def _legs(base, top, L, T, r, J, with_jacobian):
    """Residuals ``|X_i − B_i| − L_i`` into r (6,) (and their twist Jacobian into J (6, 6)):
    ``_refine.leg_residual``. Returns max |r| (inf if not finite)."""
    worst = 0.0
    for i in range(6):
        X0 = T[0, 0] * top[i, 0] + T[0, 1] * top[i, 1] + T[0, 2] * top[i, 2] + T[0, 3]
        X1 = T[1, 0] * top[i, 0] + T[1, 1] * top[i, 1] + T[1, 2] * top[i, 2] + T[1, 3]
        X2 = T[2, 0] * top[i, 0] + T[2, 1] * top[i, 1] + T[2, 2] * top[i, 2] + T[2, 3]
        d0 = X0 - base[i, 0]
        d1 = X1 - base[i, 1]
        d2 = X2 - base[i, 2]
        l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        r[i] = l - L[i]
        a = abs(r[i])
        if not a <= worst:
            worst = a if math.isfinite(a) else np.inf
        if with_jacobian:
            inv = 1.0 / (l if l > 0 else 1.0)
            S0 = d0 * inv
            S1 = d1 * inv
            S2 = d2 * inv
            J[i, 0] = X1 * S2 - X2 * S1
            J[i, 1] = X2 * S0 - X0 * S2
            J[i, 2] = X0 * S1 - X1 * S0
            J[i, 3] = S0
            J[i, 4] = S1
            J[i, 5] = S2
    return worst


@nb.njit(**_OPTS)
def _normal_equations(J, r, A, x):
    """``A = JᵀJ`` (lower triangle) and ``x = −Jᵀ r`` of a (6, 6) Jacobian; returns tr(JᵀJ)."""
    tr = 0.0
    for a in range(6):
        for b in range(a + 1):
            s = 0.0
            for i in range(6):
                s += J[i, a] * J[i, b]
            A[a, b] = s
        tr += A[a, a]
        g = 0.0
        for i in range(6):
            g += J[i, a] * r[i]
        x[a] = -g
    return tr


@nb.njit(**_OPTS)
def _ldl_solve(A, x, lam):
    """Solve ``(A + λ I) s = x`` in place (``x`` becomes ``s``) by L D Lᵀ of the lower
    triangle of the symmetric (6, 6) ``A`` (overwritten); False (``x`` untouched) where a pivot
    is not positive."""
    for j in range(6):
        d = A[j, j] + lam
        for k in range(j):
            d -= A[j, k] * A[j, k] * A[k, k]
        if not d > 0.0:
            return False
        inv_d = 1.0 / d
        for i in range(j + 1, 6):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k] * A[k, k]
            A[i, j] = s * inv_d
        A[j, j] = d
    for i in range(6):
        s = x[i]
        for k in range(i):
            s -= A[i, k] * x[k]
        x[i] = s
    for i in range(6):
        x[i] /= A[i, i]
    for i in range(5, -1, -1):
        s = x[i]
        for k in range(i + 1, 6):
            s -= A[k, i] * x[k]
        x[i] = s
    return True


@nb.njit(**_OPTS)
def _apply_twist(T, x):
    """``_refine.apply_twist`` in place: ``X' = Rot(δφ) X + δx`` for the twist ``x`` (6,)
    ``[δφ; δx_O]`` (Rodrigues, series below 1e-8 rad)."""
    w0, w1, w2 = x[0], x[1], x[2]
    th = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if th < 1e-8:
        ca = 1.0 - th * th / 6.0
        cb = 0.5 - th * th / 24.0
    else:
        ca = math.sin(th) / th
        cb = (1.0 - math.cos(th)) / (th * th)
    K = ((0.0, -w2, w1), (w2, 0.0, -w0), (-w1, w0, 0.0))
    R = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            kk = K[i][0] * K[0][j] + K[i][1] * K[1][j] + K[i][2] * K[2][j]
            R[i, j] = (1.0 if i == j else 0.0) + ca * K[i][j] + cb * kk
    old = np.empty((3, 4))
    for i in range(3):
        for j in range(4):
            old[i, j] = T[i, j]
    for i in range(3):
        for j in range(4):
            T[i, j] = R[i, 0] * old[0, j] + R[i, 1] * old[1, j] + R[i, 2] * old[2, j]
        T[i, 3] += x[3 + i]


@nb.njit(**_OPTS)
def _newton_step(base, top, L, T, r, J, A, x):
    """One ``_refine.refine`` step: ``(JᵀJ + λI) s = −Jᵀ r`` (λ = 1e-14 tr + 1e-300), non-finite
    components of s set to 0, then ``apply_twist``."""
    _legs(base, top, L, T, r, J, True)
    tr = _normal_equations(J, r, A, x)
    if not _ldl_solve(A, x, 1e-14 * tr + 1e-300):
        return
    for i in range(6):
        if not math.isfinite(x[i]):
            x[i] = 0.0
    _apply_twist(T, x)


@nb.njit(**_OPTS)
def _polish(base, top, L, T, tol, iterations, r, J, A, x):
    """``_refine.refine_where`` for one pose: Newton steps while the leg error exceeds ``tol``;
    returns the final max |leg error| (inf if not finite)."""
    err = _legs(base, top, L, T, r, J, False)
    for _ in range(iterations):
        if not err > tol:
            break
        _newton_step(base, top, L, T, r, J, A, x)
        err = _legs(base, top, L, T, r, J, False)
    return err


#: the least ``|det j|`` relative to Hadamard's bound (the product of its column norms) at which
#: the compiled tracking reads the determinant's sign (:func:`_det_sign`); nearer a singular
#: configuration the sign is left to the NumPy path (``fk._newton``), whatever the rounding
TRACK_DET_MARGIN = 1e-9


@nb.njit(**_OPTS)
def _det_sign(J, M):
    """The sign (+1 or −1) of ``det J`` (6, 6), by LU with partial pivoting of a copy in ``M``;
    0 where ``|det J|`` is below :data:`TRACK_DET_MARGIN` times the product of J's column norms
    (or not finite): too near a singular configuration to trust the sign."""
    bound = 1.0
    for j in range(6):
        s = 0.0
        for i in range(6):
            M[i, j] = J[i, j]
            s += J[i, j] * J[i, j]
        bound *= math.sqrt(s)
    sign = 1
    size = 1.0
    for k in range(6):
        p = k
        big = abs(M[k, k])
        for i in range(k + 1, 6):
            if abs(M[i, k]) > big:
                big = abs(M[i, k])
                p = i
        if not big > 0.0:
            return 0
        if p != k:
            for j in range(6):
                M[k, j], M[p, j] = M[p, j], M[k, j]
            sign = -sign
        piv = M[k, k]
        if piv < 0.0:
            sign = -sign
        size *= big
        for i in range(k + 1, 6):
            f = M[i, k] / piv
            for j in range(k + 1, 6):
                M[i, j] -= f * M[k, j]
    if not (math.isfinite(size) and size > TRACK_DET_MARGIN * bound):
        return 0
    return sign


@nb.njit(**_OPTS)
def _track_one(base, top, L, T, tol, max_iter, scale, r, J, A, x, M):
    """``fk._newton`` for one pose ``T`` (4, 4), in place: damped Newton steps (λ = 1e-12 tr +
    1e-300, at most 0.2 rad and 0.2·scale per step) until every leg is within ``tol``·1e-3 or
    ``max_iter`` steps; True only where the legs end within ``tol`` and the determinant of the
    line Jacobian read the same clear sign (:func:`_det_sign`) at the start and every iterate.
    False (a non-finite or unsolvable step, a sign change or an unclear one, no convergence):
    the caller runs the NumPy path, which names the failure."""
    worst = _legs(base, top, L, T, r, J, True)
    s0 = _det_sign(J, M)
    if s0 == 0:
        return False
    it = 0
    while not worst <= tol * 1e-3 and it < max_iter:
        tr = _normal_equations(J, r, A, x)
        if not _ldl_solve(A, x, 1e-12 * tr + 1e-300):
            return False
        fr = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / 0.2
        ft = math.sqrt(x[3] * x[3] + x[4] * x[4] + x[5] * x[5]) / (0.2 * scale)
        if not (math.isfinite(fr) and math.isfinite(ft)):
            return False
        f = max(1.0, max(fr, ft))
        for i in range(6):
            x[i] = x[i] / f
        _apply_twist(T, x)
        worst = _legs(base, top, L, T, r, J, True)
        if _det_sign(J, M) != s0:
            return False
        it += 1
    return worst <= tol


@nb.njit(**_OPTS)
def track_kernel(base, top, L, T, tol, max_iter, scale, ok):
    """:func:`_track_one` over a batch: ``L`` (N, 6) leg lengths, ``T`` (N, 4, 4) the previous
    poses, moved in place to the tracked ones; ``ok`` (N,) bool, see :func:`_track_one`."""
    r = np.empty(6)
    J = np.empty((6, 6))
    A = np.empty((6, 6))
    x = np.empty(6)
    M = np.empty((6, 6))
    for b in range(L.shape[0]):
        ok[b] = _track_one(base, top, L[b], T[b], tol, max_iter, scale, r, J, A, x, M)


@nb.njit(**_OPTS)
def _pose_gap(a, b, scale):
    """``fk._pose_distance`` of two poses (4, 4): the largest rotation-entry difference and
    translation difference over ``scale``."""
    dr = 0.0
    for i in range(3):
        for j in range(3):
            dr = max(dr, abs(a[i, j] - b[i, j]))
    dp = 0.0
    for i in range(3):
        dp = max(dp, abs(a[i, 3] - b[i, 3]))
    return max(dr, dp / scale)


@nb.njit(**_OPTS)
def nearest_moved_kernel(poses, valid, prev, pose, scale, moved):
    """``fk._verify_nearest``'s test over a batch: ``moved[b]`` where the valid mode of
    ``poses[b]`` (16, 4, 4) nearest ``prev[b]`` (the first of equals) is more than 1e-6 from
    ``pose[b]`` (``fk._pose_distance``); False where no mode is valid, as the NumPy test."""
    for b in range(poses.shape[0]):
        best = np.inf
        k = -1
        for m in range(poses.shape[1]):
            if valid[b, m]:
                d = _pose_gap(poses[b, m], prev[b], scale)
                if d < best or k < 0:
                    best = d
                    k = m
        moved[b] = k >= 0 and _pose_gap(poses[b, k], pose[b], scale) > 1e-6


@nb.njit(**_OPTS)
def line_jacobian_kernel(base, top, T, j):
    """``legs.line_jacobian`` of poses ``T`` (N, 4, 4) into ``j`` (N, 6, 6): column i is
    ``[S_i; B_i × S_i]``, ``S_i`` the unit leg direction from ``B_i`` (``base`` (6, 3)) to the
    top point ``top[i]`` carried by ``T``. Returns False where a leg has zero length."""
    for b in range(T.shape[0]):
        for i in range(6):
            d0 = T[b, 0, 0] * top[i, 0] + T[b, 0, 1] * top[i, 1] + T[b, 0, 2] * top[i, 2] \
                + T[b, 0, 3] - base[i, 0]
            d1 = T[b, 1, 0] * top[i, 0] + T[b, 1, 1] * top[i, 1] + T[b, 1, 2] * top[i, 2] \
                + T[b, 1, 3] - base[i, 1]
            d2 = T[b, 2, 0] * top[i, 0] + T[b, 2, 1] * top[i, 1] + T[b, 2, 2] * top[i, 2] \
                + T[b, 2, 3] - base[i, 2]
            n = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if not n > 0.0:
                return False
            s0, s1, s2 = d0 / n, d1 / n, d2 / n
            j[b, 0, i] = s0
            j[b, 1, i] = s1
            j[b, 2, i] = s2
            j[b, 3, i] = base[i, 1] * s2 - base[i, 2] * s1
            j[b, 4, i] = base[i, 2] * s0 - base[i, 0] * s2
            j[b, 5, i] = base[i, 0] * s1 - base[i, 1] * s0
    return True


@nb.njit(**_OPTS)
def _signature(T, scale, out):
    out[0] = T[0, 3] / scale
    out[1] = T[1, 3] / scale
    out[2] = T[2, 3] / scale
    out[3] = T[0, 0]
    out[4] = T[1, 0]
    out[5] = T[2, 0]
    out[6] = T[0, 1]
    out[7] = T[1, 1]
    out[8] = T[2, 1]


@nb.njit(**_OPTS)
def _first_occurrences(poses, valid, scale, keep):
    """``fk33.first_occurrences``: valid entries not within 1e-6 (signature distance, computed
    as |a|² + |b|² − 2 a·b) of an earlier valid entry."""
    n = valid.shape[0]
    sig = np.zeros((n, 9))
    n2 = np.zeros(n)
    for i in range(n):
        if valid[i]:
            _signature(poses[i], scale, sig[i])
            s = 0.0
            for m in range(9):
                s += sig[i, m] * sig[i, m]
            n2[i] = s
    for i in range(n):
        keep[i] = valid[i]
        if not valid[i]:
            continue
        for j in range(i):
            if not valid[j]:
                continue
            dot = 0.0
            for m in range(9):
                dot += sig[i, m] * sig[j, m]
            if n2[i] + n2[j] - 2.0 * dot < _SIG_TOL * _SIG_TOL:
                keep[i] = False
                break


@nb.njit(**_OPTS)
def _modes(G, sides2, scale, minvt, cvec, order, Fb, Ft_inv, Mb, Mt, base, top, L, flags,
           roots, tol, polish, poses, valid, res):
    """Stage 3 for one set: every verified distinct mode and its mirror image in 16 slots."""
    thS = np.empty(2)
    thT = np.empty(2)
    rc = np.empty(4)
    tri = np.empty((3, 3))
    loc = np.empty((3, 3))
    cand = np.full((_NCAND, 4, 4), np.nan)
    cok = np.zeros(_NCAND, dtype=np.bool_)
    cerr = np.full(_NCAND, np.inf)
    r = np.empty(6)
    J = np.empty((6, 6))
    A = np.empty((6, 6))
    x = np.empty(6)
    for s in range(_NSLOT):
        valid[s] = False
        res[s] = np.inf
        for i in range(4):
            for j in range(4):
                poses[s, i, j] = np.nan
    if not (flags & _FEASIBLE) or not (flags & _LEAD_OK):
        return
    rev = (flags & _REVERSED) != 0
    _, cen, rad, rad2, K, P = _setup(G, sides2, scale, minvt, cvec, order, L)
    for ri in range(8):
        z = roots[ri]
        az = abs(z)
        if not (abs(z.imag) <= _IMAG_TOL * (1 + az) and z.real >= -_IMAG_TOL * (1 + az)):
            continue
        rr = math.sqrt(max(z.real, 0.0))
        th = 2.0 * (math.atan2(1.0, rr) if rev else math.atan2(rr, 1.0))
        cR = math.cos(th)
        sR = math.sin(th)
        _partner(K[0], cR, sR, True, thS)
        _partner(K[1], cR, sR, False, thT)
        best = np.inf
        for c in range(4):
            tu = thS[c // 2]
            tv = thT[c % 2]
            cu, su, cv, sv = math.cos(tu), math.sin(tu), math.cos(tv), math.sin(tv)
            v = abs(K[2, 0] + K[2, 1] * cu + K[2, 2] * cv + K[2, 3] * cu * cv
                    + K[2, 4] * su * sv)
            rc[c] = v if math.isfinite(v) else np.inf
            best = min(best, rc[c])
        for c in range(4):
            if not (math.isfinite(rc[c]) and (rc[c] <= _COMBO_TOL or rc[c] == best)):
                continue
            angles = (th, thS[c // 2], thT[c % 2])
            finite = True
            for v_ in range(3):
                ca = math.cos(angles[v_])
                sa = math.sin(angles[v_])
                for j in range(3):
                    n_j = G[v_, 6 + j]
                    zj = 1.0 if j == 2 else 0.0
                    loc[v_, j] = cen[v_, j] + rad[v_] * (ca * n_j + sa * zj)
                    finite = finite and math.isfinite(loc[v_, j])
            if not finite:
                continue
            for v_ in range(3):  # to the base frame, model units
                for i in range(3):
                    tri[v_, i] = (scale * loc[v_, 0] * Fb[i, 0] + scale * loc[v_, 1] * Fb[i, 1]
                                  + scale * loc[v_, 2] * Fb[i, 2] + Fb[i, 3])
            q = 4 * ri + c
            T = cand[q]
            _triangle_pose(tri, Ft_inv, T)
            e = _polish(base, top, L, T, 0.1 * tol, polish, r, J, A, x)
            cerr[q] = e
            cok[q] = e <= tol
    # distinct verified candidates, at most 8, each with its mirror image (assemble_modes)
    keep = np.zeros(_NCAND, dtype=np.bool_)
    _first_occurrences(cand, cok, scale, keep)
    rank = 0
    for q in range(_NCAND):
        if not keep[q] or rank >= _NSLOT // 2:
            continue
        s = 2 * rank
        rank += 1
        for i in range(4):
            for j in range(4):
                poses[s, i, j] = cand[q, i, j]
        for i in range(4):  # Mb @ T @ Mt
            for j in range(4):
                acc = 0.0
                for a in range(4):
                    mt = 0.0
                    for b in range(4):
                        mt += cand[q, a, b] * Mt[b, j]
                    acc += Mb[i, a] * mt
                poses[s + 1, i, j] = acc
        valid[s] = valid[s + 1] = True
        res[s] = res[s + 1] = cerr[q]
    v2 = np.zeros(_NSLOT, dtype=np.bool_)
    _first_occurrences(poses, valid, scale, v2)
    for s in range(_NSLOT):
        valid[s] = v2[s]
    # the mirror images: polish and check them on the real legs (fk_all)
    for s in range(1, _NSLOT, 2):
        if valid[s]:
            e = _polish(base, top, L, poses[s], 0.1 * tol, polish, r, J, A, x)
            res[s] = e
            valid[s] = e <= tol
    _first_occurrences(poses, valid, scale, v2)
    for s in range(_NSLOT):
        valid[s] = v2[s]
        if not valid[s]:
            res[s] = np.inf
            for i in range(4):
                for j in range(4):
                    poses[s, i, j] = np.nan


@nb.njit(parallel=True, **_OPTS)
def stage3(G, sides2, scale, minvt, cvec, order, Fb, Ft_inv, Mb, Mt, base, top, L, flags,
           roots, tol, polish, poses, valid, res):
    """:func:`_modes` for every set of ``L (N, 6)`` into ``poses (N, 16, 4, 4)``,
    ``valid``, ``res (N, 16)``."""
    for k in nb.prange(L.shape[0]):
        _modes(G, sides2, scale, minvt, cvec, order, Fb, Ft_inv, Mb, Mt, base, top, L[k],
               flags[k], roots[k], tol, polish, poses[k], valid[k], res[k])


@nb.njit(**_OPTS)
def stage3_serial(G, sides2, scale, minvt, cvec, order, Fb, Ft_inv, Mb, Mt, base, top, L,
                  flags, roots, tol, polish, poses, valid, res):
    """:func:`stage3` on one thread (small batches: no thread start-up)."""
    for k in range(L.shape[0]):
        _modes(G, sides2, scale, minvt, cvec, order, Fb, Ft_inv, Mb, Mt, base, top, L[k],
               flags[k], roots[k], tol, polish, poses[k], valid[k], res[k])


# -- the Python entry points -----------------------------------------------------------------------
_POOL: list[ThreadPoolExecutor] = []  # created on first use
_EIG_SPLIT = 256  # matrices per thread below which the eigenvalues stay on one thread


def _eigvals(comp: np.ndarray) -> np.ndarray:
    """``numpy.linalg.eigvals`` of the stack, split over threads (LAPACK releases the GIL)."""
    workers = min(os.cpu_count() or 1, comp.shape[0] // _EIG_SPLIT)
    if workers < 2:
        return np.linalg.eigvals(comp)
    if not _POOL:
        _POOL.append(ThreadPoolExecutor(max_workers=os.cpu_count() or 1,
                                        thread_name_prefix="kinestat-eig"))
    parts = np.array_split(comp, workers)
    return np.concatenate(list(_POOL[0].map(np.linalg.eigvals, parts)))


def fk_all_arrays(constants: tuple, L: np.ndarray, tol: float = 1e-9,
                  polish: int = 4) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(poses (N, 16, 4, 4), valid (N, 16), residual (N, 16))`` of validated leg lengths
    ``L (N, 6)`` (finite, positive; model leg order) — the arrays of ``fk_all``. ``constants``
    are the platform's kernel constants (:func:`kinestat.parallel.fk.kernel_constants`, cached
    per platform outside it)."""
    G, sides2, scale, minvt, cvec, order, W, X, Fb, Ft_inv, Mb, Mt, base, top = constants
    L = np.ascontiguousarray(L, dtype=float)
    N = L.shape[0]
    poses = np.empty((N, _NSLOT, 4, 4))
    valid = np.empty((N, _NSLOT), dtype=bool)
    res = np.empty((N, _NSLOT))
    for start in range(0, N, CHUNK):
        part = L[start:start + CHUNK]
        n = part.shape[0]
        comp = np.empty((n, 8, 8))
        flags = np.empty(n, dtype=np.int64)
        small = n < _PARALLEL_MIN
        (stage1_serial if small else stage1)(G, sides2, scale, minvt, cvec, order, W, X, part,
                                             comp, flags)
        roots = np.ascontiguousarray(_eigvals(comp), dtype=np.complex128)
        rows = slice(start, start + n)
        (stage3_serial if small else stage3)(G, sides2, scale, minvt, cvec, order, Fb, Ft_inv,
                                             Mb, Mt, base, top, part, flags, roots, float(tol),
                                             int(polish), poses[rows], valid[rows], res[rows])
    return poses, valid, res


def track_arrays(base: np.ndarray, top: np.ndarray, L: np.ndarray, previous: np.ndarray,
                 tol: float, max_iter: int, scale: float) -> np.ndarray | None:
    """The tracked poses (..., 4, 4) of validated leg lengths ``L`` (..., 6) from the poses
    ``previous`` (..., 4, 4) (:func:`track_kernel`), or None unless every one converged with a
    clear determinant sign kept throughout (the caller then runs ``fk._newton``)."""
    shape = L.shape[:-1]
    T = np.array(previous, dtype=float, order="C").reshape(-1, 4, 4)
    ok = np.empty(T.shape[0], dtype=bool)
    track_kernel(np.ascontiguousarray(base, dtype=float), np.ascontiguousarray(top, dtype=float),
                 np.ascontiguousarray(L, dtype=float).reshape(-1, 6), T, float(tol),
                 int(max_iter), float(scale), ok)
    return T.reshape(shape + (4, 4)) if ok.all() else None
