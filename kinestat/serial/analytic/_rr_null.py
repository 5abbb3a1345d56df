"""The power-product vector of a real root of the Raghavan–Roth matrix quadratic, for the
compiled general-6R kernel (:mod:`kinestat.serial.analytic._rr_kernels`): the null vector of
``A(x) = A2 x² + A1 x + A0`` (12x12), whose entries ``x4^i x5^j`` give θ4 and θ5.

``A(x)`` repeats the six equations ``E(x)`` (6x9) on the power products shifted by x4, so the
null vector comes from a null basis of E and a 6x6 overlap system (:func:`_null_structured`);
where either is not clearly of the generic rank, from two steps of inverse iteration on the
12x12 LU (:func:`null_vector`).
"""

from __future__ import annotations

import math

import numba as nb

from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.spatial._elimination import eliminate

__all__ = ["TINY_PIVOT", "null_vector"]

#: relative pivot size below which a pivot is replaced (inverse iteration, the companion)
TINY_PIVOT = 1e-17
_B0 = (0.31, -0.72, 0.55, 0.13, -0.94, 0.67, -0.28, 0.81, -0.46, 0.19, 0.73, -0.35)


@nb.njit(**_OPTS)
def _lu_solve(A, perm, b, y):
    """``b ← A⁻¹ b`` with the LU factors and row order of :func:`eliminate`; y (n,)
    scratch."""
    n = A.shape[0]
    for i in range(n):
        acc = b[perm[i], 0]
        for j in range(i):
            acc -= A[i, j] * y[j]
        y[i] = acc
    for i in range(n - 1, -1, -1):
        acc = y[i]
        for j in range(i + 1, n):
            acc -= A[i, j] * b[j, 0]
        b[i, 0] = acc / A[i, i]


#: a pivot below this fraction of the first: the structured null vector is not clearly
#: determined (rank of E(x) below 6 or a second null vector), inverse iteration instead
_STRUCTURED_PIVOT = 1e-6


@nb.njit(**_INLINE)
def _pivot_step(M, k, rows, cols, cperm):
    """Step k of Gaussian elimination with complete pivoting on ``M[:rows, :cols]`` (column
    order into cperm); returns the pivot's modulus."""
    best = -1.0
    for i in range(k, rows):  # the largest modulus (no branch), then its first place
        for j in range(k, cols):
            best = max(best, abs(M[i, j]))
    bi, bj = k, k
    for i in range(k, rows):
        hit = False
        for j in range(k, cols):
            if abs(M[i, j]) == best:
                bi, bj, hit = i, j, True
                break
        if hit:
            break
    if bi != k:
        for j in range(cols):
            M[k, j], M[bi, j] = M[bi, j], M[k, j]
    if bj != k:
        for i in range(rows):
            M[i, k], M[i, bj] = M[i, bj], M[i, k]
        cperm[k], cperm[bj] = cperm[bj], cperm[k]
    if best > 0.0:
        for i in range(k + 1, rows):
            f = M[i, k] / M[k, k]
            for j in range(k + 1, cols):
                M[i, j] -= f * M[k, j]
            M[i, k] = 0.0
    return best


@nb.njit(**_INLINE)
def _eliminate_checked(M, steps, rows, cols, cperm):
    """``steps`` steps of :func:`_pivot_step` on ``M[:rows, :cols]``; False as soon as a pivot
    falls below ``_STRUCTURED_PIVOT`` times the first (the rank not clearly ``steps``)."""
    first = 0.0
    for k in range(steps):
        piv = _pivot_step(M, k, rows, cols, cperm)
        if k == 0:
            first = piv
        if not piv > _STRUCTURED_PIVOT * first:
            return False
    return True


@nb.njit(**_INLINE)
def _null_back_substitute(U, pivots, cols, z):
    """The null vector of the eliminated ``U[:pivots, :cols]`` (upper triangular in its first
    ``pivots`` columns) with the free entries ``z[pivots:cols]`` as given: back-substitution."""
    for k in range(pivots - 1, -1, -1):
        acc = 0.0
        for j in range(k + 1, cols):
            acc += U[k, j] * z[j]
        z[k] = -acc / U[k, k]


@nb.njit(**_OPTS)
def _null_structured(v, W, ce):
    """The null vector ``v (12, 1)`` of ``A(x)`` from its structure: rows 0-5 are
    ``E(x) (6, 9)`` (given in ``W[:6, :9]``) on the power products ``v[0:9]``, rows 6-11 the
    same on ``v[3:12]`` (the equations times x4). With N (9, 3) a null basis of E,
    ``v[0:9] = N a``, ``v[3:12] = N b`` and the overlap ``N[3:9] a = N[0:6] b`` is a 6x6
    singular system: two small eliminations with complete pivoting instead of the 12x12 LU.
    False (v untouched) where E's rank is not clearly 6 or the overlap's nullity not clearly 1
    (relative pivots below ``_STRUCTURED_PIVOT``). ``W (16, 12)``, ``ce (9,)`` (int):
    scratch."""
    E = W[:6, :9]
    M6 = W[6:12, :6]
    Nb = W[6:15, 6:9]
    z = W[15, :9]
    ab = W[12, :6]
    for j in range(9):
        ce[j] = j
    if not _eliminate_checked(E, 6, 6, 9, ce):
        return False
    for f in range(3):  # the null basis: free column 6 + f
        for j in range(6, 9):
            z[j] = 1.0 if j == 6 + f else 0.0
        _null_back_substitute(E, 6, 9, z)
        for j in range(9):
            Nb[ce[j], f] = z[j]
    for i in range(6):
        for f in range(3):
            M6[i, f] = Nb[3 + i, f]
            M6[i, 3 + f] = -Nb[i, f]
    cm = ce[:6]
    for j in range(6):
        cm[j] = j
    if not _eliminate_checked(M6, 5, 6, 6, cm):
        return False
    y = z[:6]
    y[5] = 1.0
    _null_back_substitute(M6, 5, 6, y)
    for j in range(6):
        ab[cm[j]] = y[j]
    nv = 0.0
    for i in range(12):
        acc = 0.0
        if i < 9:
            for f in range(3):
                acc += Nb[i, f] * ab[f]
        else:
            for f in range(3):
                acc += Nb[i - 3, f] * ab[3 + f]
        v[i, 0] = acc
        nv += acc * acc
    nv = math.sqrt(nv)
    if not nv > 0.0:
        return False
    for i in range(12):
        v[i, 0] /= nv
    return True


@nb.njit(**_OPTS)
def null_vector(A, x, S, v, perm, y, W):
    """The power-product vector ``v (12, 1)``: a null vector of ``A2 x² + A1 x + A0`` from its
    block structure (:func:`_null_structured`) or, where that is not clearly determined, by
    two steps of inverse iteration on one LU factorisation (the matrix is singular at an
    eigenvalue); S (12, 12), perm (12,), y (12,), W (:func:`_null_structured`) scratch. For
    |x| > 1 the matrix is divided by x² (better scaled)."""
    if abs(x) <= 1.0:
        c0, c1, c2 = 1.0, x, x * x
    else:
        c0, c1, c2 = 1.0 / (x * x), 1.0 / x, 1.0
    for i in range(6):  # E(x): all the structured path reads
        for j in range(9):
            W[i, j] = c0 * A[0, i, j] + c1 * A[1, i, j] + c2 * A[2, i, j]
    if _null_structured(v, W, perm):
        return
    for i in range(12):
        v[i, 0] = _B0[i]
    for i in range(12):
        for j in range(12):
            S[i, j] = c0 * A[0, i, j] + c1 * A[1, i, j] + c2 * A[2, i, j]
    eliminate(S, 12, TINY_PIVOT, perm)  # factors only; tiny pivots replaced
    for _ in range(2):
        _lu_solve(S, perm, v, y)
        nv = 0.0
        for i in range(12):
            nv += v[i, 0] * v[i, 0]
        nv = math.sqrt(nv)
        for i in range(12):
            v[i, 0] /= nv
