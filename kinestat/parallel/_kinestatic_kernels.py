"""Compiled (Numba) linear algebra of ONE 6 × 6 stiffness, the kinestatic control law's hot
path (:func:`kinestat.parallel.kinestatic.compose_twist_line`,
:func:`kinestat.parallel.kinestatic.solve_one`): the solve ``K⁻¹ b`` by Gaussian elimination with
partial pivoting (equal to LAPACK's ``gesv`` to rounding, not bit for bit) and the ratio of the
smallest to the largest singular value by one-sided (Hestenes) Jacobi, which the caller uses
only where it is clearly above the singularity threshold (elsewhere it runs LAPACK's SVD).
Compiled on first use and cached on disk (``cache=True``, in ``__pycache__``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_OPTS = {"cache": True, "fastmath": False, "nogil": True, "error_model": "numpy"}

__all__ = ["solve6", "singular_ratio6"]


@nb.njit(**_OPTS)
def solve6(K, b, x):
    """``x = K⁻¹ b`` for ``K`` (6, 6), ``b`` (6,) into ``x`` (6,) (Gaussian elimination with
    partial pivoting); False (``x`` unset) when a pivot is zero or the result not finite."""
    M = np.empty((6, 7))
    for r in range(6):
        for c in range(6):
            M[r, c] = K[r, c]
        M[r, 6] = b[r]
    for c in range(6):
        piv = c
        for r in range(c + 1, 6):
            if abs(M[r, c]) > abs(M[piv, c]):
                piv = r
        if not abs(M[piv, c]) > 0.0:
            return False
        if piv != c:
            for k in range(c, 7):
                M[c, k], M[piv, k] = M[piv, k], M[c, k]
        for r in range(c + 1, 6):
            f = M[r, c] / M[c, c]
            if f != 0.0:
                for k in range(c, 7):
                    M[r, k] -= f * M[c, k]
    for r in range(5, -1, -1):
        s = M[r, 6]
        for m in range(r + 1, 6):
            s -= M[r, m] * x[m]
        x[r] = s / M[r, r]
    for r in range(6):
        if not math.isfinite(x[r]):
            return False
    return True


@nb.njit(**_OPTS)
def singular_ratio6(K):
    """``s_min / s_max`` of ``K`` (6, 6) by one-sided Jacobi rotations of its columns (the
    singular values are the converged columns' norms, to high accuracy); 0.0 for a zero or
    non-finite matrix, -1.0 when the sweeps did not converge."""
    U = np.empty((6, 6))
    for r in range(6):
        for c in range(6):
            if not math.isfinite(K[r, c]):
                return 0.0
            U[r, c] = K[r, c]
    eps = 2.220446049250313e-16
    for _ in range(60):
        rotated = False
        for p in range(5):
            for q in range(p + 1, 6):
                a = 0.0
                b = 0.0
                g = 0.0
                for r in range(6):
                    a += U[r, p] * U[r, p]
                    b += U[r, q] * U[r, q]
                    g += U[r, p] * U[r, q]
                if g == 0.0 or abs(g) <= eps * math.sqrt(a * b):
                    continue
                rotated = True
                z = (b - a) / (2.0 * g)
                t = (1.0 if z >= 0.0 else -1.0) / (abs(z) + math.sqrt(1.0 + z * z))
                c = 1.0 / math.sqrt(1.0 + t * t)
                s = c * t
                for r in range(6):
                    up, uq = U[r, p], U[r, q]
                    U[r, p] = c * up - s * uq
                    U[r, q] = s * up + c * uq
        if not rotated:
            smax = 0.0
            smin = np.inf
            for c in range(6):
                n = 0.0
                for r in range(6):
                    n += U[r, c] * U[r, c]
                n = math.sqrt(n)
                smax = max(smax, n)
                smin = min(smin, n)
            return smin / smax if smax > 0.0 else 0.0
    return -1.0
