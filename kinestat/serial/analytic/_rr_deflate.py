"""Deflation of the spurious roots ``x = ±i`` from the Raghavan–Roth companion matrix.

The matrix quadratic ``A(x) = A2 x² + A1 x + A0`` of the general 6R (12x12) has
``det A(x) = (1 + x²)⁴ p16(x)``: the half-angle substitution brings the factor ``1 + x²``,
and the 24x24 companion ``C = [0 I; −A2⁻¹A0 −A2⁻¹A1]`` carries the 8 eigenvalues ±i beside the
16 of ``p16``. Their eigenvectors are known without solving: every null vector ``v = a + i b``
of ``A(i)`` gives the companion's eigenvector ``[v; i v]`` (and its conjugate for −i), so the
real subspace ``W`` spanned by ``[a; −b]`` and ``[b; a]`` is invariant under C. The
eigenvalues of C on the quotient ``R²⁴ / W`` are the remaining ones:

1. the null space of the complex ``A(i) = A0 − A2 + i A1`` by Gaussian elimination with
   complete pivoting (its numerical rank: pivots below ``RANK_TOL`` of the first);
2. a basis ``G`` of W with ``G[p] = I`` on 2d pivot rows p (Gauss–Jordan with complete
   pivoting on the basis, so ``|G| ≤ 1``);
3. the quotient map on the other coordinates ``np``: ``H = C[np, np] − G[np] C[p, np]``
   ((24 − 2d)², 16x16 where d = 4), whose eigenvalues :func:`kinestat.serial.analytic._hqr.
   eigvals` computes (LAPACK's dgeev where its iteration fails) at about a third of the
   24x24's cost.

A Möbius change of the variable ``x = (y + t)/(1 − t y)`` maps ±i to ±i and keeps the null
vectors (``B(y) = (1 − t y)² A(x)``), so the same W deflates the transformed companion. Where
the null space is not found (nullity 0 or above 4) nothing is deflated.

The null space does not depend on the pose: ``A(x)`` is ``Nᵀ`` (the left null space of Q, per
pose) times the 14 equations ``L H3 − r0 h0ᵀ`` in the power products, and at ``x = ±i`` the
pose's part ``r0 h0ᵀ`` vanishes exactly (``h0`` carries the factor ``1 + x3²``). The null
space of the 14 equations at ``x3 = i`` (28x12 with the x4-shifted copy, pose-independent) is
therefore contained in every pose's; where it has dimension 4 it is all of it, and
:func:`model_basis` computes W once per model (an SVD), so steps 1-2 leave the per-pose work.
"""

from __future__ import annotations

import numba as nb
import numpy as np
from numba import types
from numba.np.linalg import _LAPACK

from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._hqr import eigvals

__all__ = ["RANK_TOL", "deflate_scratch", "deflated_eigvals", "spurious_basis", "model_basis",
           "no_basis"]

_rgeev = _LAPACK().numba_ez_rgeev(types.float64)

#: a pivot of the elimination of A(i) below this fraction of the first ends its rank
RANK_TOL = 1e-9
_MAX_NULL = 4  # the factor (1 + x²)⁴


@nb.njit(**_OPTS)
def deflate_scratch():
    """Work arrays of :func:`deflated_eigvals`: complex A(i) (12, 12), its column order (12,),
    the null basis (12, 4), the real basis transposed (8, 24), pivot rows (8,), the row mask
    (24,), the column-major copy of the quotient for dgeev (576,), the quotient matrix (24, 24),
    the quotient's coordinate maps (48,) and the companion's free columns (12, 24)."""
    return (np.empty((12, 12), dtype=np.complex128), np.empty(12, dtype=np.int64),
            np.empty((12, 4), dtype=np.complex128), np.empty((8, 24)),
            np.empty(8, dtype=np.int64), np.empty(24, dtype=np.int64), np.empty(576),
            np.empty((24, 24)), np.empty(48, dtype=np.int64), np.empty((12, 24)))


@nb.njit(**_OPTS)
def _null_at_i(A, U, cperm, Nv):
    """Null vectors of ``A(i) = A0 − A2 + i A1`` into ``Nv[:, :d]``; returns d (0 when the
    nullity exceeds 4)."""
    for i in range(12):
        cperm[i] = i
        for j in range(12):
            U[i, j] = complex(A[0, i, j] - A[2, i, j], A[1, i, j])
    first = 0.0
    r = 12
    for k in range(12):
        bi, bj, best = k, k, -1.0
        for i in range(k, 12):
            for j in range(k, 12):
                u = U[i, j]
                a = u.real * u.real + u.imag * u.imag
                if a > best:
                    bi, bj, best = i, j, a
        if k == 0:
            first = best
        if not best > RANK_TOL * RANK_TOL * first:  # squared moduli
            r = k
            break
        if bi != k:
            for j in range(12):
                U[k, j], U[bi, j] = U[bi, j], U[k, j]
        if bj != k:
            for i in range(12):
                U[i, k], U[i, bj] = U[i, bj], U[i, k]
            cperm[k], cperm[bj] = cperm[bj], cperm[k]
        piv = U[k, k]
        for i in range(k + 1, 12):
            f = U[i, k] / piv
            if f != 0.0:
                for j in range(k + 1, 12):
                    U[i, j] -= f * U[k, j]
            U[i, k] = 0.0
    d = 12 - r
    if d == 0 or d > _MAX_NULL:
        return 0
    z = np.empty(12, dtype=np.complex128)
    for e in range(d):
        # z = [−U11⁻¹ U12 e; e] in the permuted columns
        for k in range(r, 12):
            z[k] = 1.0 if k == r + e else 0.0
        for k in range(r - 1, -1, -1):
            acc = -U[k, r + e]
            for j in range(k + 1, r):
                acc -= U[k, j] * z[j]
            z[k] = acc / U[k, k]
        for k in range(12):
            Nv[cperm[k], e] = z[k]
    return d


@nb.njit(**_OPTS)
def spurious_basis(A, S):
    """The invariant subspace of ±i as ``Bt (2d, 24)`` (in ``S[3]``) in Gauss–Jordan form:
    ``Bt[:, p] = I`` on the pivot rows ``p = S[4][:2d]``, ``S[5]`` marking them; returns 2d (0:
    no deflation). ``S``: :func:`deflate_scratch`."""
    d = _null_at_i(A, S[0], S[1], S[2])
    return _gauss_jordan(S[2], d, S[3], S[4], S[5])


@nb.njit(**_OPTS)
def _gauss_jordan(Nv, d, Bt, p, mask):
    """The real basis ``[a; −b]``, ``[b; a]`` of the null vectors ``Nv[:, :d] = a + i b`` into
    ``Bt (2d, 24)`` in Gauss–Jordan form with complete pivoting (pivot columns into p, marked in
    mask); returns 2d (0: no deflation)."""
    m = 2 * d
    for e in range(d):
        for i in range(12):
            a, b = Nv[i, e].real, Nv[i, e].imag
            Bt[2 * e, i] = a
            Bt[2 * e, 12 + i] = -b
            Bt[2 * e + 1, i] = b
            Bt[2 * e + 1, 12 + i] = a
    for j in range(24):
        mask[j] = 0
    for k in range(m):
        bi, bj, best = k, 0, -1.0
        for i in range(k, m):
            for j in range(24):
                if mask[j] == 0 and abs(Bt[i, j]) > best:
                    bi, bj, best = i, j, abs(Bt[i, j])
        if not best > 0.0:
            return 0
        if bi != k:
            for j in range(24):
                Bt[k, j], Bt[bi, j] = Bt[bi, j], Bt[k, j]
        p[k] = bj
        mask[bj] = 1
        piv = Bt[k, bj]
        for j in range(24):
            Bt[k, j] /= piv
        for i in range(m):
            if i != k:
                f = Bt[i, bj]
                if f != 0.0:
                    for j in range(24):
                        Bt[i, j] -= f * Bt[k, j]
    return m


def no_basis() -> tuple[np.ndarray, np.ndarray]:
    """The ``(basis, index)`` arguments of :func:`deflated_eigvals` that make it find the basis
    per pose (:func:`spurious_basis`)."""
    return np.zeros((8, 24)), np.zeros(33, dtype=np.int64)


def model_basis(LH: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pose-independent basis of the spurious subspace from the model's ``L H3 (14, 27)``
    (columns ``k*9 + 3i + j``: powers k of x3, i of x4, j of x5): ``(basis (8, 24), index
    (33,))``, index = [2d, the pivot columns (8), the pivot mask (24)], as :func:`spurious_basis`
    leaves them in its scratch; :func:`no_basis` where the null space at ``x3 = i`` is not
    4-dimensional (the kernel then finds it per pose)."""
    Ai = LH[:, 0:9] - LH[:, 18:27] + 1j * LH[:, 9:18]  # Σ_k i^k LH_k
    B = np.zeros((28, 12), dtype=complex)
    B[:14, :9] = Ai
    B[14:, 3:] = Ai  # the equations times x4
    _, s, Vh = np.linalg.svd(B)
    d = int(np.sum(s <= RANK_TOL * s[0]))
    if d != _MAX_NULL:
        return no_basis()
    Nv = np.ascontiguousarray(Vh[-d:].conj().T)
    Bt = np.zeros((8, 24))
    index = np.zeros(33, dtype=np.int64)
    m = _gauss_jordan(Nv, d, Bt, index[1:9], index[9:])
    if m != 2 * d:
        return no_basis()
    index[0] = m
    return Bt, index


@nb.njit(**_OPTS)
def _quotient(X, Bt, p, mask, m, Hm, maps, Xf):
    """The quotient map of the companion ``C = [0 I; −X]`` on the coordinates outside the pivots
    p (mask) into ``Hm[:24 − m, :24 − m]``: ``C[np, np] − Bt[:, np]ᵀ C[p, np]``; C's rows
    ``pk < 12`` are unit rows, so their terms are a single entry each. ``maps (48,)``,
    ``Xf (12, 24)``: scratch."""
    n = 24 - m
    free = maps[:24]
    col = maps[24:]  # the quotient column of a free coordinate, or −1
    a = 0
    for r in range(24):
        if m > 0 and mask[r] == 1:
            col[r] = -1
        else:
            free[a] = r
            col[r] = a
            a += 1
    for i in range(12):  # X's free columns, contiguous
        for b in range(n):
            Xf[i, b] = X[i, free[b]]
    for a in range(n):
        r = free[a]
        if r < 12:
            for b in range(n):
                Hm[a, b] = 0.0
            if col[r + 12] >= 0:
                Hm[a, col[r + 12]] = 1.0
        else:
            for b in range(n):
                Hm[a, b] = -Xf[r - 12, b]
        for k in range(m):  # row-wise: independent additions, in the same order per entry
            pk = p[k]
            if pk >= 12:
                f = Bt[k, r]
                for b in range(n):
                    Hm[a, b] += f * Xf[pk - 12, b]
        for k in range(m):
            pk = p[k]
            if pk < 12 and col[pk + 12] >= 0:
                Hm[a, col[pk + 12]] -= Bt[k, r]


@nb.njit(**_OPTS)
def deflated_eigvals(A, X, wr, wi, dummy, S, basis, index):
    """Eigenvalues (into wr, wi; 24 of them) of the companion ``C = [0 I; −X]`` (``X (12,
    24)`` = ``A2⁻¹ [A0 A1]``, of A or of its Möbius transform) with the invariant subspace of ±i
    of ``A (3, 12, 12)`` deflated: the eigenvalues of the (24 − 2d)² quotient (``_hqr``, or
    LAPACK's dgeev where it fails), the 2d deflated slots set to ±i. ``(basis, index)``: the
    model's basis (:func:`model_basis`), or :func:`no_basis` to find it from A. Returns 0 on
    success (else dgeev's info)."""
    F, Hm = S[6], S[7]
    if index[0] > 0:
        m = index[0]
        Bt, p, mask = basis, index[1:9], index[9:]
    else:
        m = spurious_basis(A, S)
        Bt, p, mask = S[3], S[4], S[5]
    n = 24 - m
    _quotient(X, Bt, p, mask, m, Hm, S[8], S[9])
    if eigvals(Hm, n, wr, wi):
        info = 0
    else:  # the QR iteration did not converge: LAPACK on a column-major copy
        _quotient(X, Bt, p, mask, m, Hm, S[8], S[9])
        for a in range(n):
            for b in range(n):
                F[b * n + a] = Hm[a, b]
        info = _rgeev(ord("d"), ord("N"), ord("N"), n, F.ctypes, n, wr.ctypes, wi.ctypes,
                      dummy.ctypes, 1, dummy.ctypes, 1)
    for k in range(n, 24):
        wr[k] = 0.0
        wi[k] = 1.0 if (k - n) % 2 == 0 else -1.0
    return info
