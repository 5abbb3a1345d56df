"""All IK solutions of a decoupled 6-joint arm: three R/P positioning joints, a spherical wrist.

Joints 4, 5, 6 revolute with axes meeting at the wrist centre w (Pieper 1968); joints 1, 2, 3
revolute or prismatic in any combination and in general position (axes need not meet or be
parallel): PPP gantries, RPP cylindrical arms, the Stanford arm (RRP), PRR, RPR, PRP, PPR, and
RRR with any shoulder. In product-of-exponentials form (MLS eq. 3.26) the wrist centre obeys
``M1(q1) M2(q2) M3(q3) w = p`` with ``p = T T(0)⁻¹ w``; the orientation then fixes q4..q6.

Position (one univariate eliminant in q3):

1. Joint 1 is eliminated by its invariants: a revolute joint keeps the height along its axis
   ``ω1ᵀ(x − r1) = h`` and the distance ``|x − r1|² = ρ²`` from a point r1 on it; a prismatic
   joint keeps the two coordinates across it ``u_kᵀ(x − p) = 0``. With ``x = M2(q2) y`` and
   ``y = M3(q3) w`` that is two equations in (q2, q3).
2. Joint 2 revolute (axis ω2 through r2, v = y − r2, v⊥ its part across the axis in a basis
   (e1, e2)): both equations are ``g_kᵀ Rot(q2) v⊥ + C_k(q3) = 0`` with constant 2-vectors g_k,
   so ``Rot(q2) v⊥ = −G⁻¹ C`` and ``|adj(G) C|² = det(G)² |v⊥|²`` (the 2R step of Pieper's
   quartic, Craig §4.7). Where G is singular by geometry (axes 1, 2 parallel, or meeting at
   r1 = r2, or a prismatic joint 1 across a revolute joint 2) one equation is free of q2 and is
   itself the eliminant; q2 then follows from the other (two roots, ``acos``).
   Joint 2 prismatic: the height (or the coordinate along the projection of ω2) is linear in
   q2, which is substituted into the other equation; where it is free of q2 (ω1 ⊥ ω2) it is
   the eliminant and q2 solves the quadratic distance equation.
3. The eliminant ``Ψ(q3)`` is a trigonometric polynomial of degree ≤ 2 (joint 3 revolute) or a
   polynomial of degree ≤ 4 (joint 3 prismatic). It is evaluated at 8 equally spaced angles
   (FFT: exact, perfectly conditioned) or at 9 Chebyshev nodes on ``[−L, L]`` (least squares);
   negligible top coefficients are dropped per pose and the roots come from a companion matrix
   in ``z = e^{i q3}`` (roots on the unit circle) or in ``q3 / L`` (real roots).
4. Back-substitution gives q2 (a double root, |cos| within 1e-12 of 1 or a vanishing
   discriminant, taken exactly), then q1 (subproblem 1, or the displacement along ω1); Newton
   steps on the wrist-centre equation where it misses by more than rounding; the spherical
   wrist (``closed_form._wrist``: subproblems 2 and 1, the θ5 = 0/π families ``q4 + σ q6``)
   gives two wrist branches; candidates whose wrist centre still misses or whose wrist is near
   θ5 = 0 get Gauss–Newton steps on the whole pose (truncated pseudo-inverse); ``pack``
   verifies every candidate by forward kinematics.

At most 4 wrist-centre solutions × 2 wrist branches = 8 slots. Not covered: screw joints (a
helical joint turns and slides together, so q and q + 2π are different configurations and
the solution set depends on the joint range), a prismatic joint in the wrist, and positioning
singular poses with a continuum of wrist-centre solutions (e.g. the wrist centre on axis 1 of
a cylindrical arm): the continuum gets no slot (the isolated solutions do).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from kinestat.errors import ModelError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic._common import newton_polish, pack, pose_residuals
from kinestat.serial.analytic.closed_form import _wrist
from kinestat.serial.analytic.geometry import HomeAxes, home_axes, meet, parallel
from kinestat.serial.analytic.result import IKAllResult
from kinestat.serial.analytic.subproblems import rotate, rotation_matrix, sp1

__all__ = ["Plan", "plan", "solve_decoupled", "METHOD"]

METHOD = "decoupled"
_WRIST_TOL = 1e-10
_TRIG_SAMPLES = 8  # exact for trigonometric degree ≤ 3 (the eliminant has ≤ 2)
_TRIG_MAX = 3
_CHEB_NODES = 9
_POLY_DEG = 4
_ROOT_TOL = 1e-5  # distance of an accepted root from the unit circle / real axis (relative)
_TRIM = 1e-10  # top coefficients below this fraction of the largest are dropped
_SNAP = 1e-12  # |cos| this close to 1 (or a discriminant this small): a double root
_REASON = ("no real solution: the wrist centre is out of reach of joints 1-3 (the eliminant has "
           "no real root, joint 2 cannot follow, or no root places the centre)")
_REASON_WRIST = ("no real solution: the wrist centre is reached, but the spherical wrist cannot "
                 "turn to the orientation (subproblem 2 for q4, q5 has no real root)")


@dataclass(frozen=True, eq=False)
class Plan:
    """The pose-independent set-up of the decoupled solver for one model (see module doc).

    ``kinds`` e.g. ``"RRP"`` (joints 1-3); ``mode`` the joint-2 elimination (``"full"``,
    ``"row0"``/``"row1"``: that equation is free of q2, ``"lin"``, ``"perp"``, ``"pp"``);
    ``r1``, ``r2`` the points used on axes 1, 2; ``G (2, 2)``, ``e (2, 3)`` the 2R step's
    matrix and basis across axis 2; ``u (2, 3)`` the basis across a prismatic axis 1.
    """

    kinds: str
    mode: str
    axes: HomeAxes
    wrist: np.ndarray
    T0_inv: np.ndarray
    r1: np.ndarray
    r2: np.ndarray
    G: np.ndarray
    e: np.ndarray
    u: np.ndarray


def _unit(x: np.ndarray) -> np.ndarray:
    return x / np.linalg.norm(x)


def _perp(w: np.ndarray) -> np.ndarray:
    return _unit(np.cross(w, np.eye(3)[int(np.argmin(np.abs(w)))]))


def _feet(ax: HomeAxes) -> tuple[np.ndarray, np.ndarray]:
    """Points on axes 1 and 2 closest to each other (the common perpendicular's feet)."""
    w1, w2, d = ax.w[0], ax.w[1], ax.r[1] - ax.r[0]
    c = float(w1 @ w2)
    den = 1.0 - c * c
    if den < 1e-18:  # parallel: any foot pair
        return ax.r[0] + float(d @ w1) * w1, ax.r[1]
    s = (float(d @ w1) - c * float(d @ w2)) / den
    t = (c * float(d @ w1) - float(d @ w2)) / den
    return ax.r[0] + s * w1, ax.r[1] + t * w2


def _wrist_centre(model: ChainModel, ax: HomeAxes, tol: float) -> np.ndarray:
    for i, j in enumerate(model.joints[3:], start=4):
        if j.kind != "revolute":
            raise ModelError(
                f"ik_all: joint {i} of model {model.name!r} is {j.kind}; the all-solutions "
                f"solver for arms with prismatic joints needs a spherical wrist (joints 4, 5, 6 "
                f"revolute with axes meeting at one point) — use kinestat.ik for a numerical "
                f"solution")
    w = meet(ax, 3, 4, tol)
    if w is None or float(np.linalg.norm(np.cross(w - ax.r[5], ax.w[5]))) > tol * ax.scale:
        raise ModelError(
            f"ik_all: axes 4, 5, 6 of model {model.name!r} do not meet at one point; the "
            f"all-solutions solver for arms with prismatic joints (decoupled) needs a spherical "
            f"wrist — use kinestat.ik for a numerical solution")
    if parallel(ax, 4, 5, tol):
        raise ModelError(
            f"ik_all: axes 5 and 6 of model {model.name!r} coincide; the wrist turns about two "
            f"axes only (solutions not isolated)")
    return w


def _position_rank_ok(model: ChainModel, ax: HomeAxes, kinds: str, w: np.ndarray) -> bool:
    """Joints 1-3 move the wrist centre in three independent directions somewhere."""
    rng = np.random.default_rng(0)
    for _ in range(4):
        q = rng.uniform(-2.0, 2.0, 3) * np.where(np.array(list(kinds)) == "P", ax.scale, 1.0)
        J = _position_jacobian(ax, kinds, q[None], w)[0]
        s = np.linalg.svd(J, compute_uv=False)
        if s[-1] > 1e-8 * max(s[0], 1.0):
            return True
    return False


@lru_cache(maxsize=64)
def plan(model: ChainModel, tol: float = 1e-9) -> Plan:
    """The set-up for ``model``, or :class:`ModelError` naming why it is outside the class."""
    if model.n != 6:
        raise ModelError(f"ik_all: model {model.name!r} has {model.n} joints; the decoupled "
                         f"solver needs 6")
    for i, j in enumerate(model.joints[:3], start=1):
        if j.kind == "screw":
            raise ModelError(
                f"ik_all: joint {i} of model {model.name!r} is a screw joint; the all-solutions "
                f"solvers do not handle screw joints (q and q + 2π are different configurations, "
                f"so the solution set depends on the joint range) — use kinestat.ik")
    ax = home_axes(model)
    w = _wrist_centre(model, ax, tol)
    kinds = "".join("P" if j.kind == "prismatic" else "R" for j in model.joints[:3])
    W = ax.w
    r1, r2 = ax.r[0].copy(), ax.r[1].copy()
    G = np.zeros((2, 2))
    e = np.stack([_perp(W[1]), np.cross(W[1], _perp(W[1]))])
    u = np.stack([_perp(W[0]), np.cross(W[0], _perp(W[0]))])
    c12 = float(W[0] @ W[1])
    if kinds[:2] == "RR":
        if parallel(ax, 0, 1, tol) and np.linalg.norm(np.cross(ax.r[1] - ax.r[0], W[0])) <= \
                tol * ax.scale:
            raise ModelError(f"ik_all: axes 1 and 2 of model {model.name!r} coincide; joints "
                             f"1-3 cannot place the wrist centre (solutions not isolated)")
        r1, r2 = _feet(ax)
        G = np.stack([e @ W[0], 2.0 * (e @ (r2 - r1))])
        mode = "row0" if parallel(ax, 0, 1, tol) else \
            "row1" if np.linalg.norm(r2 - r1) <= tol * ax.scale else "full"
    elif kinds[:2] == "PR":
        if abs(c12) <= tol:
            u = np.stack([W[1], _unit(np.cross(W[0], W[1]))])
        G = u @ e.T
        mode = "row0" if abs(c12) <= tol else "full"
    elif kinds[:2] == "RP":
        mode = "perp" if abs(c12) <= tol else "lin"
    else:
        if parallel(ax, 0, 1, tol):
            raise ModelError(f"ik_all: the prismatic joints 1 and 2 of model {model.name!r} are "
                             f"parallel; joints 1-3 cannot place the wrist centre")
        mode = "pp"
        n = _unit(np.cross(W[0], W[1]))
        u = np.stack([_unit(W[1] - c12 * W[0]), n])
    if not _position_rank_ok(model, ax, kinds, w):
        raise ModelError(f"ik_all: joints 1-3 of model {model.name!r} ({kinds}) cannot move the "
                         f"wrist centre in three independent directions (solutions not "
                         f"isolated)")
    return Plan(kinds=kinds, mode=mode, axes=ax, wrist=w, T0_inv=np.linalg.inv(ax.T0), r1=r1,
                r2=r2, G=G, e=e, u=u)


# -- the joint motions (points and directions), broadcast over leading dimensions ---------------

def _move(kind: str, w: np.ndarray, r: np.ndarray, q: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``e^{ξ̂ q} x`` for a revolute (rotation about (w, r)) or prismatic (translation) joint."""
    if kind == "R":
        return rotate(w, r, q, x)
    return x + q[..., None] * w


def _position_jacobian(ax: HomeAxes, kinds: str, q: np.ndarray, w=None) -> np.ndarray:
    """``∂(M1 M2 M3 w)/∂q (..., 3, 3)`` at ``q (..., 3)`` (each axis moved by the joints
    before it; w defaults to the point on axis 4)."""
    W, P = ax.w, ax.r
    w = P[3] if w is None else w
    axes, pts = [], []
    Rc = np.broadcast_to(np.eye(3), q.shape[:-1] + (3, 3))
    oc = np.zeros(q.shape[:-1] + (3,))
    for i in range(3):  # axis i at the configuration: (Rc W[i], Rc P[i] + oc)
        axes.append(np.einsum("...ij,j->...i", Rc, W[i]))
        pts.append(np.einsum("...ij,j->...i", Rc, P[i]) + oc)
        if kinds[i] == "R":
            Ri = rotation_matrix(W[i], q[..., i])
            oc = np.einsum("...ij,...j->...i", Rc, P[i] - np.einsum("...ij,j->...i", Ri, P[i])) \
                + oc
            Rc = Rc @ Ri
        else:
            oc = oc + q[..., i, None] * axes[-1]
    x = np.einsum("...ij,j->...i", Rc, w) + oc
    cols = [np.cross(a, x - r) if k == "R" else a for k, a, r in zip(kinds, axes, pts,
                                                                      strict=True)]
    return np.stack(cols, axis=-1)


def _place(pl: Plan, q: np.ndarray) -> np.ndarray:
    """``M1 M2 M3 w`` at ``q (..., 3)``."""
    W, P = pl.axes.w, pl.axes.r
    x = np.broadcast_to(pl.wrist, q.shape[:-1] + (3,))
    for i in (2, 1, 0):
        x = _move(pl.kinds[i], W[i], P[i], q[..., i], x)
    return x


# -- the eliminant and the back-substitution of joint 2 ----------------------------------------

def _invariants(pl: Plan, p: np.ndarray):
    """Joint 1's invariants of the target ``p (N, 3)``: ``(h, ρ²)`` (revolute) or ``p``."""
    d = p - pl.r1
    return d @ pl.axes.w[0], np.sum(d * d, axis=-1)


def _terms(pl: Plan, y: np.ndarray, p: np.ndarray, h: np.ndarray, rho2: np.ndarray):
    """For a revolute joint 2: ``C (..., 2)`` and ``v⊥ (..., 2)`` of ``g_kᵀ Rot(q2) v⊥ + C_k``."""
    W = pl.axes.w
    v = y - pl.r2
    vpar = v @ W[1]
    vp = v @ pl.e.T
    if pl.kinds[0] == "R":
        d = pl.r2 - pl.r1
        C1 = float(W[0] @ d) + float(W[0] @ W[1]) * vpar - h
        C2 = np.sum(v * v, axis=-1) + float(d @ d) + 2.0 * float(d @ W[1]) * vpar - rho2
        C = np.stack([C1, C2], axis=-1)
    else:
        C = np.einsum("kj,...j->...k", pl.u, pl.r2 - p) + (pl.u @ W[1]) * vpar[..., None]
    return C, vp


def _eliminant(pl: Plan, y: np.ndarray, p, h, rho2) -> np.ndarray:
    """``Ψ`` at the wrist-centre images ``y (N, S, 3)`` (pose data ``(N, 1, ...)``)."""
    W = pl.axes.w
    if pl.kinds[1] == "R":
        C, vp = _terms(pl, y, p, h, rho2)
        if pl.mode == "row0":
            return C[..., 0]
        if pl.mode == "row1":
            return C[..., 1]
        G = pl.G
        adj = np.array([[G[1, 1], -G[0, 1]], [-G[1, 0], G[0, 0]]])
        z = C @ adj.T
        return np.sum(z * z, axis=-1) - np.linalg.det(G) ** 2 * np.sum(vp * vp, axis=-1)
    if pl.mode == "pp":
        return (y - p) @ pl.u[1]
    s = y - pl.r1
    hs = s @ W[0]
    if pl.mode == "perp":
        return hs - h
    a = float(W[0] @ W[1])
    z = a * s + (h - hs)[..., None] * W[1]
    return np.sum(z * z, axis=-1) - a * a * rho2


def _joint2(pl: Plan, y: np.ndarray, p, h, rho2):
    """q2 ``(..., B)`` and existence for the wrist-centre images ``y (..., 3)``."""
    W = pl.axes.w
    if pl.kinds[1] == "R":
        C, vp = _terms(pl, y, p, h, rho2)
        if pl.mode == "full":
            z = -np.linalg.solve(pl.G, C[..., None])[..., 0]
            q2 = np.arctan2(vp[..., 0] * z[..., 1] - vp[..., 1] * z[..., 0],
                            np.sum(vp * z, axis=-1))
            return q2[..., None], np.ones(q2.shape + (1,), dtype=bool)
        j = 1 if pl.mode == "row0" else 0
        g = pl.G[j]
        al, be = math.atan2(g[1], g[0]), np.arctan2(vp[..., 1], vp[..., 0])
        den = np.linalg.norm(g) * np.linalg.norm(vp, axis=-1)
        c = -C[..., j] / np.where(den > 0, den, 1.0)
        c = np.where(np.abs(c) > 1.0 - _SNAP, np.sign(c), c)  # a double root: exactly
        ac = np.arccos(np.clip(c, -1.0, 1.0))[..., None] * np.array([1.0, -1.0])
        ok = (np.abs(c) <= 1.0 + 1e-7) & (den > 0)
        return (al - be)[..., None] + ac, np.broadcast_to(ok[..., None], ac.shape)
    if pl.mode == "pp":
        q2 = -((y - p) @ pl.u[0]) / float(pl.u[0] @ W[1])
        return q2[..., None], np.ones(q2.shape + (1,), dtype=bool)
    s = y - pl.r1
    if pl.mode == "lin":
        q2 = (h - s @ W[0]) / float(W[0] @ W[1])
        return q2[..., None], np.ones(q2.shape + (1,), dtype=bool)
    b = s @ W[1]
    ss = np.sum(s * s, axis=-1)
    disc = b * b - (ss - rho2)
    disc = np.where(np.abs(disc) <= _SNAP * (b * b + ss + rho2), 0.0, disc)
    ok = disc >= -1e-9 * (1.0 + rho2)
    r = np.sqrt(np.maximum(disc, 0.0))[..., None] * np.array([1.0, -1.0])
    return -b[..., None] + r, np.broadcast_to(ok[..., None], r.shape)


# -- roots of the eliminant ---------------------------------------------------------------------

def _companion_roots(c: np.ndarray) -> np.ndarray:
    """Roots ``(M, d)`` of polynomials with coefficients ``c (M, d + 1)``, highest first, each
    with its top coefficient non-zero (a batched companion matrix)."""
    M, n = c.shape[0], c.shape[1] - 1
    A = np.zeros((M, n, n), dtype=c.dtype)
    A[:, 0, :] = -c[:, 1:] / c[:, :1]
    A[:, np.arange(1, n), np.arange(n - 1)] = 1.0
    return np.linalg.eigvals(A)


def _roots_by_degree(coef: np.ndarray, degree: np.ndarray, width: int, top) -> np.ndarray:
    """Roots ``(N, width)`` (NaN-padded, complex) of each row's polynomial of its ``degree``;
    ``top(coef, d)`` gives the rows' coefficients (highest first) for degree d."""
    out = np.full((coef.shape[0], width), np.nan + 0j)
    for d in np.unique(degree):
        rows = np.flatnonzero(degree == d)
        if d <= 0:
            continue
        c = top(coef[rows], int(d))
        out[rows, :c.shape[1] - 1] = _companion_roots(c)
    return out


def _roots_revolute(pl: Plan, p, h, rho2) -> np.ndarray:
    """Real roots q3 ``(N, 2·_TRIG_MAX)`` (NaN-padded) for a revolute joint 3 (FFT in q3)."""
    W, P = pl.axes.w, pl.axes.r
    th = 2.0 * math.pi * np.arange(_TRIG_SAMPLES) / _TRIG_SAMPLES
    y = rotate(W[2], P[2], th, pl.wrist)  # (S, 3)
    psi = _eliminant(pl, y[None], p[:, None], h[:, None], rho2[:, None])  # (N, S)
    F = np.fft.fft(psi, axis=-1) / _TRIG_SAMPLES
    m = _TRIG_MAX
    ck = np.concatenate([F[:, -m:], F[:, :m + 1]], axis=1)  # c_{-m} .. c_m
    mag = np.abs(ck)
    big = mag.max(axis=1, keepdims=True)
    keep = mag[:, m + 1:] > _TRIM * np.maximum(big, 1e-300)  # c_1 .. c_m
    degree = np.where(keep.any(axis=1), m - np.argmax(keep[:, ::-1], axis=1), 0)

    def top(c, d):
        return c[:, m - d:m + d + 1][:, ::-1]  # z^{2d} .. z^0: c_d .. c_{-d}

    z = _roots_by_degree(ck, degree, 2 * m, top)
    on = np.abs(np.abs(z) - 1.0) <= _ROOT_TOL
    return np.where(on, np.angle(z), np.nan)


_CHEB_T = np.cos(math.pi * (np.arange(_CHEB_NODES) + 0.5) / _CHEB_NODES)
_CHEB_FIT = np.linalg.pinv(np.polynomial.chebyshev.chebvander(_CHEB_T, _POLY_DEG))
_CHEB_TO_POWER = np.stack([np.pad(c, (0, _POLY_DEG + 1 - c.size)) for c in (
    np.polynomial.chebyshev.cheb2poly(np.eye(_POLY_DEG + 1)[k]) for k in range(_POLY_DEG + 1))])
# row k: T_k in powers of t (low first)


def _roots_prismatic(pl: Plan, p, h, rho2) -> np.ndarray:
    """Real roots q3 ``(N, _POLY_DEG)`` (NaN-padded) for a prismatic joint 3 (Chebyshev fit on
    ``[−L, L]``, L from the arm's size and the target's distance)."""
    L = 4.0 * pl.axes.scale + np.linalg.norm(p - pl.wrist, axis=-1)  # (N,)
    q3 = L[:, None] * _CHEB_T  # (N, S)
    y = pl.wrist + q3[..., None] * pl.axes.w[2]
    psi = _eliminant(pl, y, p[:, None], h[:, None], rho2[:, None])
    cheb = psi @ _CHEB_FIT.T  # (N, deg+1) Chebyshev coefficients in t = q3 / L
    power = cheb @ _CHEB_TO_POWER  # low first
    mag = np.abs(power)
    keep = mag > _TRIM * np.maximum(mag.max(axis=1, keepdims=True), 1e-300)
    degree = np.where(keep.any(axis=1), _POLY_DEG - np.argmax(keep[:, ::-1], axis=1), 0)

    def top(c, d):
        return c[:, :d + 1][:, ::-1]

    t = _roots_by_degree(power, degree, _POLY_DEG, top)
    real = np.abs(t.imag) <= _ROOT_TOL * (1.0 + np.abs(t))
    return np.where(real, t.real * L[:, None], np.nan)


# -- the solver ---------------------------------------------------------------------------------

def _polish(pl: Plan, q: np.ndarray, p: np.ndarray, live: np.ndarray, iters: int = 3):
    """Newton steps on ``M1 M2 M3 w = p`` for ``q (..., 3)``; a step is kept where it helps
    (none once every ``live`` candidate is at rounding). Returns q and ``|M1 M2 M3 w − p|``."""
    f = _place(pl, q) - p
    fn = np.linalg.norm(f, axis=-1)
    small = 1e-14 * (pl.axes.scale + np.linalg.norm(p, axis=-1))
    for _ in range(iters):
        if not np.any(live & (fn > small)):  # at rounding already (the usual case)
            break
        J = _position_jacobian(pl.axes, pl.kinds, q, pl.wrist)
        ok = np.abs(np.linalg.det(J)) > 1e-300
        Js = np.where(ok[..., None, None], J, np.eye(3))
        dq = -np.linalg.solve(Js, f[..., None])[..., 0]
        qn = q + np.where(ok[..., None] & np.isfinite(dq), dq, 0.0)
        f_new = _place(pl, qn) - p
        nn = np.linalg.norm(f_new, axis=-1)
        better = nn < fn
        q = np.where(better[..., None], qn, q)
        f = np.where(better[..., None], f_new, f)
        fn = np.where(better, nn, fn)
    return q, fn


def _joint1(pl: Plan, x: np.ndarray, p: np.ndarray) -> np.ndarray:
    W = pl.axes.w
    if pl.kinds[0] == "R":
        return sp1(W[0], pl.r1, x, p)[0]
    return (p - x) @ W[0]


def _rotation(pl: Plan, q: np.ndarray) -> np.ndarray:
    """The rotation of ``M1 M2 M3`` at ``q (..., 3)`` (prismatic joints do not turn)."""
    R = np.broadcast_to(np.eye(3), q.shape[:-1] + (3, 3))
    for i in range(3):
        if pl.kinds[i] == "R":
            R = R @ rotation_matrix(pl.axes.w[i], q[..., i])
    return R


def _polish_least_squares(model: ChainModel, q: np.ndarray, T: np.ndarray, tol: float,
                          iters: int = 4) -> np.ndarray:
    """Gauss–Newton steps with a truncated pseudo-inverse on candidates ``q (M, 6)`` that miss
    ``T (M, 4, 4)`` by more than ``tol / 10`` (a step is kept where it lowers the error).

    Where the position root is a double one (the wrist centre on the boundary of what joints
    1-3 reach, e.g. the Stanford arm at q2 = 0) the back-substitution is good to √ε only; with a
    regular wrist the wrist absorbs it, but near θ5 = 0 it cannot, and the Jacobian is singular
    there (hence the truncated pseudo-inverse: the error left is of the order of the step's
    square).
    """
    pos, ang = pose_residuals(model, q, T)
    bad = np.flatnonzero(np.maximum(pos, ang) > 0.1 * tol)
    if bad.size == 0:
        return q
    q = q.copy()  # (the pseudo-inverse: a handful of rows)
    q[bad] = newton_polish(model, q[bad], T[bad], iters, rcond=1e-7)
    return q


def _slots(ok: np.ndarray, K: int) -> np.ndarray:
    """Indices of the columns of ``ok (N, C)`` that some row fills, padded (with unused or
    out-of-range indices) to at least ``K``, in order."""
    used = ok.any(axis=0)
    k = np.flatnonzero(used)
    if k.size < K:
        k = np.sort(np.concatenate([k, np.flatnonzero(~used)[:K - k.size]]))
        k = np.concatenate([k, np.arange(ok.shape[1], ok.shape[1] + K - k.size)])
    return k


def solve_decoupled(model: ChainModel, T: np.ndarray, *, tol: float = 1e-9,
                    wrist_tol: float = _WRIST_TOL) -> IKAllResult:
    """All solutions (8 slots) of the decoupled ``model`` for poses ``T (N, 4, 4)``.

    >>> import kinestat, numpy as np
    >>> m = kinestat.load("stanford")
    >>> q = np.array([0.3, -0.8, 0.25, 0.4, 0.6, -0.2])
    >>> res = kinestat.ik_all(m, kinestat.fk(m, q))
    >>> res.method, int(res.n_solutions)
    ('decoupled', 8)
    """
    pl = plan(model)
    W = pl.axes.w
    N = T.shape[0]
    g = T @ pl.T0_inv
    p = np.einsum("nij,j->ni", g[:, :3, :3], pl.wrist) + g[:, :3, 3]
    h, rho2 = _invariants(pl, p)
    q3 = (_roots_revolute if pl.kinds[2] == "R" else _roots_prismatic)(pl, p, h, rho2)
    has3 = np.isfinite(q3)
    col = has3.any(axis=0)  # root slots that some pose uses
    col[0] |= not col.any()
    q3, has3 = q3[:, col], has3[:, col]
    R = q3.shape[1]
    q3z = np.where(has3, q3, 0.0)
    y = _move(pl.kinds[2], W[2], pl.axes.r[2], q3z, np.broadcast_to(pl.wrist, (N, R, 3)))
    pN, hN, rN = p[:, None], h[:, None], rho2[:, None]
    q2, ok2 = _joint2(pl, y, pN, hN, rN)  # (N, R, B)
    B = q2.shape[-1]
    q2 = np.where(ok2, q2, 0.0)
    x = _move(pl.kinds[1], W[1], pl.axes.r[1], q2, np.broadcast_to(y[:, :, None], (N, R, B, 3)))
    pB = p[:, None, None]
    q1 = _joint1(pl, x, np.broadcast_to(pB, x.shape))
    q123 = np.stack([q1, q2, np.broadcast_to(q3z[..., None], q2.shape)], axis=-1)
    q123, miss = _polish(pl, q123, pB, has3[..., None] & ok2)
    Rp = np.swapaxes(_rotation(pl, q123), -1, -2) @ g[:, None, None, :3, :3]
    # where the wrist is near θ5 = 0 it cannot absorb an error of the position stage
    near = np.linalg.norm(np.cross(W[3], Rp @ W[5]), axis=-1) < 1e-6
    t4, t5, t6, e45, sing, sig, fam = _wrist(W, Rp, wrist_tol)  # (N, R, B, 2)
    sh = (N, R, B, 2)
    q = np.concatenate([np.broadcast_to(q123[..., None, :], sh + (3,)),
                        np.stack([t4, t5, t6], axis=-1)], axis=-1).reshape(N, -1, 6)
    ok = np.broadcast_to(((has3[..., None] & ok2) & e45)[..., None], sh).reshape(N, -1)
    q = np.where(ok[..., None], q, 0.0)
    sing = np.broadcast_to(sing[..., None], sh).reshape(N, -1)
    sig = np.broadcast_to(sig, sh).reshape(N, -1)
    fam = np.broadcast_to(fam, sh).reshape(N, -1)
    need = ok & np.broadcast_to(((miss > 0.01 * tol) | near)[..., None], sh).reshape(N, -1)
    if need.any():  # double position roots are good to √ε only: polish where needed
        q[need] = _polish_least_squares(model, q[need], np.broadcast_to(
            T[:, None], ok.shape + (4, 4))[need], tol)
    k = _slots(ok, 8)  # the candidate slots some pose fills (fewer pairs to de-duplicate)
    q, ok, sing, sig, fam = (np.take(a, k, axis=1, mode="clip") for a in (q, ok, sing, sig, fam))
    ok = ok & (k < sh[1] * sh[2] * sh[3])  # padding slots hold nothing
    res = pack(model, q, ok, T, 8, tol=tol, method=METHOD, reason_none=_REASON,
               singular=sing, family_sign=sig, family_value=fam, family_joints=(3, 5))
    # the wrist centre is reached (not only a root of the eliminant found: at a pose out of
    # reach a real root can still leave the centre off by the distance to what joints 1-3 reach)
    reached = has3[..., None] & ok2 & (miss <= 1e-6 * pl.axes.scale)
    placed = reached.any(axis=(1, 2)) & (res.n_solutions == 0)
    res.reason[placed] = _REASON_WRIST  # (a fresh array of this call's result)
    return res
