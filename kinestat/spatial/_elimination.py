"""One compiled (Numba) Gaussian elimination for the small dense systems of the kernels.

:func:`eliminate` works in place on an augmented matrix ``[A | B]``: LU factors of A with
partial pivoting (row interchanges over the whole row), the solution ``X = A⁻¹ B`` by back
substitution in the right-hand columns. The tiny-pivot rule is a parameter: the Newton steps
and the stiffness solves stop at a zero pivot, inverse iteration replaces tiny pivots so its
solution stays finite on a (by construction) singular matrix. Used by the all-solutions IK
kernels (:mod:`kinestat.serial.analytic`) and the platform's stiffness kernels
(:mod:`kinestat.parallel._stiffness_kernels`), hence this low layer. Compiled on first use and
cached on disk (``cache=True``).
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = ["eliminate"]

_OPTS = {"cache": True, "fastmath": False, "nogil": True, "error_model": "numpy"}


@nb.njit(**_OPTS)
def eliminate(M, n, tiny, perm):
    """Gaussian elimination with partial pivoting of ``M = [A | B]`` (n, n + m) in place.

    Afterwards ``M[:, :n]`` holds the LU factors of the row-permuted A (unit lower multipliers
    below the diagonal; the row order into ``perm (n,)`` unless it is None) and
    ``M[:, n:]`` the solution X of ``A X = B`` (m may be 0: factors only).
    ``tiny`` > 0: a pivot below ``tiny`` × max|A| is replaced by that size (its sign kept), so
    X stays finite on a singular A; ``tiny`` = 0: a zero (or NaN) pivot stops the elimination.
    Returns the smallest |pivot| relative to max|A| (before replacement), 0 when A is zero or a
    zero pivot stopped it.

    >>> import numpy as np
    >>> M = np.array([[2.0, 1.0, 3.0], [4.0, 3.0, 7.0]])   # [A | b]: 2x + y = 3, 4x + 3y = 7
    >>> float(eliminate(M, 2, 0.0, None)) > 0, M[:, 2].tolist()
    (True, [1.0, 1.0])
    """
    m = M.shape[1]
    big = 0.0
    for i in range(n):
        if perm is not None:
            perm[i] = i
        for j in range(n):
            big = max(big, abs(M[i, j]))
    if big == 0.0:
        return 0.0
    floor = tiny * big
    small = np.inf
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(M[i, k]) > abs(M[p, k]):
                p = i
        if p != k:
            for j in range(m):
                M[k, j], M[p, j] = M[p, j], M[k, j]
            if perm is not None:
                perm[k], perm[p] = perm[p], perm[k]
        piv = M[k, k]
        small = min(small, abs(piv) / big)
        if abs(piv) < floor:  # (near) singular: a tiny pivot keeps X finite
            piv = floor if piv >= 0.0 else -floor
            M[k, k] = piv
        elif not abs(piv) > 0.0:
            return 0.0
        for i in range(k + 1, n):
            f = M[i, k] / piv
            M[i, k] = f
            if f != 0.0:
                for j in range(k + 1, m):
                    M[i, j] -= f * M[k, j]
    for k in range(n - 1, -1, -1):
        for j in range(n, m):
            acc = M[k, j]
            for i in range(k + 1, n):
                acc -= M[k, i] * M[i, j]
            M[k, j] = acc / M[k, k]
    return small
