"""Newton refinement of platform poses on leg-length equations (shared by the FK solvers)."""

from __future__ import annotations

import numpy as np

from kinestat.spatial.se3 import so3_exp_trusted


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product over the last axis (faster than ``np.cross`` for large batches)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


#: Rodrigues' formula, :func:`kinestat.spatial.se3.so3_exp` (unchecked: the Newton steps' own
#: rotation vectors)
rotvec_matrix = so3_exp_trusted


def apply_twist(pose: np.ndarray, twist: np.ndarray) -> np.ndarray:
    """Move poses by small spatial twists ``[δφ; δx_O]`` (base frame): ``X' = Rot(δφ) X + δx_O``."""
    R = rotvec_matrix(twist[..., :3])
    out = np.empty(np.broadcast_shapes(pose.shape, twist.shape[:-1] + (4, 4)))
    out[..., :3, :3] = R @ pose[..., :3, :3]
    out[..., :3, 3] = (R @ pose[..., :3, 3:4])[..., 0] + twist[..., 3:]
    out[..., 3, :] = (0.0, 0.0, 0.0, 1.0)
    return out


def leg_residual(base: np.ndarray, top: np.ndarray, lengths, pose: np.ndarray):
    """Residuals ``|X_i − B_i| − L_i`` and their Jacobian w.r.t. a twist ``[δφ; δx_O]``.

    ``dl_i = (X_i × S_i)·δφ + S_i·δx_O`` with ``S_i`` the unit leg direction.
    """
    X = top @ np.swapaxes(pose[..., :3, :3], -1, -2) + pose[..., None, :3, 3]
    d = X - base
    l = np.sqrt(np.sum(d * d, axis=-1))
    S = d / np.where(l > 0, l, 1.0)[..., None]
    J = np.concatenate([cross(X, S), S], axis=-1)
    return l - lengths, J


def refine(base, top, lengths, pose, iterations: int = 3):
    """A few Newton steps on the leg-length equations; returns (pose, residuals).

    ``base``/``top`` are the ``(m, 3)`` joint points (base/top frames), ``lengths (..., m)`` the
    targets and ``pose (..., 4, 4)`` the start. The normal equations carry a tiny Levenberg term
    so singular Jacobians do not raise; regular solutions converge quadratically.
    """
    for _ in range(iterations):
        r, J = leg_residual(base, top, lengths, pose)
        Jt = np.swapaxes(J, -1, -2)
        JtJ = Jt @ J
        lam = 1e-14 * np.trace(JtJ, axis1=-2, axis2=-1)[..., None, None] + 1e-300
        step = -np.linalg.solve(JtJ + lam * np.eye(6), Jt @ r[..., None])[..., 0]
        step = np.where(np.isfinite(step), step, 0.0)
        pose = apply_twist(pose, step)
    r, _ = leg_residual(base, top, lengths, pose)
    return pose, r


def leg_errors(base: np.ndarray, top: np.ndarray, lengths, pose: np.ndarray) -> np.ndarray:
    """Largest |leg length − target| (...) of each pose (reverse kinematics only)."""
    X = top @ np.swapaxes(pose[..., :3, :3], -1, -2) + pose[..., None, :3, 3]
    d = X - base
    return np.max(np.abs(np.sqrt(np.sum(d * d, axis=-1)) - lengths), axis=-1)


def refine_where(base, top, lengths, pose, mask, tol: float, iterations: int = 3):
    """Newton-refine the poses where ``mask`` holds and the leg error exceeds ``tol``.

    ``lengths`` broadcasts against ``pose``'s batch shape. Each pass only touches the poses
    still above ``tol``. Returns ``(pose, max |residual|)``, the residual ``inf`` outside
    ``mask`` or where not finite.
    """
    pose = np.array(pose, copy=True)
    Lb = np.broadcast_to(lengths, pose.shape[:-2] + (np.shape(lengths)[-1],))
    err = leg_errors(base, top, Lb, pose)
    err = np.where(mask & np.isfinite(err), err, np.inf)
    idx = np.nonzero(mask & (err > tol))
    for _ in range(iterations):
        if len(idx[0]) == 0:
            break
        sub, r = refine(base, top, Lb[idx], pose[idx], iterations=1)
        e = np.max(np.abs(r), axis=-1)
        pose[idx] = sub
        err[idx] = np.where(np.isfinite(e), e, np.inf)
        keep = e > tol
        idx = tuple(i[keep] for i in idx)
    return pose, err
