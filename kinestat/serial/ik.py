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

from collections.abc import Iterator
from typing import Literal

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial import _ik_kernels as _K
from kinestat.serial._kernel_cache import KernelData, kernel_data
from kinestat.serial._lm import IKResult, damped_step, wrap_joints, wrap_rotating
from kinestat.serial._lm_constants import TARGET_LAST_ROW_TOL, TARGET_ORTHO_TOL
from kinestat.serial._reference import ik_reference
from kinestat.serial.chunks import CHUNK_ROWS, chunk_slices
from kinestat.serial.lengths import characteristic_length
from kinestat.spatial.se3 import pose_error, so3_log
from kinestat.spatial.validate import as_number, as_pose

__all__ = [
    "IKResult",
    "ik",
    "iter_ik",
    "inverse_analysis",
    "BACKENDS",
    "Backend",
    "pose_error",
    "rotation_log",
    "model_scale",
    "wrap_joints",
    "wrap_rotating",
    "damped_step",
]


#: default number of random restarts after a stalled attempt. 100 (was 20): on 10^4 random
#: reachable targets per arm the success rate with 20 was 99.34-100 % (PUMA 560 99.80 %, PUMA 762
#: 99.72 %, Panda 99.50 %, SO-100 99.34 %), with 100 it is 99.95-100 % (docs/ik.md); restarts
#: run only after a stall, so a reachable target costs the same, an unreachable one ~5x more.
DEFAULT_RESTARTS = 100

#: the SO(3) logarithm, :func:`kinestat.spatial.se3.so3_log` (old name)
rotation_log = so3_log


def model_scale(model: ChainModel) -> float:
    """The model's size, :func:`kinestat.serial.lengths.characteristic_length` without ``q``
    (the sum of its constant translations plus the finite prismatic ranges; 1 if that is zero).
    Used to weigh length errors against angles and to scale the default position tolerance.

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> model_scale(from_standard_dh([[0.0, 2.0, 3.0, 0.0]]))  # |(3, 0, 2)| at C1, C0 = I
    3.605551275463989
    """
    return characteristic_length(model)


def _check_poses(poses) -> np.ndarray:
    """Target poses ``(..., 4, 4)`` checked (:func:`kinestat.spatial.validate.as_pose`) and
    projected onto the nearest rotation (polar decomposition): rounded input (e.g. typed with 6
    digits) is accepted, and the 1e-9 rad tolerance stays attainable."""
    T = as_pose(poses, "target poses", tol=TARGET_ORTHO_TOL, last_row_tol=TARGET_LAST_ROW_TOL)
    T = T.copy()
    R = T[..., :3, :3]
    if R.size:
        U, _, Vt = np.linalg.svd(R)
        T[..., :3, :3] = U @ Vt
    return T


Backend = Literal["numba", "numpy"]

BACKENDS: tuple[Backend, ...] = ("numba", "numpy")
"""Values of :func:`ik`'s deprecated ``backend`` switch: ``"numba"`` (the compiled kernels, always
used by default) and ``"numpy"`` (the private NumPy reference in :mod:`kinestat.serial._reference`,
kept for the tests)."""

_PARALLEL_MIN = 8  # fewer targets run on one thread (starting the workers costs more)


def _model_data(model: ChainModel) -> KernelData:
    """The model's kernel data with its characteristic length filled in."""
    d = kernel_data(model)
    if d.scale is None:
        d.scale = characteristic_length(model)
    return d


def _poses_compiled(poses) -> np.ndarray:
    """:func:`_check_poses`' checks by the compiled validator; the poses as ``(*B, 4, 4)``
    (the projection onto the nearest rotation happens per target inside the solver). On a bad
    pose the NumPy validator runs to word the error (one message for both paths)."""
    try:
        T = np.asarray(poses, dtype=float)
    except (TypeError, ValueError):
        T = None
    if (T is None or T.ndim < 2 or T.shape[-2:] != (4, 4)
            or _K.validate_poses(np.ascontiguousarray(T.reshape(-1, 4, 4)))[0] != _K.POSE_OK):
        as_pose(poses, "target poses", tol=TARGET_ORTHO_TOL, last_row_tol=TARGET_LAST_ROW_TOL)
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


#: Ceilings of one IK call's effort (docs/reliability.md, "Limits and ceilings"): an attempt that
#: has not converged in 10^5 Levenberg–Marquardt iterations will not (it converges in tens), and
#: 10^4 random restarts is far past the point where another start finds a new solution.
MAX_ITER = 100_000
MAX_RESTARTS = 10_000


def _check_effort(max_iter, restarts) -> None:
    """``max_iter`` in 1..MAX_ITER and ``restarts`` in 0..MAX_RESTARTS, whole numbers."""
    for name, v, lo, hi in (("max_iter", max_iter, 1, MAX_ITER),
                            ("restarts", restarts, 0, MAX_RESTARTS)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi:
            shown = repr(v) if len(repr(v)) <= 40 else f"an integer of {len(str(v))} digits"
            raise InputError(f"{name} must be a whole number from {lo} to {hi}, got {shown}")


def ik(
    model: ChainModel,
    poses,
    q0=None,
    *,
    pos_tol: float | None = None,
    rot_tol: float = 1e-9,
    max_iter: int = 100,
    restarts: int = DEFAULT_RESTARTS,
    seed: int | None = 0,
    respect_limits: bool = True,
    backend: Backend = "numba",
) -> IKResult:
    """Inverse kinematics of ``model`` for target end poses ``T_base_end (*B, 4, 4)`` (or one
    ``(4, 4)``); the theses' "reverse analysis" (:func:`inverse_analysis` is an alias).

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> from kinestat.serial.fk import fk
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]])  # planar RR
    >>> r = ik(arm, fk(arm, [0.3, 0.4]), q0=[0.2, 0.5])
    >>> bool(r.success), np.round(r.q, 9)
    (True, array([0.3, 0.4]))

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
        backend: deprecated, for the tests: ``"numba"`` (the default and the only public path:
            compiled, each target iterates on its own, all in parallel, and draws its restarts
            from a random stream keyed by ``seed`` and its index) or ``"numpy"`` (the private
            NumPy reference, :func:`kinestat.serial._reference.ik_reference`, one shared random
            generator). The same algorithm; answers can differ only where restarts were needed.

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
    _check_effort(max_iter, restarts)
    d = _model_data(model)
    L = d.scale
    pos_tol = 1e-9 * L if pos_tol is None else as_number(pos_tol, "pos_tol", positive=True)
    rot_tol = as_number(rot_tol, "rot_tol", positive=True)
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
        return ik_reference(model, Tt, qs, shape, L, pos_tol, rot_tol, max_iter, restarts, seed,
                            respect_limits)
    Q0 = np.ascontiguousarray(q0[None] if q0.ndim == 1 else qs.reshape(-1, n))
    Tf = np.ascontiguousarray(Tt.reshape(-1, 4, 4))
    return _ik_compiled(model, Tf, Q0, shape, L, d.lower, d.upper, float(pos_tol), float(rot_tol),
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
    C, kinds, pitch = kernel_data(model).args
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

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> from kinestat.serial.fk import fk
    >>> arm = from_standard_dh([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    >>> T = fk(arm, np.array([[0.3, 0.4], [0.5, 0.6], [0.7, 0.8]]))
    >>> parts = iter_ik(arm, T, [0.4, 0.5], chunk_rows=2)
    >>> [(rows.start, bool(r.success.all())) for rows, r in parts]
    [(0, True), (2, True)]
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
    for rows in chunk_slices(N, chunk_rows):
        start = rows.start
        q0c = q0a if q0a is None or q0a.ndim == 1 else q0a[rows]
        if backend == "numba":
            yield rows, _ik_chunk(model, Tf[rows], q0c, key, start, **options)
        else:
            yield rows, ik(model, Tf[rows], q0c, seed=seed, **options)


def _ik_chunk(model: ChainModel, T: np.ndarray, q0, key: np.uint64, offset: int, *,
              pos_tol: float | None = None, rot_tol: float = 1e-9, max_iter: int = 100,
              restarts: int = DEFAULT_RESTARTS, respect_limits: bool = True,
              backend: str = "numba") -> IKResult:
    """One chunk of :func:`iter_ik` (compiled path, random streams offset by ``offset``)."""
    Tt = _poses_compiled(T)
    _check_effort(max_iter, restarts)
    d = _model_data(model)
    L, lo, hi = d.scale, d.lower, d.upper
    pos_tol = 1e-9 * L if pos_tol is None else as_number(pos_tol, "pos_tol", positive=True)
    rot_tol = as_number(rot_tol, "rot_tol", positive=True)
    q0 = model.check_q(model.q_home if q0 is None else q0, "q0")
    Q0 = np.ascontiguousarray(q0[None] if q0.ndim == 1 else q0)
    return _ik_compiled(model, np.ascontiguousarray(Tt), Q0, Tt.shape[:-2], L, lo, hi,
                        float(pos_tol), float(rot_tol), int(max_iter), int(restarts), key,
                        bool(respect_limits), offset)


#: the theses' name for :func:`ik`
inverse_analysis = ik
