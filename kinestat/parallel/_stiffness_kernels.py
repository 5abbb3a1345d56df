"""Compiled (Numba) spatial stiffness of the loaded platform at one pose: the control cycle's
single-pose path of :func:`kinestat.parallel.stiffness.stiffness` (Vibhute 2011 eq. 2-17 as
derived there: elastic ``j k jᵀ``, the two symmetric geometric terms ``(f_i / l_i) [e; B_i × e]
[e; B_i × e]ᵀ`` summed over the normals ``e`` of leg i, and the load terms
``−f_i [I; [B_i]×] [0, [S_i]×]``), written out per leg in scalars. It computes the NumPy
formulation's sums in another order, so the two agree to rounding (~1e-15 relative), not bit
for bit. Compiled on first use and cached on disk (``cache=True``, in ``__pycache__``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.spatial._elimination import eliminate

_OPTS = {"cache": True, "fastmath": False, "nogil": True, "error_model": "numpy"}

__all__ = ["stiffness_axis_one", "tip_compliance_one", "pinned_tip_step_one"]


@nb.njit(**_OPTS)
def stiffness_axis_one(B, P_top, k, l0, T, K):
    """K (6, 6), axis order ``[δφ; δx_O]``, into ``K`` for the platform with base points ``B``
    (6, 3), top points ``P_top`` (6, 3, top frame), springs ``k`` (6,) of free lengths ``l0``
    (6,) at the pose ``T`` (4, 4), the legs carrying their spring tensions ``k (l − l0)``.
    Returns False (K untouched) when a leg has zero length."""
    Kr = np.zeros((6, 6))  # ray order [δx_O; δφ]
    line = np.empty(6)
    Bx = np.empty((3, 3))
    Pm = np.empty((3, 3))
    for i in range(6):
        d = np.empty(3)
        for r in range(3):
            d[r] = (T[r, 0] * P_top[i, 0] + T[r, 1] * P_top[i, 1] + T[r, 2] * P_top[i, 2]
                    + T[r, 3] - B[i, r])
        l = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        if not l > 0.0:
            return False
        S0, S1, S2 = d[0] / l, d[1] / l, d[2] / l
        b0, b1, b2 = B[i, 0], B[i, 1], B[i, 2]
        f = k[i] * (l - l0[i])
        line[0], line[1], line[2] = S0, S1, S2
        line[3], line[4], line[5] = b1 * S2 - b2 * S1, b2 * S0 - b0 * S2, b0 * S1 - b1 * S0
        for a in range(6):
            for b in range(6):
                Kr[a, b] += k[i] * line[a] * line[b]
        # geometric: (f / l) [I; Bx] (I − S Sᵀ) [I; Bx]ᵀ
        Bx[0, 0], Bx[0, 1], Bx[0, 2] = 0.0, -b2, b1
        Bx[1, 0], Bx[1, 1], Bx[1, 2] = b2, 0.0, -b0
        Bx[2, 0], Bx[2, 1], Bx[2, 2] = -b1, b0, 0.0
        S = (S0, S1, S2)
        for r in range(3):
            for c in range(3):
                Pm[r, c] = (1.0 if r == c else 0.0) - S[r] * S[c]
        BP = Bx @ Pm
        g = f / l
        for r in range(3):
            for c in range(3):
                Kr[r, c] += g * Pm[r, c]
                pb = 0.0
                bp = 0.0
                for m in range(3):
                    pb += Pm[r, m] * Bx[c, m]
                    bp += BP[r, m] * Bx[c, m]
                Kr[r, 3 + c] += g * pb
                Kr[3 + r, c] += g * BP[r, c]
                Kr[3 + r, 3 + c] += g * bp
        # load: −f [I; Bx] [0, Sx]
        Sx00, Sx01, Sx02 = 0.0, -S2, S1
        Sx10, Sx11, Sx12 = S2, 0.0, -S0
        Sx20, Sx21, Sx22 = -S1, S0, 0.0
        Sx = ((Sx00, Sx01, Sx02), (Sx10, Sx11, Sx12), (Sx20, Sx21, Sx22))
        for r in range(3):
            for c in range(3):
                Kr[r, 3 + c] -= f * Sx[r][c]
                bs = Bx[r, 0] * Sx[0][c] + Bx[r, 1] * Sx[1][c] + Bx[r, 2] * Sx[2][c]
                Kr[3 + r, 3 + c] -= f * bs
    for r in range(6):
        for c in range(3):
            K[r, c] = Kr[r, 3 + c]
            K[r, 3 + c] = Kr[r, c]
    return True


@nb.njit(**_OPTS)
def _solve_k_tip(K, p, X, y, b):
    """``X = K⁻¹ [I; [p]×]`` (6, 3) and ``y = K⁻¹ b`` (6,) by one Gaussian elimination with
    partial pivoting of ``K`` (6, 6); returns False when ``K`` is singular."""
    M = np.empty((6, 10))
    for r in range(6):
        for c in range(6):
            M[r, c] = K[r, c]
        for c in range(3):
            M[r, 6 + c] = 0.0
        M[r, 9] = b[r]
    for c in range(3):
        M[c, 6 + c] = 1.0
    # [p]× in rows 3..5
    M[3, 7], M[3, 8] = -p[2], p[1]
    M[4, 6], M[4, 8] = p[2], -p[0]
    M[5, 6], M[5, 7] = -p[1], p[0]
    if not eliminate(M, 6, 0.0, None) > 0.0:  # [K | A b] → [· | X y]
        return False
    for r in range(6):
        for c in range(3):
            X[r, c] = M[r, 6 + c]
        y[r] = M[r, 9]
    return True


@nb.njit(**_OPTS)
def _tip_rows(p, X, C):
    """``C = [−[p]×, I] X`` (3, 3) for ``X`` (6, 3)."""
    for c in range(3):
        C[0, c] = -(-p[2] * X[1, c] + p[1] * X[2, c]) + X[3, c]
        C[1, c] = -(p[2] * X[0, c] - p[0] * X[2, c]) + X[4, c]
        C[2, c] = -(-p[1] * X[0, c] + p[0] * X[1, c]) + X[5, c]


@nb.njit(**_OPTS)
def tip_compliance_one(K, p, C):
    """The tip's translational compliance ``C = [−[p]×, I] K⁻¹ [I; [p]×]`` (3, 3) into ``C``
    for the stiffness ``K`` (6, 6, axis order) and the tip ``p`` (3,), base frame (Vibhute
    eq. 2-16/2-17, :func:`kinestat.parallel.stiffness.tip_compliance` for one pose). Returns
    False when ``K`` is singular."""
    X = np.empty((6, 3))
    y = np.empty(6)
    if not _solve_k_tip(K, p, X, y, np.zeros(6)):
        return False
    _tip_rows(p, X, C)
    return True


@nb.njit(**_OPTS)
def pinned_tip_step_one(B, P_top, T, K, p, u, F, dF, D, dl, top):
    """The platform's first-order response when its base moves so that the tip, pinned in
    space, sits at ``p + u`` in the base frame (:func:`kinestat.control.predict.predict`):
    with ``A = [I; [p]×]``, ``Bt = [−[p]×, I]``, ``b = [0; u × F]``,
    ``δF = C_tip⁻¹ (u − Bt K⁻¹ b)`` into ``dF`` (3,), the top's twist ``D = K⁻¹ (A δF + b)``
    into ``D`` (6, axis order ``[δφ; δx_O]``), the legs' changes ``jᵀ D`` into ``dl`` (6,) and
    the moved top pose ``[exp(δφ) R, exp(δφ) t + δx]`` into ``top`` (4, 4). ``B``, ``P_top``
    (6, 3) the base and top points, ``T`` (4, 4) the top pose, ``K`` (6, 6) the stiffness at
    ``T``, ``F`` (3,) the external force on the tip (base frame). Returns False when ``K`` or
    ``C_tip`` is singular (outputs then unset)."""
    b = np.zeros(6)
    b[3] = u[1] * F[2] - u[2] * F[1]
    b[4] = u[2] * F[0] - u[0] * F[2]
    b[5] = u[0] * F[1] - u[1] * F[0]
    X = np.empty((6, 3))
    y = np.empty(6)
    if not _solve_k_tip(K, p, X, y, b):
        return False
    C = np.empty((3, 3))
    _tip_rows(p, X, C)
    r = np.empty(3)  # u − Bt y
    r[0] = u[0] - (-(-p[2] * y[1] + p[1] * y[2]) + y[3])
    r[1] = u[1] - (-(p[2] * y[0] - p[0] * y[2]) + y[4])
    r[2] = u[2] - (-(-p[1] * y[0] + p[0] * y[1]) + y[5])
    if not _solve3(C, r, dF):
        return False
    for k in range(6):  # D = K⁻¹ (A δF + b) = X δF + y
        D[k] = X[k, 0] * dF[0] + X[k, 1] * dF[1] + X[k, 2] * dF[2] + y[k]
    for i in range(6):
        d0 = T[0, 0] * P_top[i, 0] + T[0, 1] * P_top[i, 1] + T[0, 2] * P_top[i, 2] + T[0, 3]
        d1 = T[1, 0] * P_top[i, 0] + T[1, 1] * P_top[i, 1] + T[1, 2] * P_top[i, 2] + T[1, 3]
        d2 = T[2, 0] * P_top[i, 0] + T[2, 1] * P_top[i, 1] + T[2, 2] * P_top[i, 2] + T[2, 3]
        d0, d1, d2 = d0 - B[i, 0], d1 - B[i, 1], d2 - B[i, 2]
        l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not l > 0.0:
            return False
        S0, S1, S2 = d0 / l, d1 / l, d2 / l
        b0, b1, b2 = B[i, 0], B[i, 1], B[i, 2]
        dl[i] = ((b1 * S2 - b2 * S1) * D[0] + (b2 * S0 - b0 * S2) * D[1]
                 + (b0 * S1 - b1 * S0) * D[2] + S0 * D[3] + S1 * D[4] + S2 * D[5])
    Rd = np.eye(3)
    th = math.sqrt(D[0] * D[0] + D[1] * D[1] + D[2] * D[2])
    if th > 0.0:  # Rodrigues: I + sin θ [k]× + (1 − cos θ) [k]×²
        k0, k1, k2 = D[0] / th, D[1] / th, D[2] / th
        s, h = math.sin(th), 2.0 * math.sin(0.5 * th) ** 2
        Rd[0, 0] = 1.0 - h * (k1 * k1 + k2 * k2)
        Rd[1, 1] = 1.0 - h * (k0 * k0 + k2 * k2)
        Rd[2, 2] = 1.0 - h * (k0 * k0 + k1 * k1)
        Rd[0, 1] = -s * k2 + h * k0 * k1
        Rd[1, 0] = s * k2 + h * k0 * k1
        Rd[0, 2] = s * k1 + h * k0 * k2
        Rd[2, 0] = -s * k1 + h * k0 * k2
        Rd[1, 2] = -s * k0 + h * k1 * k2
        Rd[2, 1] = s * k0 + h * k1 * k2
    for r in range(4):
        for c in range(4):
            top[r, c] = 0.0
    top[3, 3] = 1.0
    for r in range(3):
        for c in range(3):
            top[r, c] = Rd[r, 0] * T[0, c] + Rd[r, 1] * T[1, c] + Rd[r, 2] * T[2, c]
        top[r, 3] = Rd[r, 0] * T[0, 3] + Rd[r, 1] * T[1, 3] + Rd[r, 2] * T[2, 3] + D[3 + r]
    return True


@nb.njit(**_OPTS)
def _solve3(A, r, x):
    """``x = A⁻¹ r`` for a (3, 3) ``A`` (Gaussian elimination, partial pivoting); False when
    ``A`` is singular."""
    M = np.empty((3, 4))
    for i in range(3):
        for j in range(3):
            M[i, j] = A[i, j]
        M[i, 3] = r[i]
    if not eliminate(M, 3, 0.0, None) > 0.0:
        return False
    for i in range(3):
        x[i] = M[i, 3]
    return True
