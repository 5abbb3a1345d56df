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
"""

from __future__ import annotations

import numba as nb
import numpy as np
from numba import types
from numba.np.linalg import _LAPACK

from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._hqr import eigvals

__all__ = ["RANK_TOL", "deflate_scratch", "deflated_eigvals", "spurious_basis"]

_rgeev = _LAPACK().numba_ez_rgeev(types.float64)

#: a pivot of the elimination of A(i) below this fraction of the first ends its rank
RANK_TOL = 1e-9
_MAX_NULL = 4  # the factor (1 + x²)⁴


@nb.njit(**_OPTS)
def deflate_scratch():
    """Work arrays of :func:`deflated_eigvals`: complex A(i) (12, 12), its column order (12,),
    the null basis (12, 4), the real basis transposed (8, 24), pivot rows (8,), the row mask
    (24,), the quotient matrix (24, 24) and its column-major copy for dgeev (576,)."""
    return (np.empty((12, 12), dtype=np.complex128), np.empty(12, dtype=np.int64),
            np.empty((12, 4), dtype=np.complex128), np.empty((8, 24)),
            np.empty(8, dtype=np.int64), np.empty(24, dtype=np.int64), np.empty(576),
            np.empty((24, 24)))


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
    U, cperm, Nv, Bt, p, mask = S[0], S[1], S[2], S[3], S[4], S[5]
    d = _null_at_i(A, U, cperm, Nv)
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


@nb.njit(**_OPTS)
def deflated_eigvals(A, X, wr, wi, dummy, S):
    """Eigenvalues (into wr, wi; 24 of them) of the companion ``C = [0 I; −X]`` (``X (12,
    24)`` = ``A2⁻¹ [A0 A1]``, of A or of its Möbius transform) with the invariant subspace of ±i
    of ``A (3, 12, 12)`` deflated: the eigenvalues of the (24 − 2d)² quotient (``_hqr``, or
    LAPACK's dgeev where it fails), the 2d deflated slots set to ±i. Returns 0 on success
    (else dgeev's info)."""
    Bt, p, mask, F, Hm = S[3], S[4], S[5], S[6], S[7]
    m = spurious_basis(A, S)
    n = 24 - m
    # quotient map on the unmarked coordinates; C[r, c] = δ(c, r + 12) (r < 12), −X[r−12, c];
    # the pivot rows of C first (Cp, in the free rows of F)
    Cp = F[:24 * m].reshape((m, 24)) if m > 0 else F[:24].reshape((1, 24))
    for k in range(m):
        pk = p[k]
        for c in range(24):
            if pk < 12:
                Cp[k, c] = 1.0 if c == pk + 12 else 0.0
            else:
                Cp[k, c] = -X[pk - 12, c]
    a = 0
    for r in range(24):
        if mask[r] == 1 and m > 0:
            continue
        b = 0
        for c in range(24):
            if mask[c] == 1 and m > 0:
                continue
            if r < 12:
                h = 1.0 if c == r + 12 else 0.0
            else:
                h = -X[r - 12, c]
            for k in range(m):
                h -= Bt[k, r] * Cp[k, c]
            Hm[a, b] = h
            b += 1
        a += 1
    for a in range(n):  # a column-major copy (Cp is no longer needed) for LAPACK
        for b in range(n):
            F[b * n + a] = Hm[a, b]
    if eigvals(Hm, n, wr, wi):
        info = 0
    else:  # the QR iteration did not converge: LAPACK
        info = _rgeev(ord("d"), ord("N"), ord("N"), n, F.ctypes, n, wr.ctypes, wi.ctypes,
                      dummy.ctypes, 1, dummy.ctypes, 1)
    for k in range(n, 24):
        wr[k] = 0.0
        wi[k] = 1.0 if (k - n) % 2 == 0 else -1.0
    return info
