"""Building blocks of the Levenberg–Marquardt IK in NumPy (Levenberg 1944, Marquardt 1963;
"damped least squares", Wampler 1986): the result type, joint wrapping into limits, random
restarts, the scaled SE(3) error and one damped step. Shared by :mod:`kinestat.serial.ik` and its
NumPy reference (:mod:`kinestat.serial._reference`); the compiled kernels do the same in
:mod:`kinestat.serial._ik_kernels`."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.fk import fk_frames
from kinestat.serial.jacobian import jacobian_from_frames
from kinestat.spatial.se3 import so3_log

__all__ = ["IKResult", "wrap_joints", "wrap_rotating", "damped_step", "blocked_joints"]


def wrap_joints(model: ChainModel, q, reference=None) -> np.ndarray:
    """Shift rotating joints by whole turns: into their limits when possible (nearest
    ``reference``, default 0), else to [-π, π) about the reference. Prismatic joints are only
    clipped to their limits; rotating joints that cannot be shifted into their limits are
    clipped too. ``q (..., n)``; ``reference`` broadcasts against it."""
    q = model.check_q(q)
    rot = ~model.prismatic
    lo, hi = model.lower, model.upper
    if reference is None:
        ref = np.zeros_like(q)
    else:
        ref = model.check_q(reference, "reference")
        try:
            ref = np.broadcast_to(ref, q.shape)
        except ValueError:
            raise InputError(f"reference of shape {ref.shape} does not broadcast to q's shape "
                             f"{q.shape}") from None
    base = ref + (q - ref + math.pi) % (2 * math.pi) - math.pi
    # the whole-turn shift nearest the reference that lies in [lo, hi]
    ks = np.arange(-3, 4) * (2 * math.pi)
    cand = base[..., None] + ks
    inside = (cand >= lo[:, None]) & (cand <= hi[:, None])
    dist = np.where(inside, np.abs(cand - ref[..., None]), np.inf)
    idx = np.argmin(dist, axis=-1)
    best = np.take_along_axis(cand, idx[..., None], axis=-1)[..., 0]
    has = np.isfinite(np.take_along_axis(dist, idx[..., None], axis=-1)[..., 0])
    out = np.where(rot, np.where(has, best, base), q)
    return np.clip(out, lo, hi)


def wrap_rotating(model: ChainModel, q) -> np.ndarray:
    """Rotating joints wrapped to [-π, π); prismatic joints untouched (limits ignored)."""
    q = model.check_q(q)
    return np.where(model.prismatic, q, (q + math.pi) % (2 * math.pi) - math.pi)


@dataclass(frozen=True, eq=False)
class IKResult:
    """Result of :func:`ik`, batched like the poses ``B``.

    Attributes:
        q: ``(*B, n)`` joint values (radians / length): the solution where ``success``, the best
            configuration found otherwise.
        success: ``(*B,)`` the pose is reproduced within the tolerances and q is within limits.
        position_error: ``(*B,)`` distance between the reached and target positions (length).
        rotation_error: ``(*B,)`` angle between the reached and target orientations (radians).
        iterations: ``(*B,)`` total iterations spent (over all attempts).
        attempts: ``(*B,)`` starts used (1 = converged from the given start).
    """

    q: np.ndarray
    success: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    iterations: np.ndarray
    attempts: np.ndarray


def _random_q(model: ChainModel, rng: np.random.Generator, k: int, scale: float) -> np.ndarray:
    lo, hi = model.lower, model.upper
    rot = ~model.prismatic
    lo_f = np.where(np.isfinite(lo), lo, np.where(rot, -math.pi, -scale))
    hi_f = np.where(np.isfinite(hi), hi, np.where(rot, math.pi, scale))
    # a revolute joint spanning more than a turn: one turn is enough
    span = np.where(rot, np.minimum(hi_f - lo_f, 2 * math.pi), hi_f - lo_f)
    return lo_f + rng.random((k, model.n)) * span


def _errors(model: ChainModel, q: np.ndarray, Tt: np.ndarray, L: float):
    """Link frames, scaled error vectors ``[ω; δp/L]`` (k, 6) and squared cost (k,)."""
    F = fk_frames(model, q)
    T = F[..., -1, :, :]
    w = so3_log(Tt[..., :3, :3] @ np.swapaxes(T[..., :3, :3], -1, -2))
    dp = Tt[..., :3, 3] - T[..., :3, 3]
    e = np.concatenate([w, dp / L], axis=-1)
    return F, e, np.sum(e * e, axis=-1)


def blocked_joints(model: ChainModel, q: np.ndarray, step: np.ndarray) -> np.ndarray | None:
    """``free (k, n)``: 0.0 for each joint that sits on a limit the ``step`` pushes it beyond
    (a prismatic joint, or a revolute one whose limits span less than a turn), 1.0 for the
    others; None when no joint is blocked. Clipping such a joint leaves a step computed as if
    it moved, which the others do not make up for: the iteration stalls on the limit (a
    gripper's finger at the end of its travel); the step is solved again without it."""
    bounded = model.prismatic | (model.upper - model.lower < 2 * math.pi)
    out = bounded & (((q <= model.lower) & (step < 0)) | ((q >= model.upper) & (step > 0)))
    return np.where(out, 0.0, 1.0) if out.any() else None


def damped_step(model: ChainModel, frames: np.ndarray, e: np.ndarray, mu: np.ndarray,
                L: float, free: np.ndarray | None = None) -> np.ndarray:
    """One Levenberg–Marquardt step ``δq (k, n)`` for the scaled errors ``e = [ω; δp/L]``.

    ``(JᵀJ + μ s I) δx = Jᵀ e`` with ``J = [J_ω; (J_v − p × J_ω)/L] · D`` (the space Jacobian's
    velocity rows moved to the end point p, lengths over L, prismatic columns scaled by
    ``D = L``), ``s = trace(JᵀJ)/n``, and ``δq = D δx``. ``free (k, n)``
    (:func:`blocked_joints`) multiplies ``D``: a blocked joint's column is zero and its step 0.
    """
    n = model.n
    D = np.where(model.prismatic, L, 1.0)
    if free is not None:
        D = D * free
    J = jacobian_from_frames(model, frames)
    p = frames[..., -1, :3, 3]
    Jw = J[..., :3, :]
    Jv = J[..., 3:, :] - np.cross(p[..., None, :], np.swapaxes(Jw, -1, -2)).swapaxes(-1, -2)
    Js = np.concatenate([Jw, Jv / L], axis=-2) * D[..., None, :]
    JtJ = np.swapaxes(Js, -1, -2) @ Js
    g = np.einsum("...ji,...j->...i", Js, e)
    s = np.maximum(np.trace(JtJ, axis1=-2, axis2=-1) / n, 1e-12)
    A = JtJ + (mu * s)[..., None, None] * np.eye(n)
    return np.linalg.solve(A, g[..., None])[..., 0] * D
