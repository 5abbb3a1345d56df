"""Numerical inverse kinematics for any serial chain: batched Levenberg–Marquardt on SE(3).

For a target pose ``T_t = (R_t, p_t)`` and the current end pose ``T(q) = (R, p)`` the error is the
twist that carries one onto the other to first order, in the base frame::

    e = [ω; δp],   ω = log(R_t Rᵀ)^∨ (axis-angle),   δp = p_t − p

and the Jacobian of ``[ω; ṗ]`` is the space Jacobian ``[J_ω; J_v]`` (twists ``[ω; v_O]``,
:mod:`kinestat.serial.jacobian`) with its velocity rows moved from the origin to the end point,
``ṗ = v_O + ω × p``. Each step solves the damped normal equations
``(JᵀJ + μ s I) δq = Jᵀ e`` (Levenberg 1944, Marquardt 1963; "damped least squares", Wampler
1986) with lengths scaled by the model's size so that millimetres and radians weigh alike; μ
shrinks after a step that lowers the error and grows after one that does not. Joint limits are
enforced by projection after each step (a revolute or screw joint is first shifted by whole
turns into its limits; a prismatic joint is only clipped). A start that stalls — the error stops
falling, or the iteration budget of one attempt is spent — is restarted from a random
configuration within the limits.

By default each target iterates in compiled code (:mod:`kinestat.serial._ik_kernels`), all
targets in parallel; ``backend="numpy"`` runs the plain array reference, where all targets
iterate together (vectorised over the batch; converged ones drop out). Success is decided from
the final forward kinematics only: the position error is at most ``pos_tol``, the rotation
error at most ``rot_tol`` and the configuration is within the limits. There are no false
successes.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial import _ik_kernels as _K
from kinestat.serial.fk import CHUNK_ROWS, fk, fk_frames
from kinestat.serial.jacobian import jacobian_from_frames

__all__ = [
    "IKResult",
    "ik",
    "iter_ik",
    "BACKENDS",
    "pose_error",
    "rotation_log",
    "model_scale",
    "wrap_joints",
    "wrap_rotating",
    "damped_step",
]


def pose_error(T, T_target) -> tuple[np.ndarray, np.ndarray]:
    """Position distance and rotation angle between poses ``(..., 4, 4)``.

    The angle is ``2 asin(|R − R_t|_F / (2√2))``: exact, and accurate at small angles
    (``|R − R_t|_F² = 8 sin²(θ/2)``).
    """
    T = np.asarray(T, dtype=float)
    Tt = np.asarray(T_target, dtype=float)
    pos = np.linalg.norm(T[..., :3, 3] - Tt[..., :3, 3], axis=-1)
    d = np.sqrt(np.sum((T[..., :3, :3] - Tt[..., :3, :3]) ** 2, axis=(-1, -2)))
    rot = 2.0 * np.arcsin(np.minimum(d / (2.0 * math.sqrt(2.0)), 1.0))
    return pos, rot


def rotation_log(R) -> np.ndarray:
    """Rotation vectors ``(..., 3)`` (axis × angle, angle in [0, π]) of rotations ``(..., 3, 3)``.

    The SO(3) logarithm, via SciPy's ``Rotation.as_rotvec``.
    """
    R = np.asarray(R, dtype=float)
    flat = R.reshape(-1, 3, 3)
    if flat.shape[0] == 0:
        return np.zeros(R.shape[:-2] + (3,))
    return Rotation.from_matrix(flat).as_rotvec().reshape(R.shape[:-2] + (3,))


def model_scale(model: ChainModel) -> float:
    """A characteristic length of the model: the sum of its constant translations, plus the
    finite ranges of its prismatic joints (1 if that is zero). Used to weigh length errors
    against angles and to scale the default position tolerance."""
    L = float(np.sum(np.linalg.norm(model.constants[:, :3, 3], axis=-1)))
    for j in model.joints:
        if j.kind == "prismatic" and math.isfinite(j.lower) and math.isfinite(j.upper):
            L += j.upper - j.lower
    return L if L > 0.0 else 1.0


def wrap_joints(model: ChainModel, q, reference=None) -> np.ndarray:
    """Shift rotating joints by whole turns: into their limits when possible (nearest
    ``reference``, default 0), else to [-π, π) about the reference. Prismatic joints are only
    clipped to their limits; rotating joints that cannot be shifted into their limits are
    clipped too."""
    q = np.asarray(q, dtype=float)
    rot = ~model.prismatic
    lo, hi = model.lower, model.upper
    ref = np.zeros_like(q) if reference is None else np.broadcast_to(reference, q.shape)
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
    q = np.asarray(q, dtype=float)
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


def _check_poses(poses) -> np.ndarray:
    T = np.asarray(poses, dtype=float)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(f"target poses must have shape (..., 4, 4), got {T.shape}")
    if not np.all(np.isfinite(T)):
        raise InputError("target poses contain NaN or infinity")
    R = T[..., :3, :3]
    ortho = np.max(np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)), axis=(-1, -2), initial=0.0)
    det = np.linalg.det(R) if R.size else np.ones(R.shape[:-2])
    bad = (ortho > 1e-6) | (np.abs(det - 1.0) > 1e-6)
    if np.any(bad):
        idx = np.argwhere(bad)[0]
        where = f" (pose {tuple(int(i) for i in idx)})" if bad.ndim else ""
        raise InputError(
            f"target pose{where} is not a rigid transform: its rotation part is not orthonormal "
            "with determinant +1"
        )
    if np.any(np.abs(T[..., 3, :] - np.array([0.0, 0.0, 0.0, 1.0])) > 1e-12):
        raise InputError("target poses must have last row [0, 0, 0, 1]")
    # rounded input (e.g. typed with 6 digits) is accepted and projected onto the nearest
    # rotation (polar decomposition), so that the 1e-9 rad tolerance is attainable
    T = T.copy()
    if R.size:
        U, _, Vt = np.linalg.svd(R)
        T[..., :3, :3] = U @ Vt
    return T


_CHECK = 10  # iterations between progress checks


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
    w = rotation_log(Tt[..., :3, :3] @ np.swapaxes(T[..., :3, :3], -1, -2))
    dp = Tt[..., :3, 3] - T[..., :3, 3]
    e = np.concatenate([w, dp / L], axis=-1)
    return F, e, np.sum(e * e, axis=-1)


def damped_step(model: ChainModel, frames: np.ndarray, e: np.ndarray, mu: np.ndarray,
                L: float) -> np.ndarray:
    """One Levenberg–Marquardt step ``δq (k, n)`` for the scaled errors ``e = [ω; δp/L]``.

    ``(JᵀJ + μ s I) δx = Jᵀ e`` with ``J = [J_ω; (J_v − p × J_ω)/L] · D`` (the space Jacobian's
    velocity rows moved to the end point p, lengths over L, prismatic columns scaled by
    ``D = L``), ``s = trace(JᵀJ)/n``, and ``δq = D δx``.
    """
    n = model.n
    D = np.where(model.prismatic, L, 1.0)
    J = jacobian_from_frames(model, frames)
    p = frames[..., -1, :3, 3]
    Jw = J[..., :3, :]
    Jv = J[..., 3:, :] - np.cross(p[..., None, :], np.swapaxes(Jw, -1, -2)).swapaxes(-1, -2)
    Js = np.concatenate([Jw, Jv / L], axis=-2) * D
    JtJ = np.swapaxes(Js, -1, -2) @ Js
    g = np.einsum("...ji,...j->...i", Js, e)
    s = np.maximum(np.trace(JtJ, axis1=-2, axis2=-1) / n, 1e-12)
    A = JtJ + (mu * s)[..., None, None] * np.eye(n)
    return np.linalg.solve(A, g[..., None])[..., 0] * D


BACKENDS = ("numba", "numpy")
"""Implementations of :func:`ik`: ``"numba"`` (compiled, every target in parallel,
:mod:`kinestat.serial._ik_kernels`; the default) and ``"numpy"`` (the plain array reference,
all targets iterating together)."""

_PARALLEL_MIN = 8  # fewer targets run on one thread (starting the workers costs more)

# per-model constants of the compiled path: (L, lower, upper), computed once per model
_MODEL_ARGS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _model_args(model: ChainModel) -> tuple[float, np.ndarray, np.ndarray]:
    args = _MODEL_ARGS.get(model)
    if args is None:
        args = (model_scale(model), np.ascontiguousarray(model.lower, dtype=float),
                np.ascontiguousarray(model.upper, dtype=float))
        _MODEL_ARGS[model] = args
    return args


def _poses_compiled(poses) -> np.ndarray:
    """:func:`_check_poses`' checks by the compiled validator; the poses as ``(*B, 4, 4)``
    (the projection onto the nearest rotation happens per target inside the solver)."""
    try:
        T = np.asarray(poses, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"target poses must be numbers of shape (..., 4, 4): {exc}") from exc
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(f"target poses must have shape (..., 4, 4), got {T.shape}")
    code, k = _K.validate_poses(np.ascontiguousarray(T.reshape(-1, 4, 4)))
    if code == _K.POSE_NONFINITE:
        raise InputError("target poses contain NaN or infinity")
    if code == _K.POSE_NOT_RIGID:
        shape = T.shape[:-2]
        where = f" (pose {tuple(int(i) for i in np.unravel_index(k, shape))})" if shape else ""
        raise InputError(
            f"target pose{where} is not a rigid transform: its rotation part is not orthonormal "
            "with determinant +1"
        )
    if code == _K.POSE_LAST_ROW:
        raise InputError("target poses must have last row [0, 0, 0, 1]")
    return T


def _seed_key(seed) -> np.uint64:
    """The 64-bit key of the compiled path's random streams."""
    if seed is None:
        return np.uint64(np.random.SeedSequence().entropy % (1 << 64))
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        if seed < 0:
            raise InputError(f"seed must be a non-negative integer or None, got {seed}")
        return np.uint64(int(seed) % (1 << 64))
    try:
        return np.random.default_rng(seed).integers(0, 1 << 64, dtype=np.uint64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"seed must be a non-negative integer or None, got {seed!r}") from exc


def ik(
    model: ChainModel,
    poses,
    q0=None,
    *,
    pos_tol: float | None = None,
    rot_tol: float = 1e-9,
    max_iter: int = 100,
    restarts: int = 20,
    seed: int | None = 0,
    respect_limits: bool = True,
    backend: str = "numba",
) -> IKResult:
    """Inverse kinematics of ``model`` for target end poses ``(*B, 4, 4)`` (or one ``(4, 4)``).

    Args:
        model: any :class:`~kinestat.mechanism.chain.ChainModel` (``kinestat.load(...)``).
        poses: target poses of the end frame, in the model's base frame and length unit. A
            rotation part orthonormal to within 1e-6 is accepted and replaced by the nearest
            rotation.
        q0: start configuration ``(n,)`` or ``(*B, n)``; default the model's ``q_home``.
        pos_tol: position tolerance in the model's length unit; default ``1e-9 ×``
            :func:`model_scale` (about 1.6e-6 mm for the PUMA 762).
        rot_tol: rotation tolerance (radians).
        max_iter: iterations per attempt.
        restarts: extra attempts from random configurations after the first one stalls.
        seed: seed of the random restarts (deterministic by default).
        respect_limits: keep every iterate within the joint limits (and judge success with
            them); False ignores the limits.
        backend: ``"numba"`` (compiled; each target iterates on its own, all in parallel, and
            draws its restarts from a random stream keyed by ``seed`` and its index) or
            ``"numpy"`` (the plain array reference, one shared random generator). The same
            algorithm; answers can differ only where restarts were needed.

    Returns an :class:`IKResult`. The compiled path needs no memory beyond its inputs and
    outputs; :func:`iter_ik` streams the results of very large batches chunk by chunk.
    """
    if not isinstance(model, ChainModel):
        raise InputError(f"model must be a ChainModel (use kinestat.load), got {type(model)!r}")
    if backend not in BACKENDS:
        raise InputError(f"backend must be one of {BACKENDS}, got {backend!r}")
    Tt = _check_poses(poses) if backend == "numpy" else _poses_compiled(poses)
    shape = Tt.shape[:-2]
    n = model.n
    if max_iter < 1 or restarts < 0:
        raise InputError("max_iter must be at least 1 and restarts non-negative")
    if backend == "numpy":
        L = model_scale(model)
    else:
        L, lo, hi = _model_args(model)
    if pos_tol is None:
        pos_tol = 1e-9 * L
    if not (pos_tol > 0 and rot_tol > 0):
        raise InputError("pos_tol and rot_tol must be positive")
    if q0 is None:
        q0 = model.q_home
    q0 = model.check_q(q0, "q0")
    try:
        qs = np.broadcast_to(q0, shape + (n,))
    except ValueError as exc:
        raise InputError(
            f"q0 of shape {q0.shape} does not match {int(np.prod(shape))} poses of shape {shape}"
        ) from exc
    if backend == "numpy":
        return _ik_numpy(model, Tt, qs, shape, L, pos_tol, rot_tol, max_iter, restarts, seed,
                         respect_limits)
    Q0 = np.ascontiguousarray(q0[None] if q0.ndim == 1 else qs.reshape(-1, n))
    Tf = np.ascontiguousarray(Tt.reshape(-1, 4, 4))
    return _ik_compiled(model, Tf, Q0, shape, L, lo, hi, float(pos_tol), float(rot_tol),
                        int(max_iter), int(restarts), _seed_key(seed), bool(respect_limits), 0)


def _ik_compiled(model: ChainModel, Tf: np.ndarray, Q0: np.ndarray, shape: tuple, L: float,
                 lo: np.ndarray, hi: np.ndarray, pos_tol: float, rot_tol: float, max_iter: int,
                 restarts: int, key: np.uint64, limits: bool, offset: int) -> IKResult:
    N = Tf.shape[0]
    n = model.n
    q = np.empty((N, n))
    ok = np.empty(N, dtype=bool)
    pos = np.empty(N)
    rot = np.empty(N)
    its = np.empty(N, dtype=np.int64)
    att = np.empty(N, dtype=np.int64)
    C, kinds, pitch = model.kernel_args  # type: ignore[attr-defined]
    kernel = _K.ik_batch if N >= _PARALLEL_MIN else _K.ik_serial
    kernel(C, kinds, pitch, lo, hi, Q0, Tf, L, pos_tol, rot_tol, max_iter, restarts, limits,
           key, offset, q, ok, pos, rot, its, att)
    return IKResult(q=q.reshape(shape + (n,)), success=ok.reshape(shape),
                    position_error=pos.reshape(shape), rotation_error=rot.reshape(shape),
                    iterations=its.reshape(shape), attempts=att.reshape(shape))


def iter_ik(model: ChainModel, poses, q0=None, *, chunk_rows: int = CHUNK_ROWS,
            **options) -> Iterator[tuple[slice, IKResult]]:
    """Stream :func:`ik` over a large batch of targets ``(N, 4, 4)`` chunk by chunk: yields
    ``(rows, result)`` so that 10^7 targets need only one chunk of results at a time.

    ``q0`` is ``(n,)`` or ``(N, n)``; ``options`` are :func:`ik`'s keywords. With the compiled
    backend each target keeps its own random stream, so the chunks give exactly the answers of
    one call on the whole batch.
    """
    if chunk_rows < 1:
        raise InputError(f"chunk_rows must be at least 1, got {chunk_rows}")
    if not isinstance(model, ChainModel):
        raise InputError(f"model must be a ChainModel (use kinestat.load), got {type(model)!r}")
    T = np.asarray(poses, dtype=float)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(f"target poses must have shape (..., 4, 4), got {T.shape}")
    Tf = T.reshape(-1, 4, 4)
    N = Tf.shape[0]
    q0a = None if q0 is None else model.check_q(q0, "q0")
    if q0a is not None and q0a.ndim > 1:
        try:
            q0a = np.broadcast_to(q0a, T.shape[:-2] + (model.n,)).reshape(-1, model.n)
        except ValueError as exc:
            raise InputError(f"q0 of shape {q0a.shape} does not match {N} poses of shape "
                             f"{T.shape[:-2]}") from exc
    backend = options.get("backend", "numba")
    seed = options.pop("seed", 0)
    key = _seed_key(seed) if backend == "numba" else None
    for start in range(0, N, chunk_rows):
        rows = slice(start, min(start + chunk_rows, N))
        q0c = q0a if q0a is None or q0a.ndim == 1 else q0a[rows]
        if backend == "numba":
            yield rows, _ik_chunk(model, Tf[rows], q0c, key, start, **options)
        else:
            yield rows, ik(model, Tf[rows], q0c, seed=seed, **options)


def _ik_chunk(model: ChainModel, T: np.ndarray, q0, key: np.uint64, offset: int, *,
              pos_tol: float | None = None, rot_tol: float = 1e-9, max_iter: int = 100,
              restarts: int = 20, respect_limits: bool = True,
              backend: str = "numba") -> IKResult:
    """One chunk of :func:`iter_ik` (compiled path, random streams offset by ``offset``)."""
    Tt = _poses_compiled(T)
    if max_iter < 1 or restarts < 0:
        raise InputError("max_iter must be at least 1 and restarts non-negative")
    L, lo, hi = _model_args(model)
    if pos_tol is None:
        pos_tol = 1e-9 * L
    if not (pos_tol > 0 and rot_tol > 0):
        raise InputError("pos_tol and rot_tol must be positive")
    q0 = model.check_q(model.q_home if q0 is None else q0, "q0")
    Q0 = np.ascontiguousarray(q0[None] if q0.ndim == 1 else q0)
    return _ik_compiled(model, np.ascontiguousarray(Tt), Q0, Tt.shape[:-2], L, lo, hi,
                        float(pos_tol), float(rot_tol), int(max_iter), int(restarts), key,
                        bool(respect_limits), offset)


def _ik_numpy(model: ChainModel, Tt: np.ndarray, qs: np.ndarray, shape: tuple, L: float,
              pos_tol: float, rot_tol: float, max_iter: int, restarts: int, seed,
              respect_limits: bool) -> IKResult:
    """The plain NumPy reference: all targets iterate together, in chunks of
    :data:`~kinestat.serial.fk.CHUNK_ROWS` targets (bounded temporaries)."""
    n = model.n
    qs = qs.reshape(-1, n).astype(float)
    Tt = Tt.reshape(-1, 4, 4)
    N = Tt.shape[0]
    rng = np.random.default_rng(seed)
    parts = [_lm_numpy(model, Tt[s:s + CHUNK_ROWS], qs[s:s + CHUNK_ROWS], L, pos_tol, rot_tol,
                       max_iter, restarts, rng, respect_limits)
             for s in range(0, max(N, 1), CHUNK_ROWS)]
    q_out, ok, pos, rot, it_total, attempts = (np.concatenate(a) for a in zip(*parts,
                                                                               strict=True))
    return IKResult(
        q=q_out.reshape(shape + (n,)),
        success=ok.reshape(shape),
        position_error=pos.reshape(shape),
        rotation_error=rot.reshape(shape),
        iterations=it_total.reshape(shape),
        attempts=attempts.reshape(shape),
    )


def _lm_numpy(model: ChainModel, Tt: np.ndarray, qs: np.ndarray, L: float, pos_tol: float,
              rot_tol: float, max_iter: int, restarts: int, rng: np.random.Generator,
              respect_limits: bool):
    """Levenberg–Marquardt with restarts, vectorised over the targets ``Tt (N, 4, 4)``."""
    N = Tt.shape[0]
    if respect_limits:
        project = lambda q, ref: wrap_joints(model, q, ref)  # noqa: E731
    else:
        project = lambda q, ref: q  # noqa: E731

    q = project(qs.copy(), qs)
    mu = np.full(N, 1e-3)
    it_total = np.zeros(N, dtype=int)
    it_attempt = np.zeros(N, dtype=int)
    attempts = np.ones(N, dtype=int)
    best_q = q.copy()
    best_cost = np.full(N, np.inf)
    checkpoint = np.full(N, np.inf)
    pos_tol_s = pos_tol / L

    def keep_best(ids, qv, cv):
        better = cv < best_cost[ids]
        best_cost[ids] = np.where(better, cv, best_cost[ids])
        best_q[ids] = np.where(better[:, None], qv, best_q[ids])

    idx = np.arange(N)
    F, e, cost = _errors(model, q, Tt, L)
    keep_best(idx, q, cost)
    while idx.size:
        qa = q[idx]
        # convergence: within half the tolerances (the final verdict is taken again from the
        # forward kinematics), polished until 1000 times smaller or no step improves any more
        pe = np.linalg.norm(e[:, 3:], axis=-1)
        re = np.linalg.norm(e[:, :3], axis=-1)
        within = (pe <= 0.5 * pos_tol_s) & (re <= 0.5 * rot_tol)
        done = (pe <= 1e-3 * pos_tol_s) & (re <= 1e-3 * rot_tol)
        q_new = project(qa + damped_step(model, F, e, mu[idx], L), qa)
        F_new, e_new, cost_new = _errors(model, q_new, Tt[idx], L)
        accept = (cost_new < cost) & ~done
        mu[idx] = np.where(accept, np.maximum(mu[idx] / 3.0, 1e-12), mu[idx] * 8.0)
        q[idx] = np.where(accept[:, None], q_new, qa)
        F = np.where(accept[:, None, None, None], F_new, F)
        e = np.where(accept[:, None], e_new, e)
        cost = np.where(accept, cost_new, cost)
        keep_best(idx, q[idx], cost)
        it_total[idx] += ~done
        it_attempt[idx] += ~done
        # stalled: damping exploded (no descent), the error did not halve over the last
        # ``_CHECK`` iterations (stuck against a limit or in a local minimum), or the attempt's
        # budget is spent
        check = (it_attempt[idx] % _CHECK == 0) & ~done
        slow = check & (cost > 0.9 * checkpoint[idx])
        checkpoint[idx] = np.where(check, cost, checkpoint[idx])
        stalled = ~done & ~within & ((mu[idx] > 1e10) | slow | (it_attempt[idx] >= max_iter))
        restart = stalled & (attempts[idx] <= restarts)
        done |= within & (~accept | (it_attempt[idx] >= max_iter))
        finished = done | (stalled & ~restart)
        if np.any(restart):
            r = idx[restart]
            q[r] = project(_random_q(model, rng, r.size, L), qs[r])
            mu[r] = 1e-3
            checkpoint[r] = np.inf
            it_attempt[r] = 0
            attempts[r] += 1
            Fr, er, cr = _errors(model, q[r], Tt[r], L)
            F[restart], e[restart], cost[restart] = Fr, er, cr
            keep_best(r, q[r], cr)
        keep = ~finished
        idx = idx[keep]
        F, e, cost = F[keep], e[keep], cost[keep]

    # the answer: the best iterate of each target, judged by its own forward kinematics
    q_out = best_q if respect_limits else wrap_rotating(model, best_q)
    pos, rot = pose_error(fk(model, q_out), Tt)
    ok = (pos <= pos_tol) & (rot <= rot_tol)
    if respect_limits:
        ok &= model.within_limits(q_out)
    return q_out, ok, pos, rot, it_total, attempts
