"""The wrist-singular families of arms with three parallel axes (UR-type), as curves.

For axes 2 ∥ 3 ∥ 4 (direction h) with axes 5, 6 meeting at p (see
:func:`kinestat.serial.analytic.closed_form.solve_three_parallel`), a θ1 branch on which axis 6
can be parallel to h (θ5 = 0 or 180° on the UR) leaves θ6 free: for every θ6 = t,
``R1ᵀ Rg = Rh(φ) R5 R6(t)`` fixes φ = Σ ±θ2..4 (subproblem 1), the point r4 on axis 4 is carried
to ``y(t) = e^{−ξ̂1θ1} g e^{−ξ̂6 t} e^{−ξ̂5θ5} r4`` (on a circle about axis 6), θ3 follows by
subproblem 3 (one elbow root per family), θ2 by subproblem 1 and θ4 from φ. Unlike the
spherical wrist's family (θ4 ± θ6 fixed, :attr:`IKAllResult.family_joints`), four joints move
together, θ2 and θ3 non-linearly: :class:`WristCurve` generates the members, and a member exists
only for the t where the elbow reaches ``y(t)``. :func:`add_wrist_families` puts one member of
each family (the t with the most elbow margin) into the result's free slots.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic._common import pose_residuals, wrap_angles
from kinestat.serial.analytic.result import IKAllResult
from kinestat.serial.analytic.subproblems import rotate, rotation_matrix, sp1, sp3, sp4

__all__ = ["WristCurve", "add_wrist_families"]

_SCAN = 72  # θ6 values scanned for the member with the most elbow margin


def _perp(w: np.ndarray) -> np.ndarray:
    e = np.eye(3)[int(np.argmin(np.abs(w)))]
    x = np.cross(w, e)
    return x / np.linalg.norm(x)


@dataclasses.dataclass(frozen=True, eq=False)
class WristCurve:
    """The wrist-singular families of a three-parallel-axes result (flat pose index).

    Attributes:
        free_joint: the joint whose value parameterises a family (5: θ6, 0-based).
        joints: the joints that move along a family (θ2, θ3, θ4, θ6).
        T: ``(N, 4, 4)`` the poses; ``theta1``, ``theta5``, ``elbow`` ``(N, K)`` per family slot
            (``elbow`` the subproblem-3 root, −1 where the slot is not such a family).
        description: the relation in words (for reports).
    """

    T: np.ndarray
    theta1: np.ndarray
    theta5: np.ndarray
    elbow: np.ndarray
    W: np.ndarray
    P: np.ndarray
    T0inv: np.ndarray
    sg: np.ndarray
    free_joint: int = 5
    joints: tuple[int, ...] = (1, 2, 3, 5)
    description: str = ("θ1 and θ5 fixed, θ6 free; θ2, θ3, θ4 follow it (±θ2 ± θ3 ± θ4 ± θ6 "
                        "fixed; θ2, θ3 from the elbow)")

    def members(self, n: int, k: int, t) -> tuple[np.ndarray, np.ndarray]:
        """Members ``(m, 6)`` of slot ``k`` of pose ``n`` (flat) for θ6 values ``t (m,)``, and
        where they exist (the elbow reaches); NaN rows where not."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if self.elbow[n, k] < 0:
            return np.full((t.size, 6), np.nan), np.zeros(t.size, dtype=bool)
        q, ok, _ = _members(self, n, self.theta1[n, k], self.theta5[n, k], t)
        e = int(self.elbow[n, k])
        return np.where(ok[:, e, None], q[:, e], np.nan), ok[:, e]


def _members(c: WristCurve, n: int, t1: float, t5: float, t6: np.ndarray):
    """Both elbow members ``(m, 2, 6)`` for θ6 values ``t6 (m,)``, existence ``(m, 2)`` and the
    elbow margin ``(m,)`` (how far inside the elbow's reach y(t) lies)."""
    W, P, sg = c.W, c.P, c.sg
    h = W[1]
    g = c.T[n] @ c.T0inv
    Rr = rotation_matrix(W[0], -t1) @ g[:3, :3]
    R56 = rotation_matrix(W[4], t5) @ rotation_matrix(W[5], t6)  # (m, 3, 3)
    R234 = Rr @ np.swapaxes(R56, -1, -2)
    x = _perp(h)
    phi, _, _ = sp1(h, np.zeros(3), x, np.einsum("...ij,j->...i", R234, x))
    y = rotate(W[5], P[5], -t6, rotate(W[4], P[4], -t5, P[3]))
    y = np.einsum("ij,...j->...i", g[:3, :3], y) + g[:3, 3]
    y = rotate(W[0], P[0], -t1, y)
    d = np.linalg.norm(y - P[1], axis=-1)
    t3, e3 = sp3(W[2], P[2], P[3], P[1], d)  # (m, 2)
    y3 = rotate(W[2], P[2], t3, P[3])
    t2, _, _ = sp1(W[1], P[1], y3, y[:, None, :])
    t4 = sg[2] * (phi[:, None] - sg[0] * t2 - sg[1] * t3)
    m = t6.size
    q = np.stack([np.full((m, 2), t1), t2, t3, t4, np.full((m, 2), t5),
                  np.broadcast_to(t6[:, None], (m, 2))], axis=-1)
    # margin: distance of |y − P1| from the ends of the elbow's reach (sampled on the root)
    u = P[3] - P[2]
    u = u - (u @ W[2]) * W[2]
    v = P[1] - P[2]
    hgt = (P[3] - P[1]) @ W[2]
    v = v - (v @ W[2]) * W[2]
    lo = math.hypot(abs(np.linalg.norm(u) - np.linalg.norm(v)), hgt)
    hi = math.hypot(np.linalg.norm(u) + np.linalg.norm(v), hgt)
    margin = np.minimum(d - lo, hi - d)
    return q, np.broadcast_to(e3[:, None], (m, 2)), margin


def add_wrist_families(model: ChainModel, T: np.ndarray, data: dict, res: IKAllResult, *,
                       wrist_tol: float = 1e-10, near: np.ndarray | None = None) -> IKAllResult:
    """``res`` of the three-parallel solver for poses ``T (N, 4, 4)`` with one member of every
    wrist-singular family added in its free slots (``singular`` True, verified by FK).
    ``near``: indices of the poses to examine (a superset of the wrist-singular ones, e.g. the
    compiled kernel's flags); by default a cheap necessary test picks them."""
    ax = data["axes"]
    W, P = ax.w, ax.r
    h = W[1]
    if "family_args" not in data:  # pose-independent, kept with the model's cached geometry
        T0inv = np.linalg.inv(ax.T0)
        data["family_args"] = (T0inv, T0inv[:3, :3] @ W[5], float(W[0] @ h))
    T0inv, w6, w0h = data["family_args"]
    # necessary (cheap) test: a rotation about axis 1 keeps the component along it, so axis 6
    # (g ω6) can be parallel to h only where ω1ᵀ g ω6 = ±ω1ᵀ h
    if near is None:
        c = T[:, :3, :3] @ w6 @ W[0]
        near = np.flatnonzero(np.minimum(np.abs(c - w0h), np.abs(c + w0h)) < 1e-6)
    if near.size == 0:
        return res
    g = T[near] @ T0inv
    q56 = np.einsum("nij,j->ni", g[:, :3, :3], data["p56"]) + g[:, :3, 3]
    psi, e1 = sp4(h, W[0], q56 - P[0], float(h @ (data["p56"] - P[0])))  # (M, 2)
    Rr = rotation_matrix(W[0], psi) @ g[:, None, :3, :3]  # (M, 2, 3, 3)
    hr = np.einsum("...ji,j->...i", Rr, h)
    sing = e1[:, None] & (np.linalg.norm(np.cross(hr, W[5]), axis=-1) < wrist_tol)
    N, K = res.valid.shape
    elbow = np.full((N, K), -1, dtype=np.int8)
    if not sing.any():
        return res
    sg = np.array([float(np.sign(W[i] @ h)) for i in (1, 2, 3)])
    curve = WristCurve(T=T, theta1=np.full((N, K), np.nan), theta5=np.full((N, K), np.nan),
                       elbow=elbow, W=W, P=P, T0inv=T0inv, sg=sg)
    q, valid = res.q.copy(), res.valid.copy()
    pos, rot = res.position_error.copy(), res.rotation_error.copy()
    singular = res.singular.copy()
    scan = np.linspace(-math.pi, math.pi, _SCAN, endpoint=False)
    for i, b in zip(*np.nonzero(sing), strict=True):
        n = int(near[i])
        t1 = float(-psi[i, b])
        t5, _, _ = sp1(W[4], np.zeros(3), W[5], Rr[i, b] @ W[5])
        t5 = float(t5)
        qm, ok, margin = _members(curve, n, t1, t5, scan)
        best = int(np.argmax(np.where(ok.any(1), margin, -np.inf)))
        for e in range(2):
            if not ok[best, e]:
                continue
            cand = wrap_angles(qm[best, e], np.ones(6, dtype=bool))
            pe, re = pose_residuals(model, cand, T[n])
            if not (pe <= res.tol and re <= res.tol):
                continue
            dup = valid[n] & (np.max(np.abs(np.mod(q[n] - cand + math.pi, 2 * math.pi)
                                            - math.pi), axis=-1) < 1e-6)
            free = np.flatnonzero(~valid[n])
            if dup.any() or free.size == 0:
                continue
            k = int(free[0])
            q[n, k], valid[n, k], pos[n, k], rot[n, k] = cand, True, pe, re
            singular[n, k] = True
            curve.theta1[n, k], curve.theta5[n, k], elbow[n, k] = t1, t5, e
    nsol = valid.sum(axis=1)
    return dataclasses.replace(
        res, q=q, valid=valid, position_error=pos, rotation_error=rot, singular=singular,
        family_sign=np.where(singular, 0.0, res.family_sign),
        n_solutions=nsol, reason=np.where(nsol > 0, "", res.reason).astype(object),
        family_curve=curve)
