"""Compiled (Numba) contact estimate of one cycle: the curvature of the measured tip path
(:func:`kinestat.control.contact_estimate.path_curvature` for one path, the follow task's hot
path). The circle fit's least squares is solved by Householder QR of the (N, 3) design matrix
instead of NumPy's SVD-based ``lstsq``: for a full-rank matrix both give the least-squares
solution, equal to rounding (relative ~ condition number × 1e-16). A design matrix near rank
deficiency (where ``lstsq`` would return its minimum-norm solution) is left to the NumPy
formulation (the kernel says so). Compiled on first use and cached on disk (``cache=True``, in
``__pycache__``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_OPTS = {"cache": True, "fastmath": False, "nogil": True, "error_model": "numpy"}

__all__ = ["path_curvature_kernel"]

#: smallest |R_kk| / max |R_jj| of the QR factor the kernel solves with (else: NumPy's lstsq)
RANK_TOL = 1e-10


@nb.njit(**_OPTS)
def _householder_lstsq(M, b, coef):
    """Least squares ``min |M coef − b|`` for ``M`` (n, 3) by Householder QR (``M`` and ``b``
    overwritten); False when ``R``'s smallest diagonal is below :data:`RANK_TOL` of its
    largest."""
    n = M.shape[0]
    for k in range(3):
        s = 0.0
        for i in range(k, n):
            s += M[i, k] * M[i, k]
        nrm = math.sqrt(s)
        if nrm == 0.0:
            return False
        alpha = -nrm if M[k, k] >= 0.0 else nrm
        v = np.empty(n - k)
        for i in range(k, n):
            v[i - k] = M[i, k]
        v[0] -= alpha
        vv = 0.0
        for i in range(n - k):
            vv += v[i] * v[i]
        if vv > 0.0:
            for j in range(k, 3):
                d = 0.0
                for i in range(k, n):
                    d += v[i - k] * M[i, j]
                f = 2.0 * d / vv
                for i in range(k, n):
                    M[i, j] -= f * v[i - k]
            d = 0.0
            for i in range(k, n):
                d += v[i - k] * b[i]
            f = 2.0 * d / vv
            for i in range(k, n):
                b[i] -= f * v[i - k]
    rmax = max(abs(M[0, 0]), abs(M[1, 1]), abs(M[2, 2]))
    if min(abs(M[0, 0]), abs(M[1, 1]), abs(M[2, 2])) <= RANK_TOL * rmax:
        return False
    for k in range(2, -1, -1):
        s = b[k]
        for j in range(k + 1, 3):
            s -= M[k, j] * coef[j]
        coef[k] = s / M[k, k]
    return True


@nb.njit(**_OPTS)
def path_curvature_kernel(points, tip, normal, tangent, min_span):
    """The signed curvature of the tip path (:func:`~kinestat.control.contact_estimate.
    path_curvature`'s formulation: the points and the tip in the plane of ``tangent`` and
    ``normal`` through ``tip``, the circle ``A (x² + y²) + B x − y + D = 0`` fitted in the
    least-squares sense, ``κ = −2A / sqrt(max(B² + 1 − 4AD, 1e-12))``, 0 for a span below
    ``min_span`` or a sagitta ``|κ| span²/8`` below twice the RMS residual).

    Args:
        points: (N, 3), N ≥ 3, the earlier tips; tip, normal, tangent: (3,).

    Returns ``(κ, ok)``; ``ok`` False when the fit's matrix is near rank deficient (the
    caller then runs the NumPy formulation).
    """
    n = points.shape[0] + 1
    x = np.empty(n)
    y = np.empty(n)
    for i in range(n - 1):
        d0 = points[i, 0] - tip[0]
        d1 = points[i, 1] - tip[1]
        d2 = points[i, 2] - tip[2]
        x[i] = d0 * tangent[0] + d1 * tangent[1] + d2 * tangent[2]
        y[i] = d0 * normal[0] + d1 * normal[1] + d2 * normal[2]
    x[n - 1] = 0.0
    y[n - 1] = 0.0
    xmin = x[0]
    xmax = x[0]
    for i in range(1, n):
        xmin = min(xmin, x[i])
        xmax = max(xmax, x[i])
    span = xmax - xmin
    if span < min_span:
        return 0.0, True
    M = np.empty((n, 3))
    b = np.empty(n)
    for i in range(n):
        M[i, 0] = x[i] * x[i] + y[i] * y[i]
        M[i, 1] = x[i]
        M[i, 2] = 1.0
        b[i] = y[i]
    coef = np.empty(3)
    if not _householder_lstsq(M, b, coef):
        return 0.0, False
    A, B, D = coef[0], coef[1], coef[2]
    kappa = -2.0 * A / math.sqrt(max(B * B + 1.0 - 4.0 * A * D, 1e-12))
    ss = 0.0
    for i in range(n):
        r = y[i] - (A * (x[i] * x[i] + y[i] * y[i]) + B * x[i] + D)
        ss += r * r
    if abs(kappa) * span * span / 8.0 < 2.0 * math.sqrt(ss / n):
        return 0.0, True
    return kappa, True
