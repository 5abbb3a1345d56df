"""One guidance step: solve ``J(q) δq = B`` (Nadkarni eq. 4-11), batched.

[A]·D = B of eq. 4-11b is literally ``jacobian(model, q) @ dq = B`` with twists ``[ω; v_O]``.
Twist Jacobians mix units (rad and length), so their singular values and condition numbers
depend on the length unit. Everything here works on the *dimensionless* Jacobian

    J_s = diag(I, I/L) · J · diag(c),   c_j = L for prismatic joints, 1 otherwise,

with ``L`` a characteristic length of the mechanism (:func:`characteristic_length`): the
solution of a square regular system is the same, but singular values, condition numbers,
least-squares weights and damping no longer change when inches become millimetres.

- :func:`solve_step`: exact solve (n = 6), least squares (n ≠ 6, or a rank-deficient J), or
  damped least squares; reports σ_min and the condition number of J_s.
- :func:`escape_singularity` (greedy, one joint per try) and :func:`perturb_all_joints`
  (DISP's way, every joint at once): Nadkarni ch. IV "Singularities" 1), give the joints
  small increments until the singularity disappears.
- :func:`solve_second_order`: Nadkarni eq. 5-5 (suggestion 2), the δθ²/2 terms.
- :func:`limit_violation`: ch. IV "Singularities" 2), a joint at its limit.
- :func:`origin_displacement_twist`, :func:`split_substep_count`: the step as DISP (1977)
  computed it in Illustration 5 (docs/seed-errata.md G1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.fk import fk_frames
from kinestat.serial.jacobian import jacobian
from kinestat.serial.lengths import characteristic_length
from kinestat.spatial.transforms import as_array

__all__ = [
    "StepSolution",
    "characteristic_length",
    "column_scale",
    "scaled_jacobian",
    "conditioning",
    "solve_step",
    "damping_for",
    "second_order_residual",
    "solve_second_order",
    "escape_singularity",
    "perturb_all_joints",
    "sigma_min_gradient",
    "limit_violation",
    "origin_displacement_twist",
    "split_substep_count",
    "DEFAULT_COND_LIMIT",
]

#: Dimensionless condition number above which a configuration counts as singular: a relative
#: error of 1e-16 in B becomes ~1e-13 in δq, but first-order steps of a given size grow by the
#: same factor, so the linearisation stops describing the motion (see docs/guidance.md).
DEFAULT_COND_LIMIT = 1.0e3


@dataclass(frozen=True)
class StepSolution:
    """Result of :func:`solve_step` (batched like its inputs).

    ``dq`` ``(..., n)`` joint increments; ``sigma_min`` and ``cond`` the smallest singular value
    and condition number of the dimensionless Jacobian; ``residual`` ``|J dq - B|`` in scaled
    units (0 for an exact solve); ``damping`` the λ used (0 unless damped); ``method`` is
    ``"exact"``, ``"least_squares"`` or ``"damped"``.
    """

    dq: np.ndarray
    sigma_min: np.ndarray
    cond: np.ndarray
    residual: np.ndarray
    damping: np.ndarray
    method: str


def column_scale(model: ChainModel, length: float) -> np.ndarray:
    """Column scale ``c`` ``(n,)``: ``length`` for prismatic joints, 1 for the others."""
    return np.where(model.prismatic, float(length), 1.0)


def scaled_jacobian(J, prismatic, length: float) -> np.ndarray:
    """Dimensionless Jacobian ``diag(I, I/L) J diag(c)`` ``(..., 6, n)``."""
    J = np.asarray(J, dtype=float)
    row = np.array([1.0, 1.0, 1.0, 1.0 / length, 1.0 / length, 1.0 / length])
    col = np.where(np.asarray(prismatic, dtype=bool), float(length), 1.0)
    return row[:, None] * J * col[None, :]


def conditioning(J_s) -> tuple[np.ndarray, np.ndarray]:
    """``(sigma_min, cond)`` of dimensionless Jacobians ``(..., 6, n)``.

    For n < 6 the rank is at most n, so σ_min is the n-th singular value (the least-squares
    problem is still well posed when it is not small); cond is ``inf`` when σ_min is 0.
    """
    s = np.linalg.svd(np.asarray(J_s, dtype=float), compute_uv=False)
    smin = s[..., -1]
    with np.errstate(divide="ignore"):
        cond = np.where(smin > 0, s[..., 0] / np.where(smin > 0, smin, 1.0), np.inf)
    return smin, cond


def damping_for(sigma_min, sigma_max, cond_limit: float = DEFAULT_COND_LIMIT,
                max_damping: float = 0.1) -> np.ndarray:
    """Damping λ of damped least squares, zero away from singularities.

    ``λ² = λ_max² (1 − (σ_min/ε)²)`` for ``σ_min < ε = σ_max / cond_limit``, else 0
    (Nakamura & Hanafusa 1986; Maciejewski & Klein 1988): λ grows smoothly from 0 as the
    configuration approaches a singularity, so regular steps stay exact.
    """
    smin = np.asarray(sigma_min, dtype=float)
    eps = np.asarray(sigma_max, dtype=float) / cond_limit
    ratio = np.clip(smin / np.where(eps > 0, eps, 1.0), 0.0, 1.0)
    lam2 = np.where(smin < eps, max_damping**2 * (1.0 - ratio**2), 0.0)
    return np.sqrt(lam2)


def solve_step(J, B, *, prismatic, length: float = 1.0, damping=None,
               cond_limit: float = DEFAULT_COND_LIMIT, max_damping: float = 0.1) -> StepSolution:
    """Solve ``J δq = B`` (eq. 4-11) for Jacobians ``(..., 6, n)`` and twists ``(..., 6)``.

    Args:
        J: the twist Jacobian ``(..., 6, n)``.
        B: the hand displacement twist ``[δθ u_ω; v_O]`` ``(..., 6)``.
        prismatic: boolean mask ``(n,)`` of prismatic joints (for the dimensionless scaling).
        length: the characteristic length L, one number or one per Jacobian ``(...)``.
        damping: ``None`` for the plain solution (exact when n = 6 and J is regular, least
            squares / minimum norm otherwise), ``"auto"`` for damped least squares with
            :func:`damping_for`, or a fixed λ ≥ 0.

    The solve goes through the SVD of the dimensionless Jacobian, which gives σ_min and the
    condition number for free and handles every shape.
    """
    J = np.asarray(J, dtype=float)
    B = np.asarray(B, dtype=float)
    if J.ndim < 2 or J.shape[-2] != 6:
        raise InputError(f"J must have shape (..., 6, n), got {J.shape}")
    if B.shape[-1:] != (6,):
        raise InputError(f"B must have shape (..., 6), got {B.shape}")
    if not (np.all(np.isfinite(J)) and np.all(np.isfinite(B))):
        raise InputError("J or B contains NaN or infinity")
    L = np.asarray(length, dtype=float)[..., None]
    if not np.all((L > 0) & np.isfinite(L)):
        raise InputError(f"length must be positive and finite, got {length!r}")
    n = J.shape[-1]
    row = np.concatenate(np.broadcast_arrays(np.ones(3), 1.0 / L), axis=-1)
    col = np.where(np.asarray(prismatic, dtype=bool), L, 1.0)
    Js = row[..., :, None] * J * col[..., None, :]
    Bs = row * B
    U, s, Vt = np.linalg.svd(Js, full_matrices=False)
    smin = s[..., -1]
    smax = s[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        cond = np.where(smin > 0, smax / np.where(smin > 0, smin, 1.0), np.inf)
    if damping is None:
        lam = np.zeros_like(smin)
        method = "exact" if n == 6 else "least_squares"
        tiny = s <= np.finfo(float).eps * 16 * smax[..., None] * max(n, 6)
        with np.errstate(divide="ignore"):
            inv_s = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, s))
        if np.any(tiny):
            method = "least_squares"
    else:
        if isinstance(damping, str):
            if damping != "auto":
                raise InputError(f"damping must be None, 'auto' or a number, got {damping!r}")
            lam = damping_for(smin, smax, cond_limit, max_damping)
        else:
            lam = np.broadcast_to(np.asarray(damping, dtype=float), smin.shape)
            if np.any(lam < 0) or not np.all(np.isfinite(lam)):
                raise InputError("damping λ must be finite and ≥ 0")
        inv_s = s / (s * s + lam[..., None] ** 2)
        method = "damped" if np.any(lam > 0) else ("exact" if n == 6 else "least_squares")
    UtB = np.einsum("...ji,...j->...i", U, Bs)
    dqs = np.einsum("...ji,...j->...i", Vt, inv_s * UtB)
    dq = dqs * col
    res = np.linalg.norm(np.einsum("...ij,...j->...i", Js, dqs) - Bs, axis=-1)
    return StepSolution(dq=dq, sigma_min=smin, cond=cond, residual=res, damping=lam,
                        method=method)


def _axes_points(model: ChainModel, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    F = fk_frames(model, q)
    return F[..., :-1, :3, 2], F[..., :-1, :3, 3], F[..., -1, :3, 3]


def second_order_residual(model: ChainModel, q, dq, omega, disp) -> np.ndarray:
    """Residual ``(..., 6)`` of Nadkarni's eqs. 4-9 and 5-5 for joint increments ``dq``.

    ``[Σ δθ_j u_j − δθ u_ω ;  Σ (h_j δθ_j u_j + δθ_j u_j×ρ_jH + δθ_j²/2 u_j×(u_j×ρ_jH))
    + Σ_prismatic δr_j u_j − δr u_v]`` with ``ρ_jH`` from a point of axis j to the hand origin
    O_H; ``omega`` is δθ u_ω and ``disp`` the intended displacement δr u_v of O_H.
    """
    u, p, o = _axes_points(model, q)
    dq = np.asarray(dq, dtype=float)
    pris = model.prismatic
    h = model.pitches
    rho = o[..., None, :] - p
    ux = np.cross(u, rho)
    uux = np.cross(u, ux)
    t = np.where(pris, 0.0, dq)[..., None]
    rot = np.sum(t * u, axis=-2) - omega
    lin = (np.sum(np.where(pris[:, None], dq[..., None] * u, 0.0), axis=-2)
           + np.sum(t * (h[:, None] * u + ux) + 0.5 * t * t * uux, axis=-2) - disp)
    return np.concatenate([rot, lin], axis=-1)


def solve_second_order(model: ChainModel, q, B, disp, *, length: float = 1.0,
                       dq0=None, tol: float = 1e-14, max_iter: int = 20
                       ) -> tuple[np.ndarray, int, float]:
    """Joint increments from the second-order equations 4-9 and 5-5 (Nadkarni suggestion 2).

    ``B`` is the step twist (its rotation part is δθ u_ω); ``disp`` ``(3,)`` the intended
    displacement of the hand origin O_H during the step (the chord of the path, not the
    first-order velocity). Starts from the first-order solution ``dq0`` (``J dq0 = B``) and
    refines it by Newton iterations (the thesis suggests Freudenstein & Roth's parameter
    perturbation; Newton from the first-order solution converges in a few iterations for steps
    of a few degrees). Returns ``(dq, iterations, final residual)`` for one configuration.
    """
    q = model.check_q(q)
    if q.ndim != 1:
        raise InputError("solve_second_order takes one configuration q of shape (n,)")
    B = np.asarray(B, dtype=float)
    disp = np.asarray(disp, dtype=float)
    u, p, o = _axes_points(model, q)
    pris = model.prismatic
    h = model.pitches
    rho = o - p
    ux = np.cross(u, rho)
    uux = np.cross(u, ux)
    if dq0 is None:
        dq0 = solve_step(jacobian(model, q), B, prismatic=pris, length=length).dq
    dq = np.array(dq0, dtype=float)
    scale = np.array([1.0, 1.0, 1.0, 1.0 / length, 1.0 / length, 1.0 / length])
    col = np.where(pris, float(length), 1.0)
    res = np.inf
    it = 0
    for it in range(1, max_iter + 1):
        r = second_order_residual(model, q, dq, B[:3], disp) * scale
        res = float(np.linalg.norm(r))
        if res <= tol:
            return dq, it - 1, res
        t = np.where(pris, 0.0, dq)
        Jr = np.zeros((6, model.n))
        Jr[:3] = np.where(pris[None, :], 0.0, u.T)
        Jr[3:] = np.where(pris[None, :], u.T, (h[:, None] * u + ux + t[:, None] * uux).T)
        Js = scale[:, None] * Jr * col[None, :]
        step = np.linalg.lstsq(Js, -r, rcond=None)[0] * col
        dq = dq + step
    r = second_order_residual(model, q, dq, B[:3], disp) * scale
    return dq, it, float(np.linalg.norm(r))


def escape_singularity(model: ChainModel, q, *, length: float,
                       cond_limit: float = DEFAULT_COND_LIMIT, increment_deg: float = 1.0,
                       max_tries: int = 30) -> tuple[np.ndarray, float, int]:
    """Nadkarni's remedy for a singular [A]: small joint increments until it is regular.

    Greedy search: each try moves one joint by ±``increment_deg`` (prismatic joints by
    ±L/100), choosing the move that lowers the dimensionless condition number most, until it
    is below ``cond_limit``. Returns ``(q_new, cond_new, tries)``; ``cond_new >= cond_limit``
    means the search gave up after ``max_tries`` (the caller reports it and stops).
    """
    q = model.check_q(q).astype(float)
    pris = model.prismatic
    inc = np.where(pris, length / 100.0, math.radians(increment_deg))
    moves = np.concatenate([np.diag(inc), -np.diag(inc)])  # (2n, n)
    _, cond = conditioning(scaled_jacobian(jacobian(model, q), pris, length))
    cond = float(cond)
    lo, hi = model.lower, model.upper
    for tries in range(1, max_tries + 1):
        cand = q + moves
        ok = np.all((cand >= lo) & (cand <= hi), axis=-1)
        if not np.any(ok):
            return q, cond, tries
        _, cc = conditioning(scaled_jacobian(jacobian(model, cand), pris, length))
        cc = np.where(ok, cc, np.inf)
        best = int(np.argmin(cc))
        if not cc[best] < cond:  # no move improves: a flat spot, give up
            return q, cond, tries
        q = cand[best]
        cond = float(cc[best])
        if cond < cond_limit:
            return q, cond, tries
    return q, cond, max_tries


def sigma_min_gradient(model: ChainModel, q, *, length: float, h: float = 1e-6) -> np.ndarray:
    """``∂σ_min/∂q`` ``(n,)`` of the dimensionless Jacobian, per unit of the scaled joint
    variables (radians; prismatic joints in units of L), by central differences. A component
    within the differences' rounding (σ_min is computed to about ε σ_max, so ``16 ε σ_max / h``)
    is 0: a joint that cannot change σ_min (the base's turn about its own axis) gets no sign
    from rounding noise."""
    q = np.asarray(q, dtype=float)
    pris = model.prismatic
    scale = np.where(pris, length, 1.0)
    dq = np.diag(h * scale)
    cand = np.concatenate([q + dq, q - dq])
    smin, cond = conditioning(scaled_jacobian(jacobian(model, cand), pris, length))
    n = q.shape[0]
    g = (smin[:n] - smin[n:]) / (2.0 * h)
    floor = 16.0 * np.finfo(float).eps * float(np.max(smin * cond)) / h
    return np.where(np.abs(g) <= floor, 0.0, g)


def _best_signs(model: ChainModel, q, eps: np.ndarray, signs: np.ndarray, length: float
                ) -> tuple[np.ndarray, float]:
    """The sign pattern (every joint ±1) that gives ``q + eps·signs`` the smallest condition
    number: start from ``signs``, flip the one joint that lowers it most while one does by more
    than the condition number's rounding (relative ``8 ε κ``). Candidates outside the joint
    limits count as infinitely ill-conditioned."""
    pris = model.prismatic
    lo, hi = model.lower, model.upper

    def conds(S):
        cand = q + eps * S
        _, c = conditioning(scaled_jacobian(jacobian(model, cand), pris, length))
        ok = np.all((cand >= lo) & (cand <= hi), axis=-1)
        return np.where(ok, c, np.inf)

    s = signs.copy()
    best = float(conds(s[None, :])[0])
    for _ in range(model.n):
        flips = np.where(np.eye(model.n, dtype=bool), -s, s)
        c = conds(flips)
        i = int(np.argmin(c))
        if not c[i] < best * (1.0 - 8.0 * np.finfo(float).eps * best):
            break
        s, best = flips[i], float(c[i])
    return s, best


def perturb_all_joints(model: ChainModel, q, *, length: float,
                       cond_limit: float = DEFAULT_COND_LIMIT, increment_deg: float = 0.1,
                       max_tries: int = 300) -> tuple[np.ndarray, float, int]:
    """Nadkarni ch. IV, "Singularities" 1): "a new configuration of the manipulator by giving
    small increments to the joint variables till the singularity becomes non-existent" — the
    smallest such increments, to every joint at once.

    Every joint moves by the same amount t × ``increment_deg`` (prismatic joints: that angle
    in radians × L), each in its own direction: the sign pattern starts from the sign of
    ``∂σ_min/∂q`` (σ_min the smallest singular value of the dimensionless Jacobian; + where it
    is 0) and single joints are flipped while that lowers the condition number at that size.
    The criterion: the dimensionless condition number below ``cond_limit``. t is the smallest
    whole number ≤ ``max_tries`` that meets it (doubling, then bisection, which assumes the
    best condition number falls as t grows). A candidate past a joint limit does not count.
    Returns ``(q_new, cond_new, t)``; ``cond_new >= cond_limit`` means none within
    ``max_tries`` increments did (``q_new`` is then the start).

    >>> from kinestat.io.library import load
    >>> m = load("puma762")
    >>> q_wrist_singular = np.radians([90.0, -30.0, 30.0, 0.0, 0.0, 0.0])  # θ5 = 0
    >>> q, c, t = perturb_all_joints(m, q_wrist_singular, length=400.0)
    >>> d = np.degrees(q - q_wrist_singular)
    >>> bool(c < DEFAULT_COND_LIMIT), bool(np.allclose(np.abs(d), 0.1 * t))
    (True, True)
    >>> bool(np.ptp(np.sign(d)))                                     # mixed signs
    True
    """
    q = model.check_q(q).astype(float)
    scale = np.where(model.prismatic, length, 1.0)
    step = math.radians(increment_deg) * scale
    _, cond0 = conditioning(scaled_jacobian(jacobian(model, q), model.prismatic, length))
    g = sigma_min_gradient(model, q, length=length)
    signs0 = np.where(np.isfinite(g) & (g < 0.0), -1.0, 1.0)
    found: dict[int, tuple[np.ndarray, float]] = {}

    def meets(t: int) -> bool:
        if t not in found:
            found[t] = _best_signs(model, q, t * step, signs0, length)
        return found[t][1] < cond_limit

    lo, hi = 0, 1
    while hi < max_tries and not meets(hi):
        lo, hi = hi, min(2 * hi, max_tries)
    if not meets(hi):
        return q, float(cond0), max_tries
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if meets(mid) else (mid, hi)
    s, c = found[hi]
    return q + hi * step * s, c, hi


def limit_violation(model: ChainModel, q, tol: float = 1e-12):
    """First joint outside its limits: ``(index, "lower"/"upper", limit, value)`` or None."""
    q = np.asarray(q, dtype=float)
    lo, hi = model.lower, model.upper
    for i in range(model.n):
        if q[i] < lo[i] - tol:
            return i, "lower", float(lo[i]), float(q[i])
        if q[i] > hi[i] + tol:
            return i, "upper", float(hi[i]), float(q[i])
    return None


def origin_displacement_twist(B) -> np.ndarray:
    """``[ω; v + ½ ω×v]`` ``(..., 6)`` for a step twist ``B = [ω; v]`` ``(..., 6)``.

    ``v + ½ ω×v`` is the displacement, to second order, of the body point at the global
    origin; for a screw step ``[δθU; hδθU − δθU×ρn]`` it is ``hδθU − δθU×ρn + ½δθ²ρn``
    (ρn ⊥ U). Used as the translational part of B (with the first-order solve of eq. 4-11)
    it leaves every step off by ``½δθ² W`` (W the point of the turning axis nearest the
    origin): the error pattern of Nadkarni's Table A2-9 (docs/seed-errata.md G1).
    """
    B = as_array(B, shape_tail=(6,), name="step twist")
    w, v = B[..., :3], B[..., 3:]
    return np.concatenate([w, v + 0.5 * np.cross(w, v)], axis=-1)


def split_substep_count(B, deg2: float) -> int:
    """Equal sub-steps for one step twist ``B`` ``(6,)``: ``max(1, ⌈(δθ°)² / deg2⌉)`` with δθ°
    its rotation in degrees.

    With ``deg2`` in [39.72, 40.40) it gives the counts Table A2-9 implies (3, 3, 3, 3, 2, 2,
    then 1; 37 steps for 27 splits, 38 with the final correction: the caption's "Total 38
    steps"). The rule is fitted to those counts, not taken from the thesis.
    """
    B = as_array(B, shape_tail=(6,), name="step twist")
    if B.shape != (6,):
        raise InputError(f"split_substep_count takes one twist of shape (6,), got {B.shape}")
    if not (math.isfinite(deg2) and deg2 > 0):
        raise InputError(f"deg2 must be a positive number of square degrees, got {deg2!r}")
    d = math.degrees(float(np.linalg.norm(B[:3])))
    return max(1, math.ceil(d * d / deg2 - 1e-9))
