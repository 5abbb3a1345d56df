"""Compiled (Numba) kernel of the Raghavan–Roth general 6R solver: the same steps as
:mod:`kinestat.serial.analytic.general6r` (which stays the NumPy reference and the fallback for
poses the kernel flags), one pose at a time, batches split over the cores with ``prange``.

Per pose: the pose link ``C0⁻¹ T C6⁻¹`` (or its inverse) of the formulation, the right side of
RR eq. 4 (15x15 rigid action), a pivoted Householder QR of Q (its left null space; the
least-squares back-substitution), the 12x12 matrix quadratic, the eigenvalues of its
companion with the spurious ±i deflated (:mod:`kinestat.serial.analytic._rr_deflate`: the
compiled QR iteration on 16x16), the power-product vector of each real root
(:mod:`kinestat.serial.analytic._rr_null`), back-substitution, θ6 (the serial FK kernel's
scalar steps), Newton polishing against FK, verification and de-duplication
(:mod:`kinestat.serial.analytic._solution_kernels`). On a suspect pose (``_rr_qz.suspect``: a
lost real root, an odd real count, a complex pair within the double-root split of the
observed eigenvalue error, a nearly singular leading coefficient; about 1 % of Jaco2-type
poses, fewer on general arms) the roots are recovered again from the QZ eigenvalues of the
companion pencil (:mod:`kinestat.serial.analytic._rr_qz`), which are backward stable where the
companion's are not: clustered real roots. Every work array is allocated once per chunk of
poses (:func:`_scratch`), not per root or per step; only dgeev allocates its workspace.
Flags: 0 solved, 1 Q rank deficient, 2 dggev failed (the caller reruns the pose with the NumPy
reference).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.serial._kernels import _affine, _turn
from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial._sincos import sincos
from kinestat.serial.analytic._rr_deflate import deflate_scratch, deflated_eigvals
from kinestat.serial.analytic._rr_null import TINY_PIVOT as _TINY_PIVOT
from kinestat.serial.analytic._rr_null import null_vector as _null_vector
from kinestat.serial.analytic._rr_qz import nearly_real, pencil_eigvals_qz, qz_scratch, suspect
from kinestat.serial.analytic._solution_kernels import polish, store
from kinestat.spatial._elimination import eliminate

FLAG_OK = 0
FLAG_DEFICIENT = 1
FLAG_ILL_CONDITIONED = 2
_CHUNK = 16  # poses per scratch allocation in the parallel loop
#: A2's smallest relative pivot below which the variable is changed (:func:`_companion_eigvals`):
#: the companion's spurious eigenvalues ±i are defective (4-fold), so an ill-conditioned A2 can
#: move even the real roots by percent (a Jaco2 pose at 5e-8 lost two of its three solutions)
_A2_PIVOT_MIN = 1e-5
#: the Möbius parameters tried in turn (0: the plain variable)
_MOBIUS = (0.0, 0.7, -1.3, 2.9)


@nb.njit(**_INLINE)
def _rigid_product(A, B, C, out):
    """``out = A B C`` for rigid 4x4 arrays (bottom row [0, 0, 0, 1])."""
    for i in range(3):
        ab0 = A[i, 0] * B[0, 0] + A[i, 1] * B[1, 0] + A[i, 2] * B[2, 0]
        ab1 = A[i, 0] * B[0, 1] + A[i, 1] * B[1, 1] + A[i, 2] * B[2, 1]
        ab2 = A[i, 0] * B[0, 2] + A[i, 1] * B[1, 2] + A[i, 2] * B[2, 2]
        ab3 = A[i, 0] * B[0, 3] + A[i, 1] * B[1, 3] + A[i, 2] * B[2, 3] + A[i, 3]
        for j in range(4):
            out[i, j] = ab0 * C[0, j] + ab1 * C[1, j] + ab2 * C[2, j]
        out[i, 3] += ab3
    out[3, 0] = 0.0
    out[3, 1] = 0.0
    out[3, 2] = 0.0
    out[3, 3] = 1.0


@nb.njit(**_INLINE)
def _rigid_inverse(T, out):
    """``out = T⁻¹`` for a rigid 4x4 array."""
    for i in range(3):
        for j in range(3):
            out[i, j] = T[j, i]
        out[i, 3] = -(T[0, i] * T[0, 3] + T[1, i] * T[1, 3] + T[2, i] * T[2, 3])
        out[3, i] = 0.0
    out[3, 3] = 1.0


@nb.njit(**_OPTS)
def _rigid_action_inv(T, M):
    """``M = rigid_action(T⁻¹)`` (see ``_rr_algebra.rigid_action``), T rigid 4x4."""
    M[:, :] = 0.0
    R = (T[0, 0], T[1, 0], T[2, 0], T[0, 1], T[1, 1], T[2, 1], T[0, 2], T[1, 2], T[2, 2])
    t0 = -(R[0] * T[0, 3] + R[1] * T[1, 3] + R[2] * T[2, 3])
    t1 = -(R[3] * T[0, 3] + R[4] * T[1, 3] + R[5] * T[2, 3])
    t2 = -(R[6] * T[0, 3] + R[7] * T[1, 3] + R[8] * T[2, 3])
    t = (t0, t1, t2)
    tt = t0 * t0 + t1 * t1 + t2 * t2
    M[0, 0] = 1.0
    M[7, 7] = 1.0
    M[8, 8] = 1.0
    M[7, 0] = tt
    for j in range(3):
        tRj = t0 * R[j] + t1 * R[3 + j] + t2 * R[6 + j]
        M[7, 1 + j] = 2.0 * tRj
        M[8, 4 + j] = tRj
        for i in range(3):
            Rij = R[3 * i + j]
            # ([t]x R)_ij = (t x R[:, j])_i
            i1 = (i + 1) % 3
            i2 = (i + 2) % 3
            txR = t[i1] * R[3 * i2 + j] - t[i2] * R[3 * i1 + j]
            M[1 + i, 1 + j] = Rij
            M[4 + i, 4 + j] = Rij
            M[9 + i, 9 + j] = Rij
            M[12 + i, 12 + j] = Rij
            M[9 + i, 4 + j] = txR
            M[12 + i, 9 + j] = -2.0 * txR
            M[12 + i, 4 + j] = tt * Rij - 2.0 * t[i] * tRj
    for i in range(3):
        M[1 + i, 0] = t[i]
        M[12 + i, 8] = -2.0 * t[i]


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
def _right_side(M1, Ts, Rh, MA, f, u, o, w):
    """``Rh (15, 9)``: invariants of ``Z2⁻¹ M1⁻¹ Z1⁻¹ (p, l)`` of the target Ts, column a*3+b
    multiplying ``m_a(θ1) m_b(θ2)``; MA (15, 15), f, u, o, w (15,) are scratch."""
    _rigid_action_inv(M1, MA)
    p0, p1, p2 = Ts[0, 3], Ts[1, 3], Ts[2, 3]
    l0, l1, l2 = Ts[0, 2], Ts[1, 2], Ts[2, 2]
    pp = p0 * p0 + p1 * p1 + p2 * p2
    pl = p0 * l0 + p1 * l1 + p2 * l2
    f[0] = 1.0
    f[1], f[2], f[3] = p0, p1, p2
    f[4], f[5], f[6] = l0, l1, l2
    f[7] = pp
    f[8] = pl
    f[9], f[10], f[11] = p1 * l2 - p2 * l1, p2 * l0 - p0 * l2, p0 * l1 - p1 * l0
    f[12], f[13], f[14] = pp * l0 - 2.0 * pl * p0, pp * l1 - 2.0 * pl * p1, pp * l2 - 2.0 * pl * p2
    for a in range(3):
        _apply_d(a, -1.0, f, u)
        for i in range(15):
            acc = 0.0
            for j in range(15):
                acc += MA[i, j] * u[j]
            w[i] = acc
        for b in range(3):
            _apply_d(b, -1.0, w, o)
            for i in range(15):
                Rh[i, a * 3 + b] = o[i]


@nb.njit(**_OPTS)
def _qr_pivoted(Rh, H, R, piv, Vr, Aw):
    """Householder QR with column pivoting of ``Q = Rh[1:, 1:] (14, 8)``:
    ``Q[:, piv] = H[:, :8] R`` with ``H (14, 14)`` orthogonal (its last 6 columns span the left
    null space of Q) and ``R (8, 8)`` upper triangular, |R[k, k]| non-increasing. Vr (8, 14),
    Aw (14, 8): scratch (the reflectors and the working copy)."""
    for i in range(14):
        for j in range(8):
            Aw[i, j] = Rh[i + 1, j + 1]
    for j in range(8):
        piv[j] = j
    for k in range(8):
        best, jb = -1.0, k
        for j in range(k, 8):
            nj = 0.0
            for i in range(k, 14):
                nj += Aw[i, j] * Aw[i, j]
            if nj > best:
                best, jb = nj, j
        if jb != k:
            for i in range(14):
                Aw[i, k], Aw[i, jb] = Aw[i, jb], Aw[i, k]
            piv[k], piv[jb] = piv[jb], piv[k]
        alpha = math.sqrt(best)
        if Aw[k, k] > 0.0:
            alpha = -alpha
        vv = 0.0
        for i in range(14):
            Vr[k, i] = Aw[i, k] if i >= k else 0.0
        Vr[k, k] -= alpha
        for i in range(k, 14):
            vv += Vr[k, i] * Vr[k, i]
        if vv > 0.0:
            for j in range(k, 8):
                d = 0.0
                for i in range(k, 14):
                    d += Vr[k, i] * Aw[i, j]
                d *= 2.0 / vv
                for i in range(k, 14):
                    Aw[i, j] -= d * Vr[k, i]
            for i in range(k, 14):
                Vr[k, i] /= math.sqrt(vv / 2.0)  # now H_k = I − v vᵀ
        else:
            for i in range(14):
                Vr[k, i] = 0.0
    for i in range(8):
        for j in range(8):
            R[i, j] = Aw[i, j] if j >= i else 0.0
    # H = H_1 H_2 … H_8, applied to the identity from the left in reverse order (H_k leaves
    # the unit columns j < k of H_k+1 … H_8 as they are)
    for i in range(14):
        for j in range(14):
            H[i, j] = 1.0 if i == j else 0.0
    for k in range(7, -1, -1):
        for j in range(k, 14):
            d = 0.0
            for i in range(k, 14):
                d += Vr[k, i] * H[i, j]
            if d != 0.0:
                for i in range(k, 14):
                    H[i, j] -= d * Vr[k, i]


@nb.njit(**_OPTS)
def _pencil(LH, h0, Rh, A, E, H, R, piv, Vr, Aw):
    """Fill ``A (3, 12, 12)`` from ``E = Nᵀ (L H3 − r0 h0ᵀ)`` (N the left null space of Q,
    r0 = Rh[1:, 0]) and the pivoted QR of Q into H, R, piv; returns the flag (Q rank
    deficient: |R[7, 7]| ≤ 1e-10 |R[0, 0]|)."""
    _qr_pivoted(Rh, H, R, piv, Vr, Aw)
    if not abs(R[7, 7]) > 1e-10 * abs(R[0, 0]):
        return FLAG_DEFICIENT
    for e in range(6):
        nr = 0.0
        for i in range(14):
            nr += H[i, 8 + e] * Rh[i + 1, 0]
        for c in range(27):
            acc = -nr * h0[c]
            for i in range(14):
                acc += H[i, 8 + e] * LH[i, c]
            E[e, c] = acc
    A[:, :, :] = 0.0
    for k in range(3):
        for e in range(6):
            for m in range(9):
                A[k, e, m] = E[e, k * 9 + m]
                A[k, 6 + e, 3 + m] = E[e, k * 9 + m]
    return FLAG_OK


@nb.njit(**_OPTS)
def _companion_eigvals(A, XA, wr, wi, dummy, D, basis, index):
    """Eigenvalues (into wr, wi) of ``A2 x² + A1 x + A0`` (A normalised in place) through the
    companion with the inverse leading coefficient, its 8 spurious eigenvalues ±i deflated
    first (:func:`kinestat.serial.analytic._rr_deflate.deflated_eigvals`: the 16x16 quotient).

    When A2 is ill-conditioned (smallest relative pivot below ``_A2_PIVOT_MIN``) the variable
    is changed by the Möbius map ``x = (y + t)/(1 − t y)`` (a shift of the half-angle by
    atan t): ``B(y) = (1 − t y)² A(x)`` has the leading coefficient ``A0 t² − A1 t + A2``,
    regular unless −1/t is itself a root. Returns the leading coefficient's smallest relative
    pivot, 0 when no tried t gives a regular one (or the eigensolver fails).
    ``XA (12, 36)``: ``[A2 | A0 A1]`` solved in place to ``[· | X]``, ``X = A2⁻¹ [A0 A1]``;
    D: :func:`~kinestat.serial.analytic._rr_deflate.deflate_scratch`; ``(basis, index)``: the
    model's spurious subspace (:func:`~kinestat.serial.analytic._rr_deflate.model_basis`)."""
    s0 = s1 = s2 = 0.0  # three independent maxima, not one chain
    for i in range(12):
        for j in range(12):
            s0 = max(s0, abs(A[0, i, j]))
            s1 = max(s1, abs(A[1, i, j]))
            s2 = max(s2, abs(A[2, i, j]))
    sc = max(s0, max(s1, s2))
    # scaled by the power of 2 at or above the largest entry: exact, a product not a quotient
    g = math.ldexp(1.0, -math.frexp(sc)[1]) if 0.0 < sc < np.inf else 1.0 / sc
    for k in range(3):
        for i in range(12):
            for j in range(12):
                A[k, i, j] *= g
    t = 0.0
    regular = False
    pivot = 0.0
    for t in _MOBIUS:
        tt = t * t
        for i in range(12):
            for j in range(12):
                a0, a1, a2 = A[0, i, j], A[1, i, j], A[2, i, j]
                if t == 0.0:  # the plain variable (most poses): a copy
                    XA[i, 12 + j] = a0
                    XA[i, 24 + j] = a1
                    XA[i, j] = a2
                else:
                    XA[i, 12 + j] = a0 + t * a1 + tt * a2
                    XA[i, 24 + j] = -2.0 * t * a0 + (1.0 - tt) * a1 + 2.0 * t * a2
                    XA[i, j] = tt * a0 - t * a1 + a2
        pivot = eliminate(XA, 12, _TINY_PIVOT, None)
        if pivot >= _A2_PIVOT_MIN:
            regular = True
            break
    if not regular:
        return 0.0
    X = XA[:, 12:]
    for i in range(12):
        for j in range(24):
            if not abs(X[i, j]) <= 1e10:  # not finite, or too large
                return 0.0
    info = deflated_eigvals(A, X, wr, wi, dummy, D, basis, index)
    if t != 0.0:  # back to x = (y + t) / (1 − t y)
        for k in range(24):
            x = (complex(wr[k], wi[k]) + t) / (1.0 - t * complex(wr[k], wi[k]))
            wr[k] = x.real
            wi[k] = x.imag
    return pivot if info == 0 else 0.0


@nb.njit(**_INLINE)
def _ratio(v, axis):
    """Least-squares ratio along ``axis`` (0: x4, 1: x5) of the power products ``v[3i + j]``
    (i: power of x4, j: power of x5)."""
    num = 0.0
    den = 0.0
    if axis == 0:
        for i in range(3):
            for j in range(3):
                num += v[3 * (i + 1) + j, 0] * v[3 * i + j, 0]
                den += v[3 * i + j, 0] * v[3 * i + j, 0]
    else:
        for i in range(4):
            for j in range(2):
                num += v[3 * i + j + 1, 0] * v[3 * i + j, 0]
                den += v[3 * i + j, 0] * v[3 * i + j, 0]
    return num / den if den > 0 else np.nan


@nb.njit(**_INLINE)
def _half_angle(x, ph):
    """``(1, cos φ, sin φ)`` of ``φ = 2 atan x``: rational in x (no trigonometric calls) unless
    |x| is so large that x² would lose it."""
    if abs(x) < 1e100:
        d = 1.0 / (1.0 + x * x)
        return 1.0, (1.0 - x) * (1.0 + x) * d, 2.0 * x * d
    return 1.0, math.cos(ph), math.sin(ph)


@nb.njit(**_INLINE)
def _unit(c, s):
    """``(cos φ, sin φ)`` of ``φ = atan2(s, c)``: ``(c, s)`` normalised, ``(1, 0)`` at the
    origin."""
    h = math.sqrt(c * c + s * s)
    if not h > 0.0:
        return 1.0, 0.0
    g = 1.0 / h
    return c * g, s * g


@nb.njit(**_INLINE)
def _offset_turns(off):
    """``(cos, sin)`` of the three offsets, flat."""
    s0, c0 = sincos(off[0])
    s1, c1 = sincos(off[1])
    s2, c2 = sincos(off[2])
    return (c0, s0, c1, s1, c2, s2)


@nb.njit(**_OPTS)
def _angles(x3, v, off, cs, L, Rh, H, R, piv, M1, links, Ts, th, m, coef):
    """θ (6,) of the loop from a real root x3 and its power products ``v (12, 1)``; False if
    not usable. m (41,), coef (8,) scratch; ``links (4, 4, 4)`` the constant M2..M5; ``cs``
    the cosines and sines of the offsets ``off`` (:func:`_offset_turns`)."""
    x4 = _ratio(v, 0)
    x5 = _ratio(v, 1)
    if not (np.isfinite(x4) and np.isfinite(x5)):
        return False
    ph3 = 2.0 * math.atan(x3)
    ph4 = 2.0 * math.atan(x4)
    ph5 = 2.0 * math.atan(x5)
    m3 = _half_angle(x3, ph3)
    m4 = _half_angle(x4, ph4)
    m5 = _half_angle(x5, ph5)
    for a in range(3):
        for b in range(3):
            for c in range(3):
                m[a * 9 + b * 3 + c] = m3[a] * m4[b] * m5[c]
    # (c1, s1, c2, s2) products in least squares (Manocha–Canny eq. 9): R x = H₈ᵀ (L m − r0)
    r = m[27:]
    for i in range(14):
        r[i] = -Rh[i + 1, 0]
    for c in range(27):  # column by column: 14 independent sums, each in the order of c
        mc = m[c]
        for i in range(14):
            r[i] += L[i, c] * mc
    for j in range(8):
        coef[j] = 0.0
    for i in range(14):
        for j in range(8):
            coef[j] += H[i, j] * r[i]
    for k in range(7, -1, -1):
        acc = coef[k]
        for j in range(k + 1, 8):
            acc -= R[k, j] * coef[j]
        coef[k] = acc / R[k, k]
    S0 = S1 = S2 = S5 = 0.0
    for j in range(8):
        if piv[j] == 0:
            S0 = coef[j]
        elif piv[j] == 1:
            S1 = coef[j]
        elif piv[j] == 2:
            S2 = coef[j]
        elif piv[j] == 5:
            S5 = coef[j]
    th[0] = math.atan2(S5, S2)
    th[1] = math.atan2(S1, S0)
    th[2] = ph3 + off[0]
    th[3] = ph4 + off[1]
    th[4] = ph5 + off[2]
    # θ6 from Z6 = (Z1 M1 … Z5 M5)⁻¹ Ts; the turns from what is known (no sine or cosine)
    c, s = _unit(S2, S5)
    t = (c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    t = _affine(M1, t)
    c, s = _unit(S0, S1)
    t = _affine(links[0], _turn(c, s, t))
    t = _affine(links[1], _turn(m3[1] * cs[0] - m3[2] * cs[1], m3[2] * cs[0] + m3[1] * cs[1], t))
    t = _affine(links[2], _turn(m4[1] * cs[2] - m4[2] * cs[3], m4[2] * cs[2] + m4[1] * cs[3], t))
    t = _affine(links[3], _turn(m5[1] * cs[4] - m5[2] * cs[5], m5[2] * cs[4] + m5[1] * cs[5], t))
    # R6 = G_Rᵀ Ts_R: entries (0, 0), (0, 1), (1, 0), (1, 1)
    r00 = t[0] * Ts[0, 0] + t[4] * Ts[1, 0] + t[8] * Ts[2, 0]
    r01 = t[0] * Ts[0, 1] + t[4] * Ts[1, 1] + t[8] * Ts[2, 1]
    r10 = t[1] * Ts[0, 0] + t[5] * Ts[1, 0] + t[9] * Ts[2, 0]
    r11 = t[1] * Ts[0, 1] + t[5] * Ts[1, 1] + t[9] * Ts[2, 1]
    th[5] = math.atan2(r10 - r01, r00 + r11)
    return True


@nb.njit(**_OPTS)
def _scratch():
    """Work arrays of :func:`_solve_pose` (one set per chunk of poses)."""
    return (np.empty((3, 4, 4)), np.empty((15, 9)), np.empty((15, 15)), np.empty((5, 15)),
            np.empty((3, 12, 12)), np.empty((6, 27)), np.empty((12, 36)), np.empty((12, 12)),
            np.empty((1, 1)), np.empty((3, 24)), np.empty((12, 1)), np.empty(41),
            np.empty(8), np.empty((3, 6, 7)), np.empty((4, 6)), np.empty(6), np.empty(6),
            np.empty((14, 14)), np.empty((8, 8)), np.empty(8, dtype=np.int64), np.empty((8, 14)),
            np.empty((14, 8)), np.empty(12, dtype=np.int64), np.empty(12), deflate_scratch(),
            np.empty((16, 12)))


@nb.njit(**_OPTS)
def _recover(n, wr, wi, C, T, A, off, L, Rh, H, R, piv, M1, links, Ts, order, sign, tol, iters,
             dedup, out_q, out_valid, out_pos, out_rot, cnt, S):
    """Solutions of pose n from the real eigenvalues ``wr + i wi (24,)``: power products,
    angles, Newton polishing, verification, storage after the ``cnt`` already stored. Returns
    (the new count, real eigenvalues tried, of them lost: not verified or a repeat, the largest
    eigenvalue error ``|x − x*| / (1 + |x*|)`` against the polished root x*)."""
    A2, v, m, coef, Ms, Vs, th, q, perm, y12 = S[7], S[10], S[11], S[12], S[13], S[14], \
        S[15], S[16], S[22], S[23]
    W = S[25]
    tried = 0
    lost = 0
    err = 0.0
    cs = _offset_turns(off)
    for k in range(24):
        if not abs(wi[k]) <= 1e-6 * (1.0 + abs(wr[k])):
            continue
        tried += 1
        _null_vector(A, wr[k], A2, v, perm, y12, W)
        if not _angles(wr[k], v, off, cs, L, Rh, H, R, piv, M1, links, Ts, th, m, coef):
            lost += 1
            continue
        for i in range(6):
            q[order[i]] = sign * th[i]
        pos, rot = polish(C, T[n], q, iters, Ms, Vs)
        if not (pos <= tol and rot <= tol):
            lost += 1
            continue
        xs = math.tan(0.5 * (sign * q[order[2]] - off[0]))
        err = max(err, abs(wr[k] - xs) / (1.0 + abs(xs)))
        new = store(n, (q[0], q[1], q[2], q[3], q[4], q[5]), pos, rot, dedup, out_q, out_valid,
                    out_pos, out_rot, cnt)
        lost += new == cnt
        cnt = new
    return cnt, tried, lost, err


@nb.njit(**_OPTS)
def _solve_pose(n, C, T, form, links, LH, h0, L, off, order, sign, basis, index, tol, iters,
                dedup, recheck, out_q, out_valid, out_pos, out_rot, flags, counts, stats, S):
    """All solutions of pose n (its slots cleared first: q and errors NaN, valid False; the
    number of solutions into ``counts[n]``). ``form (4, 4, 4)``: C0⁻¹, C6⁻¹ and the constant
    M1 / Ts of the formulation; ``order[6:8]`` say which of M1 and Ts is the pose link (0
    constant, 1 ``G = C0⁻¹ T C6⁻¹``, 2 ``G⁻¹``). ``recheck``: 0 never, 1 on suspect poses
    (``_rr_qz.suspect``), 2 always: the roots are recovered again from the QZ eigenvalues,
    which replace the companion's (its solutions are dropped: near a fold a companion root
    can stall at a near-singular point within ``tol`` beside the two true roots).
    ``stats[n]``: see ``general6r.run_kernel``."""
    Gs, Rh, MA, V15, A, E, XA, W24 = S[0], S[1], S[2], S[3], S[4], S[5], S[6], S[9]
    H, R, piv, Vr, Aw = S[17], S[18], S[19], S[20], S[21]
    _clear(n, out_q, out_valid, out_pos, out_rot)
    counts[n] = 0
    _rigid_product(form[0], T[n], form[1], Gs[1])
    _rigid_inverse(Gs[1], Gs[2])
    Gs[0] = form[2]
    M1 = Gs[order[6]]
    if order[7] == 0:
        Ts = form[3]
    else:
        Ts = Gs[order[7]]
    _right_side(M1, Ts, Rh, MA, V15[0], V15[1], V15[2], V15[3])
    flag = _pencil(LH, h0, Rh, A, E, H, R, piv, Vr, Aw)
    if flag != FLAG_OK:
        flags[n] = flag
        return
    wr, wi = W24[0], W24[1]
    cnt, tried, lost, near, err = 0, 0, 0, np.inf, 0.0
    pivot = _companion_eigvals(A, XA, wr, wi, W24[2], S[24], basis, index)
    stats[n, 5] = pivot
    if pivot > 0.0:
        cnt, tried, lost, err = _recover(n, wr, wi, C, T, A, off, L, Rh, H, R, piv, M1, links,
                                         Ts, order, sign, tol, iters, dedup, out_q, out_valid,
                                         out_pos, out_rot, cnt, S)
        near = nearly_real(wr, wi)
        rerun = recheck == 2 or (recheck == 1 and suspect(tried, lost, near, err, pivot))
    else:
        rerun = True  # no usable companion: QZ is the only pass
    stats[n, 0] = tried
    stats[n, 1] = lost
    stats[n, 2] = near
    stats[n, 3] = cnt
    stats[n, 4] = 0.0
    stats[n, 6] = err
    flags[n] = FLAG_OK
    counts[n] = cnt
    if rerun:
        stats[n, 4] = 1.0
        if not pencil_eigvals_qz(A, wr, wi, qz_scratch()):  # allocated here: rare
            flags[n] = FLAG_ILL_CONDITIONED
            return
        _clear(n, out_q, out_valid, out_pos, out_rot)  # the QZ roots replace the companion's
        cnt = _recover(n, wr, wi, C, T, A, off, L, Rh, H, R, piv, M1, links, Ts, order, sign,
                       tol, iters, dedup, out_q, out_valid, out_pos, out_rot, 0, S)[0]
        counts[n] = cnt


@nb.njit(**_INLINE)
def _clear(n, out_q, out_valid, out_pos, out_rot):
    """Empty slots of pose n: q and errors NaN, valid False."""
    for j in range(out_valid.shape[1]):
        out_valid[n, j] = False
        out_pos[n, j] = np.nan
        out_rot[n, j] = np.nan
        for i in range(6):
            out_q[n, j, i] = np.nan


@nb.njit(parallel=True, **_OPTS)
def solve_batch(C, T, form, links, LH, h0, L, off, order, sign, basis, index, tol, iters, dedup,
                recheck, out_q, out_valid, out_pos, out_rot, flags, counts, stats):
    """All solutions of N poses (see the module docstring) into the outputs (any contents:
    every pose's slots are cleared first) and their numbers into ``counts (N,)``."""
    N = T.shape[0]
    for c in nb.prange((N + _CHUNK - 1) // _CHUNK):
        S = _scratch()
        for n in range(c * _CHUNK, min(N, (c + 1) * _CHUNK)):
            _solve_pose(n, C, T, form, links, LH, h0, L, off, order, sign, basis, index, tol,
                        iters, dedup, recheck, out_q, out_valid, out_pos, out_rot, flags, counts,
                        stats, S)


@nb.njit(**_OPTS)
def solve_serial(C, T, form, links, LH, h0, L, off, order, sign, basis, index, tol, iters, dedup,
                 recheck, out_q, out_valid, out_pos, out_rot, flags, counts, stats):
    """:func:`solve_batch` on one thread (small batches: no thread start-up)."""
    S = _scratch()
    for n in range(T.shape[0]):
        _solve_pose(n, C, T, form, links, LH, h0, L, off, order, sign, basis, index, tol, iters,
                    dedup, recheck, out_q, out_valid, out_pos, out_rot, flags, counts, stats,
                    S)
