"""The offset-shoulder closed form's pose-independent data: the shoulder's 20 numbers and the
compiled kernel's packed array (the derivation: :mod:`kinestat.serial.analytic.pieper_offset`)."""

from __future__ import annotations

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic.geometry import cross3, norm3

__all__ = ["shoulder", "pack", "REASON"]

REASON = ("no real solution: the wrist centre is out of reach of the arm (the shoulder's "
          "equations have no real root)")


def shoulder(W: np.ndarray, P: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The shoulder's 20 numbers: o1, r2, the coefficient vectors ``u = u0 + u1 cos θ3 + u2 sin
    θ3``, A, sin α, cos α, 0, and 1.0 when axes 1 and 2 are parallel (then only that flag)."""
    G = np.zeros(20)
    w1, w2, w3 = W[0], W[1], W[2]
    ca = float(w1 @ w2)
    if norm3(cross3(w1, w2)) <= 1e-9:
        G[19] = 1.0
        return G
    d = P[1] - P[0]
    t = (ca * float(d @ w1) - float(d @ w2)) / (1.0 - ca * ca)
    s = float(d @ w1) + t * ca
    o1 = P[0] + s * w1
    r2 = P[1] + t * w2
    a = r2 - o1
    A = norm3(a)
    e2 = cross3(w2, a / A)
    m = w - P[2]
    mpar = w3 * float(w3 @ m)
    u1 = m - mpar
    G[:15] = np.concatenate([o1, r2, P[2] + mpar - r2, u1, cross3(w3, u1)])
    G[15:18] = A, float(w1 @ e2), ca
    return G


def pack(model: ChainModel, ax, w: np.ndarray, x6: np.ndarray) -> np.ndarray:
    """The compiled kernel's pose-independent data in one float array."""
    T0inv = np.eye(4)  # a rigid inverse (np.linalg.inv costs several times as much)
    T0inv[:3, :3] = ax.T0[:3, :3].T
    T0inv[:3, 3] = -(T0inv[:3, :3] @ ax.T0[:3, 3])
    parts = (model.constants, T0inv, ax.w, ax.r, w, x6, shoulder(ax.w, ax.r, w))
    return np.concatenate([np.ravel(x) for x in parts])
