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

_OPTS = {"cache": True, "fastmath": False, "nogil": True, "error_model": "numpy"}

__all__ = ["stiffness_axis_one"]


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
