"""Shared steps of the all-solutions solvers: pose checks, Newton polishing, verification by
forward kinematics, de-duplication and packing into an :class:`IKAllResult`. Batched."""

from __future__ import annotations

import math

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic.result import IKAllResult
from kinestat.serial.fk import fk
from kinestat.serial.jacobian import fk_and_jacobian
from kinestat.spatial.validate import as_pose

__all__ = ["check_poses", "pose_residuals", "newton_polish", "wrap_angles", "pack", "nan_array",
           "call_compiled", "plain_poses",
           "reasons"]


def nan_array(shape: tuple[int, ...]) -> np.ndarray:
    """A float array of NaN (output slots the kernels fill)."""
    a = np.empty(shape)
    a.fill(np.nan)
    return a


_ENTRY: dict = {}


def call_compiled(kernel, *args, variant=None):
    """``kernel(*args)`` through the compiled overload's entry point: Numba's per-call
    resolution of the argument types (≈ 70 ns per array; 1-2 µs of a 13- or 18-argument
    single-pose call) is done once, on the first call, which goes through the dispatcher
    (compiling or loading the kernel) and records the overload its argument types select.

    The caller guarantees that the arguments' Numba types never change between calls: arrays
    it allocates itself, poses that are C-contiguous, aligned and writeable float64, and
    Python floats for the scalars. Anything else must call the dispatcher itself, or name the
    ``variant`` of argument types (e.g. None or an int in one place) it calls.
    """
    entry = _ENTRY.get((kernel, variant))
    if entry is not None:
        return entry(*args)
    out = kernel(*args)
    if not hasattr(kernel, "overloads"):  # NUMBA_DISABLE_JIT: a plain function
        return out
    cres = kernel.overloads.get(tuple(kernel.typeof_pyval(a) for a in args))
    if cres is not None:
        _ENTRY[kernel, variant] = cres.entry_point
    return out


def run_kernels(batch, serial, args: tuple, T: np.ndarray, parallel_min: int,
                plain: bool | None = None, variant=None) -> None:
    """Run a kernel pair on ``args`` (poses ``T (N, 4, 4)`` among them): the parallel
    ``batch`` kernel from ``parallel_min`` poses on, else the ``serial`` one, through
    :func:`call_compiled` (with ``variant``) when the poses are plain (``plain``, or
    :func:`plain_poses`)."""
    if T.shape[0] >= parallel_min:
        batch(*args)
    elif plain_poses(T) if plain is None else plain:
        call_compiled(serial, *args, variant=variant)
    else:
        serial(*args)


def plain_poses(T: np.ndarray) -> bool:
    """``T`` is a C-contiguous, aligned, writeable float64 ``(N, 4, 4)`` array: the poses
    :func:`call_compiled` may pass to a kernel (one Numba type for all of them)."""
    f = T.flags
    return f.c_contiguous and f.aligned and f.writeable and T.ndim == 3 and \
        T.dtype == np.float64


def reasons(n_solutions: np.ndarray, why_none: str) -> np.ndarray:
    """Object array: ``""`` where a pose has solutions, ``why_none`` where it has none."""
    r = np.empty(n_solutions.shape, dtype=object)
    if n_solutions.shape == (1,):  # one pose (a single call): no mask
        r[0] = why_none if n_solutions[0] == 0 else ""
        return r
    if n_solutions.size == 1:
        r.fill(why_none if n_solutions.flat[0] == 0 else "")
        return r
    r.fill("")
    r[n_solutions == 0] = why_none
    return r


def wrap_angles(q: np.ndarray, rotates: np.ndarray) -> np.ndarray:
    """Revolute values wrapped to [-π, π); prismatic ones unchanged."""
    return np.where(rotates, np.mod(q + math.pi, 2.0 * math.pi) - math.pi, q)


def check_poses(T, *, tol: float = 1e-6) -> np.ndarray:
    """Validate ``T (..., 4, 4)`` as finite rigid transforms
    (:func:`kinestat.spatial.validate.as_pose`, rotations to ``tol``, last row exact); raise
    :class:`~kinestat.errors.InputError` naming ``T_base_flange`` and the first bad pose."""
    return as_pose(T, "ik_all: T_base_flange", tol=tol)


def pose_residuals(model: ChainModel, q: np.ndarray, T: np.ndarray):
    """Position error (length unit) and rotation angle (rad) of ``fk(q)`` against ``T``."""
    F = fk(model, q)
    pos = np.linalg.norm(F[..., :3, 3] - T[..., :3, 3], axis=-1)
    d = np.linalg.norm(F[..., :3, :3] - T[..., :3, :3], axis=(-2, -1))
    rot = 2.0 * np.arcsin(np.minimum(d / (2.0 * math.sqrt(2.0)), 1.0))
    return pos, rot


def _twist_error(F: np.ndarray, T: np.ndarray) -> np.ndarray:
    """First-order spatial twist ``[ω; v_O]`` taking F to T (``T ≈ (I + [ξ]) F``)."""
    dR = T[..., :3, :3] @ np.swapaxes(F[..., :3, :3], -1, -2)
    w = 0.5 * np.stack([dR[..., 2, 1] - dR[..., 1, 2], dR[..., 0, 2] - dR[..., 2, 0],
                        dR[..., 1, 0] - dR[..., 0, 1]], axis=-1)
    p = F[..., :3, 3]
    v = T[..., :3, 3] - p - np.cross(w, p)
    return np.concatenate([w, v], axis=-1)


def newton_polish(model: ChainModel, q: np.ndarray, T: np.ndarray, iters: int = 3,
                  rcond: float | None = None) -> np.ndarray:
    """Newton steps ``J(q) δq = ξ(q)`` (Nadkarni eq. 4-11) towards the pose T, batched.

    ``q (M, n)``, ``T (M, 4, 4)``; a step is kept only where it lowers the twist error (a
    singular Jacobian leaves the row as it was). With ``rcond`` the steps are Gauss–Newton
    with the pseudo-inverse truncated at ``rcond`` (for Jacobians that are singular at the
    root).
    """
    q = q.copy()
    if q.shape[0] == 0:
        return q
    F, J = fk_and_jacobian(model, q)
    e = _twist_error(F, T)
    en = np.linalg.norm(e, axis=-1)
    for _ in range(iters):
        if rcond is not None:
            dq = np.einsum("mij,mj->mi", np.linalg.pinv(J, rcond=rcond), e)
        else:
            try:
                dq = np.linalg.solve(J, e[..., None])[..., 0]
            except np.linalg.LinAlgError:
                dq = (np.linalg.pinv(J) @ e[..., None])[..., 0]  # some Jacobian is singular
        dq = np.where(np.isfinite(dq), dq, 0.0)
        qn = q + dq
        Fn, Jn = fk_and_jacobian(model, qn)
        en_new = _twist_error(Fn, T)
        nn = np.linalg.norm(en_new, axis=-1)
        better = nn < en
        q = np.where(better[:, None], qn, q)
        J = np.where(better[:, None, None], Jn, J)
        e = np.where(better[:, None], en_new, e)
        en = np.where(better, nn, en)
    return q


def pack(model: ChainModel, q: np.ndarray, cand: np.ndarray, T: np.ndarray, K: int, *,
         tol: float, method: str, reason_none: str, singular=None, family_sign=None,
         family_value=None, family_joints=None, dedup: float = 1e-6) -> IKAllResult:
    """Verify candidates ``q (N, C, n)`` (mask ``cand``) by FK against ``T (N, 4, 4)``, drop
    duplicates and pack the valid ones first into ``K`` slots."""
    N, C, n = q.shape
    rot = ~model.prismatic
    qw = wrap_angles(np.where(cand[..., None], q, 0.0), rot)
    pos, ang = pose_residuals(model, qw, T[:, None])
    ok = cand & (pos <= tol) & (ang <= tol)
    if singular is None:
        singular = np.zeros((N, C), dtype=bool)
        family_sign = np.zeros((N, C))
        family_value = np.full((N, C), np.nan)
    # de-duplicate: a later candidate equal (mod 2π) to an earlier valid one is dropped
    diff = qw[:, :, None, :] - qw[:, None, :, :]
    diff = np.where(rot, np.mod(diff + math.pi, 2 * math.pi) - math.pi, diff)
    same = np.max(np.abs(diff), axis=-1) < dedup  # (N, C, C)
    earlier = np.tril(np.ones((C, C), dtype=bool), -1)
    for c in range(1, C):
        dup = np.any(same[:, c, :c] & ok[:, :c] & earlier[c, :c], axis=-1)
        ok[:, c] &= ~dup
    order = np.argsort(~ok, axis=1, kind="stable")[:, :K]
    take = np.take_along_axis
    okk = take(ok, order, 1)
    out_q = np.where(okk[..., None], take(qw, order[..., None], 1), np.nan)
    nsol = okk.sum(axis=1)
    if np.any(ok.sum(axis=1) > K):
        raise AssertionError(f"{method}: more than {K} distinct solutions (a solver bug)")
    reason = np.where(nsol > 0, "", reason_none).astype(object)
    return IKAllResult(
        q=out_q, valid=okk, position_error=np.where(okk, take(pos, order, 1), np.nan),
        rotation_error=np.where(okk, take(ang, order, 1), np.nan),
        singular=okk & take(singular, order, 1),
        family_sign=np.where(okk, take(family_sign, order, 1), 0.0),
        family_value=np.where(okk, take(family_value, order, 1), np.nan),
        family_joints=family_joints, n_solutions=nsol, reason=reason, method=method, tol=tol,
    )
