"""Compiled steps around a locked arm's single call (:mod:`kinestat.serial.analytic.locked`):
the pose handed to the folded 6-joint chain's kernel, and its solutions put back in the full
chain's joint order with the locked value. One pose each (``(1, 4, 4)``, ``(K, 6)``): a
single call is a few µs, and each NumPy step would cost a fraction of one."""

from __future__ import annotations

import numba as nb
import numpy as np

from kinestat.serial._numba_options import OPTS as _OPTS


@nb.njit(**_OPTS)
def pose_in(T, L, R, invert, out):
    """``out[0] = L · T[0] · R``, inverted when ``invert`` (``L``, ``R`` rigid; the inverse as
    ``[Rᵀ, −Rᵀp]``). A pose whose last row is not ``[0, 0, 0, 1]`` gives NaN, which the
    kernel after this one refuses (the caller then checks the pose and names the fault)."""
    if T[0, 3, 0] != 0.0 or T[0, 3, 1] != 0.0 or T[0, 3, 2] != 0.0 or T[0, 3, 3] != 1.0:
        for i in range(4):
            for k in range(4):
                out[0, i, k] = float("nan")
        return
    A = np.empty((3, 4))  # (L · T)'s top rows, then (L · T · R)'s
    M = np.empty((3, 4))
    for i in range(3):
        for k in range(4):
            A[i, k] = L[i, 0] * T[0, 0, k] + L[i, 1] * T[0, 1, k] + L[i, 2] * T[0, 2, k]
        A[i, 3] += L[i, 3]
    for i in range(3):
        for k in range(4):
            M[i, k] = A[i, 0] * R[0, k] + A[i, 1] * R[1, k] + A[i, 2] * R[2, k]
        M[i, 3] += A[i, 3]
    if invert:
        for i in range(3):
            for k in range(3):
                out[0, i, k] = M[k, i]
            out[0, i, 3] = -(M[0, i] * M[0, 3] + M[1, i] * M[1, 3] + M[2, i] * M[2, 3])
    else:
        for i in range(3):
            for k in range(4):
                out[0, i, k] = M[i, k]
    out[0, 3, 0] = 0.0
    out[0, 3, 1] = 0.0
    out[0, 3, 2] = 0.0
    out[0, 3, 3] = 1.0


@nb.njit(**_OPTS)
def joints_out(q6, take, j, v, out):
    """``out[k, i] = q6[k, take[i]]`` for every slot k, and ``out[k, j] = v`` (NaN where the
    slot is empty: its first joint is NaN); ``q6 (K, 6)``, ``out (K, n)``."""
    for k in range(q6.shape[0]):
        for i in range(take.shape[0]):
            out[k, i] = q6[k, take[i]]
        out[k, j] = q6[k, 0] * 0.0 + v


@nb.njit(**_OPTS)
def value_in(P, R, mode, tol_dir, tol_len, values, out, special):
    """A locked joint's values ``(S,)``: ``out[k] = P[0] + cos v · P[1] + sin v · P[2]``
    (``P (3, m)``: the terms of arrays that are ``a + b cos v + c sin v``), and ``special[k]``
    where an axis pair across the joint is parallel, meets or coincides within ``tol_dir[p]``
    (directions, per pair) and ``tol_len`` (lengths) where it does not at a generic value.
    ``R (p, 7, 3)``: per pair ``(a, b)`` the terms of ``n = wa × wb``, of ``(rb − ra) · n``
    and of ``(rb − ra) × wa``; ``mode (p,)``: what the pair is at every value (0 neither
    parallel nor meeting, 1 meeting, 2 parallel, 3 coincident: nothing to test)."""
    x = np.empty(7)
    for k in range(values.shape[0]):
        c, s = np.cos(values[k]), np.sin(values[k])
        for i in range(P.shape[1]):
            out[k, i] = P[0, i] + c * P[1, i] + s * P[2, i]
        hit = False
        for p in range(R.shape[0]):
            if mode[p] == 3:
                continue
            for i in range(7):
                x[i] = R[p, i, 0] + c * R[p, i, 1] + s * R[p, i, 2]
            nn = x[0] * x[0] + x[1] * x[1] + x[2] * x[2]
            if mode[p] == 2:  # parallel: coincident here?
                hit = x[4] * x[4] + x[5] * x[5] + x[6] * x[6] <= tol_len * tol_len
            elif nn <= tol_dir[p] * tol_dir[p]:  # parallel here
                hit = True
            elif mode[p] == 0:  # meeting here?
                hit = abs(x[3]) <= tol_len * np.sqrt(nn)
            if hit:
                break
        special[k] = hit
