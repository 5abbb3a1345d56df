"""Spherical-wrist arms whose shoulder axes 1 and 2 do not meet (the offset shoulder of KUKA,
ABB, Fanuc and Stäubli arms): every solution in closed form.

Product-of-exponentials form as in :mod:`kinestat.serial.analytic.closed_form`: the wrist
centre ``p = g w`` depends on θ1, θ2, θ3 only. Let o1 and r2 be the feet of the common normal
of axes 1 and 2 (``a = r2 − o1``, length A, unit e1; ``e2 = ω2 × e1``; ``cos α = ω1·ω2``,
``sin α = ω1·e2``) and ``u(θ3) = e^{ξ̂3θ3} w − r2``, with ``h = ω2·u`` and ``v = R2 u⊥`` (u⊥
the part of u normal to ω2). Rotating by θ1 keeps the distance of p from o1 and its height
along ω1, which gives

- ``|p − o1|² = A² + |u|² + 2A (e1·v)``,
- ``ω1·(p − o1) = h cos α + (e2·v) sin α``,

so ``x = e1·v`` and ``y = e2·v`` are linear in (1, cos θ3, sin θ3), and ``x² + y² = |u|² − h²``
is a trigonometric polynomial of degree 2 in θ3: a quartic in tan(θ3/2) (Pieper 1968). Each
real root gives v, hence θ2 (subproblem 1 about axis 2: u⊥ → v) and θ1 (subproblem 1 about
axis 1), and the wrist as for the meeting shoulder: up to 8 solutions.

Axes 1 and 2 parallel (ω): the height ``ω·p = ω·e^{ξ̂3θ3} w`` fixes θ3 (subproblem 4), the
distance of p from axis 1 fixes θ2 (subproblem 3), then θ1 (subproblem 1).

:mod:`kinestat.serial.analytic._offset_pack` packs the compiled kernel's data
(:mod:`kinestat.serial.analytic._offset_kernels`); :func:`solve_pieper_offset` is the NumPy
reference (the quartic's roots by ``numpy.roots``).
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic._common import pack as pack_result
from kinestat.serial.analytic._offset_pack import REASON, shoulder
from kinestat.serial.analytic.closed_form import _wrist
from kinestat.serial.analytic.result import IKAllResult
from kinestat.serial.analytic.subproblems import rotate, rotation_matrix, sp1, sp3, sp4

__all__ = ["solve_pieper_offset"]

def _theta3(G: np.ndarray, W: np.ndarray, pw: np.ndarray) -> list[float]:
    """The real roots θ3 of the shoulder's equations for one wrist centre (skew axes 1, 2)."""
    o1, u0, u1, u2 = G[0:3], G[6:9], G[9:12], G[12:15]
    A, sa, ca = G[15:18]
    d = pw - o1
    N = np.array([u0 @ u0 + u1 @ u1, 2 * u0 @ u1, 2 * u0 @ u2])
    H = np.array([W[1] @ u0, W[1] @ u1, W[1] @ u2])
    X = np.array([d @ d - A * A - N[0], -N[1], -N[2]]) / (2 * A)
    Y = (np.array([W[0] @ d, 0.0, 0.0]) - ca * H) / sa

    def form(L):  # (1 + t²) (l0 + l1 cos θ3 + l2 sin θ3), t = tan(θ3/2), highest power first
        return np.array([L[0] - L[1], 2 * L[2], L[0] + L[1]])

    # (1 + t²)² (x² + y² + h² − |u|²)
    poly = sum(np.polymul(form(L), form(L)) for L in (X, Y, H)) \
        - np.polymul(form(N), [1.0, 0.0, 1.0])
    roots = [2 * math.atan(r.real) for r in np.roots(poly)
             if abs(r.imag) <= 1e-5 * (1 + abs(r.real))]
    if abs(poly[0]) <= 1e-12 * np.max(np.abs(poly)):
        roots.append(math.pi)  # t = ∞
    return roots


def _arm_angles(G: np.ndarray, W: np.ndarray, P: np.ndarray, w: np.ndarray,
                pw: np.ndarray) -> list[tuple[float, float, float]]:
    """Every (θ1, θ2, θ3) that puts the wrist centre w at pw."""
    out = []
    if G[19] == 1.0:
        t3s, ok = sp4(W[0], W[2], w - P[2], float(W[0] @ (pw - P[2])))
        if not ok:
            return out
        foot = P[0] + W[0] * float(W[0] @ (pw - P[0]))
        for t3 in np.atleast_1d(t3s):
            g3 = rotate(W[2], P[2], t3, w)
            t2s, ok2 = sp3(W[1], P[1], g3, foot, float(np.linalg.norm(pw - foot)))
            for t2 in (np.atleast_1d(t2s) if ok2 else ()):
                q2 = rotate(W[1], P[1], t2, g3)
                t1 = float(sp1(W[0], P[0], q2, pw)[0])
                out.append((t1, float(t2), float(t3)))
        return out
    o1, r2 = G[0:3], G[3:6]
    A = G[15]
    e1 = (r2 - o1) / A
    for t3 in _theta3(G, W, pw):
        u = rotate(W[2], P[2], t3, w) - r2
        up = u - W[1] * float(W[1] @ u)
        d = pw - o1
        x = (d @ d - A * A - u @ u) / (2 * A)
        y = (W[0] @ d - G[17] * float(W[1] @ u)) / G[16]
        v = x * e1 + y * np.cross(W[1], e1)
        t2 = float(sp1(W[1], np.zeros(3), up, v)[0])
        q2 = r2 + rotation_matrix(W[1], t2) @ u
        t1 = float(sp1(W[0], o1, q2, pw)[0])
        out.append((t1, t2, float(t3)))
    return out


def solve_pieper_offset(model: ChainModel, T: np.ndarray, data: dict, *, tol: float = 1e-9,
                        wrist_tol: float = 1e-10) -> IKAllResult:
    """All solutions (8 slots) for a spherical-wrist arm whose axes 1, 2 do not meet;
    ``T (N, 4, 4)``. The NumPy reference of the compiled kernel (a loop over poses)."""
    ax, w = data["axes"], data["wrist"]
    W, P = ax.w, ax.r
    G = shoulder(W, P, w)
    N = T.shape[0]
    g = T @ np.linalg.inv(ax.T0)
    q = np.full((N, 8, 6), np.nan)
    ok = np.zeros((N, 8), dtype=bool)
    sing = np.zeros((N, 8), dtype=bool)
    sig = np.zeros((N, 8))
    fam = np.full((N, 8), np.nan)
    for n in range(N):
        pw = g[n, :3, :3] @ w + g[n, :3, 3]
        for i, (t1, t2, t3) in enumerate(_arm_angles(G, W, P, w, pw)[:4]):
            R123 = (rotation_matrix(W[0], t1) @ rotation_matrix(W[1], t2)
                    @ rotation_matrix(W[2], t3))
            t4, t5, t6, e45, s45, sg, fm = _wrist(W, R123.T @ g[n, :3, :3], wrist_tol)
            for j in range(2):
                q[n, 2 * i + j] = (t1, t2, t3, t4[j], t5[j], t6[j])
                ok[n, 2 * i + j] = bool(e45)
                sing[n, 2 * i + j], sig[n, 2 * i + j], fam[n, 2 * i + j] = s45, sg[j], fm[j]
    return pack_result(model, q, ok, T, 8, tol=tol, method="pieper", reason_none=REASON,
                       singular=sing, family_sign=sig, family_value=fam, family_joints=(3, 5))
