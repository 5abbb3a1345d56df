"""PUMA 762 reverse analysis (Vibhute §2.2.3; Crane & Duffy ch. 10): closing the loop with the
hypothetical seventh link, all eight branches of a batch of poses, and the distinct solutions and
wrist-singular families of one pose. The theses' "reverse analysis" is kinestat's ik; the public
functions always run the compiled kernels (:mod:`kinestat.robots.puma762._kernels`)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Literal

import numpy as np

from kinestat.errors import InputError, UnreachableError
from kinestat.robots.puma762 import _kernels as _pk
from kinestat.robots.puma762._reference import reverse_numpy
from kinestat.robots.puma762.forward import _frame6_message, frame6, wrist_center
from kinestat.robots.puma762.params import (
    A23,
    N_BRANCHES,
    S2,
    S4,
    STATUS_INSIDE_CYLINDER,
    STATUS_OK,
    STATUS_TOO_FAR,
    STATUS_TOO_NEAR,
    _wrap,
)
from kinestat.serial.chunks import CHUNK_ROWS, chunk_slices

__all__ = [
    "ClosedLoop",
    "close_loop",
    "ReverseBatch",
    "reverse_batch",
    "WristFamily",
    "ReverseResult",
    "reverse",
    "reverse_pose",
    "reverse_batch_pose",
    "iter_reverse_batch_pose",
    "BACKENDS",
    "Backend",
    "CHUNK_ROWS",
    "status_message",
]

Backend = Literal["numba", "numpy"]

BACKENDS: tuple[Backend, ...] = ("numba", "numpy")
"""Values of the deprecated ``backend`` switch (for the tests): ``"numba"`` (the compiled
kernels, always the default) and ``"numpy"`` (the private NumPy reference,
:mod:`kinestat.robots.puma762._reference`)."""

_PARALLEL_MIN = 64  # smaller batches run on one thread (starting the workers costs more)


# -- closing the loop (Vibhute eqs. 2-35..2-43) ---------------------------------------------------
@dataclass(frozen=True, eq=False)
class ClosedLoop:
    """Parameters of the hypothetical seventh link (Crane & Duffy ch. 10; Vibhute eqs. 2-35..43).

    All batched like the input. Angles in radians, lengths in mm.

    Attributes:
        s7: unit vector S7_F = a67_F × S6_F (α67 = 90°).
        a71: unit vector a71_F, the common normal of S7 and S1.
        alpha71: twist angle α71 (from S7 to S1 about a71), in [0, π].
        theta7: joint angle θ7 (from a67 to a71 about S7).
        gamma1: angle from a71 to the fixed x axis about S1 (eqs. 2-39, 2-40), so φ1 = θ1 − γ1.
        S7, a71_len, S1: the offsets S7, the link length a71 and the offset S1 (eqs. 2-41..2-43).

    >>> c = close_loop([650.0, -190.0, 475.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0])
    >>> c.s7 + 0.0, round(float(np.degrees(c.alpha71)), 9)
    (array([0., 1., 0.]), 90.0)
    """

    s7: np.ndarray
    a71: np.ndarray
    alpha71: np.ndarray
    theta7: np.ndarray
    gamma1: np.ndarray
    S7: np.ndarray
    a71_len: np.ndarray
    S1: np.ndarray


def close_loop(tool_point, s6, a67, tool_point_6=(0.0, 0.0, 0.0), *,
               tol: float = 1e-6) -> ClosedLoop:
    """Close the loop with the hypothetical seventh link (Vibhute eqs. 2-35..2-43).

    ``S7 = a67 × S6``; ``c71 = S7·S1`` (2-35); ``a71 = S7 × S1 / s71`` (2-36); ``c7 = a67·a71``,
    ``s7 = (a67 × a71)·S7`` (2-37, 2-38); ``cγ1 = a71·i``, ``sγ1 = (a71 × i)·S1`` (2-39, 2-40);
    ``S7 = (S1 × P6)·a71 / s71``, ``a71 = (P6 × S1)·S7 / s71``, ``S1 = (P6 × S7)·a71 / s71``
    (2-41..2-43, P6 the origin of frame 6) — signs restored, see docs/seed-errata.md.
    When S7 is parallel to S1 (s71 = 0) the common normal is not unique: a71 is taken along the
    perpendicular from S7 to S1 (or along a67 if the lines coincide) and S7 = 0.

    >>> c = close_loop([650.0, -190.0, 475.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0])
    >>> c.a71 + 0.0
    array([1., 0., 0.])
    """
    T = frame6(tool_point, s6, a67, tool_point_6, tol=tol)
    x6, z6, p6 = T[..., :3, 0], T[..., :3, 2], T[..., :3, 3]
    s7v = np.cross(x6, z6)
    k = np.array([0.0, 0.0, 1.0])
    i = np.array([1.0, 0.0, 0.0])
    c71 = s7v[..., 2]
    n = np.cross(s7v, k)
    s71 = np.linalg.norm(n, axis=-1)
    parallel = s71 < 1e-12
    safe = np.where(parallel, 1.0, s71)
    a71v = n / safe[..., None]
    # parallel case: a71 from the S7 line towards the S1 axis
    perp = p6 - p6[..., 2:3] * k
    nperp = np.linalg.norm(perp, axis=-1)
    has_perp = nperp > 1e-12
    alt = np.where(has_perp[..., None], -perp / np.where(has_perp, nperp, 1.0)[..., None], x6)
    a71v = np.where(parallel[..., None], alt, a71v)
    alpha71 = np.arctan2(s71, c71)
    c7 = np.sum(x6 * a71v, axis=-1)
    s7 = np.sum(np.cross(x6, a71v) * s7v, axis=-1)
    theta7 = np.arctan2(s7, c7)
    cg = a71v[..., 0]
    sg = np.sum(np.cross(a71v, i) * k, axis=-1)
    gamma1 = np.arctan2(sg, cg)
    S7 = np.where(parallel, 0.0, np.sum(np.cross(k, p6) * a71v, axis=-1) / safe)
    a71_len = np.where(parallel, nperp, np.sum(np.cross(p6, k) * s7v, axis=-1) / safe)
    S1 = np.where(parallel, -p6[..., 2], np.sum(np.cross(p6, s7v) * a71v, axis=-1) / safe)
    return ClosedLoop(s7=s7v, a71=a71v, alpha71=alpha71, theta7=theta7, gamma1=gamma1, S7=S7,
                      a71_len=a71_len, S1=S1)


# -- reverse analysis, batched kernel -------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class ReverseBatch:
    """All eight branches of the reverse analysis for a batch of poses ``B`` (any shape).

    Attributes:
        q: ``(*B, 8, 6)`` joint angles (radians, each in [-π, π)); branch ``4·i1 + 2·i3 + i5``.
            Meaningless where ``valid`` is False (filled with NaN).
        valid: ``(*B, 8)`` the branch exists (and, when verified, reproduces the pose).
        singular: ``(*B, 8)`` the branch is at a wrist singularity (|sin θ5| < ``s5_tol``):
            θ4 and θ6 are a one-parameter family; ``q`` holds one representative member.
        family_sum: ``(*B, 8)`` True where the family keeps θ4 + θ6 fixed (θ5 = 180°), False
            where it keeps θ6 − θ4 fixed (θ5 = 0°); only meaningful where ``singular``.
        family_value: ``(*B, 8)`` the fixed θ4 + θ6 or θ6 − θ4 (radians, in [-π, π)); NaN where
            the branch is not singular.
        status: ``(*B,)`` :data:`STATUS_OK`, or why no branch exists
            (:data:`STATUS_INSIDE_CYLINDER`: φ1 has no real solution; :data:`STATUS_TOO_FAR`,
            :data:`STATUS_TOO_NEAR`: θ3 has none).
        position_error, rotation_error: ``(*B, 8)`` forward-analysis residuals of each branch
            (tool point distance in mm; rotation angle in radians); NaN when not verified.
        verified: whether the residuals were computed (``verify=True``).

    >>> from kinestat.robots.puma762.forward import forward
    >>> b = reverse_batch_pose(forward(np.full((2, 6), 0.3)).pose)
    >>> b.q.shape, b.valid.shape, b.status.tolist()
    ((2, 8, 6), (2, 8), [0, 0])
    """

    q: np.ndarray
    valid: np.ndarray
    singular: np.ndarray
    family_sum: np.ndarray
    family_value: np.ndarray
    status: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    verified: bool


def status_message(status: int, *, wrist_radius: float | None = None,
                   reach: float | None = None) -> str:
    """Explain a :class:`ReverseBatch` status code (which step has no real solution).

    >>> status_message(STATUS_INSIDE_CYLINDER)[:32]
    'φ1 has no real solution: the wri'
    """
    if status == STATUS_INSIDE_CYLINDER:
        extra = ("" if wrist_radius is None
                 else f" (its distance from S1 is {wrist_radius:.6g} mm)")
        return (
            f"φ1 has no real solution: the wrist centre lies inside the cylinder of radius "
            f"S2 = {S2:g} mm about the first joint axis{extra}; move the tool point away from S1"
        )
    if status == STATUS_TOO_FAR:
        extra = f" (it is {reach:.6g} mm)" if reach is not None else ""
        return (
            f"θ3 has no real solution: the wrist centre is too far from the shoulder — the "
            f"distance in the arm plane must be at most a23 + S4 = {A23 + S4:g} mm{extra}"
        )
    if status == STATUS_TOO_NEAR:
        extra = f" (it is {reach:.6g} mm)" if reach is not None else ""
        return (
            f"θ3 has no real solution: the wrist centre is too near the shoulder — the distance "
            f"in the arm plane must be at least |a23 − S4| = {abs(A23 - S4):g} mm{extra}"
        )
    return "reachable"


def _check_backend(backend: str) -> None:
    if backend not in BACKENDS:
        raise InputError(f"backend must be one of {BACKENDS}, got {backend!r}")


def reverse_batch(
    tool_point,
    s6,
    a67,
    tool_point_6=(0.0, 0.0, 0.0),
    *,
    verify: bool = True,
    tol: float = 1e-9,
    unit_tol: float = 1e-6,
    s5_tol: float = 1e-10,
    backend: Backend = "numba",
) -> ReverseBatch:
    """Reverse analysis of a batch of end-effector descriptions, all eight branches.

    Args:
        tool_point: ``P_tool_F (*B, 3)`` in mm.
        s6: ``S6_F (*B, 3)``, a unit vector (to ``unit_tol``) perpendicular to ``a67``.
        a67: ``a67_F (*B, 3)``, a unit vector (to ``unit_tol``) perpendicular to ``s6``.
        tool_point_6: ``P_tool_6 (*B, 3)`` or ``(3,)``.
        verify: run the forward analysis on every branch and keep only those that reproduce the
            pose within ``tol`` (mm for the position, radians for the rotation).
        tol: reach tolerance (a wrist centre up to ``tol`` mm outside the workspace is clamped onto
            its boundary) and verification tolerance.
        s5_tol: |sin θ5| below which a branch is reported as a wrist-singular family.
        backend: deprecated, for the tests: ``"numba"`` (the default: compiled, parallel over
            the poses) or ``"numpy"`` (the private NumPy reference,
            :mod:`kinestat.robots.puma762._reference`); both give the same results.

    No Python loop over poses. See :class:`ReverseBatch`.

    >>> from kinestat.robots.puma762.forward import forward
    >>> q = np.array([[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]])
    >>> f = forward(q)
    >>> b = reverse_batch(f.tool_point, f.s6, f.a67)
    >>> b.q.shape, int(b.valid.sum()), bool(np.any(np.all(np.abs(b.q[0] - q) < 1e-9, -1)))
    ((1, 8, 6), 8, True)
    """
    _check_backend(backend)
    T = frame6(tool_point, s6, a67, tool_point_6, tol=unit_tol)
    return reverse_batch_pose(T, verify=verify, tol=tol, s5_tol=s5_tol, backend=backend)


def reverse_batch_pose(pose6, *, verify: bool = True, tol: float = 1e-9,
                       s5_tol: float = 1e-10, backend: Backend = "numba") -> ReverseBatch:
    """:func:`reverse_batch` for poses of frame 6 ``(*B, 4, 4)`` given directly.

    The poses must be rigid transforms; only their finiteness is checked here (this is the
    fast path). A rotation part that is not orthonormal fails the verification. Memory: the
    compiled path needs nothing beyond its outputs (about 0.5 kB per pose); the NumPy reference
    works in chunks of :data:`CHUNK_ROWS` poses. :func:`iter_reverse_batch_pose` streams the
    results of very large batches chunk by chunk.

    >>> from kinestat.robots.puma762.forward import forward
    >>> q = np.array([[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]])
    >>> b = reverse_batch_pose(forward(q).pose)
    >>> found = np.all(np.abs(b.q[0] - q) < 1e-9, axis=-1)  # the branch that is q
    >>> bool(found.any()), float(b.position_error.max()) < 1e-9
    (True, True)
    """
    _check_backend(backend)
    T = np.asarray(pose6, dtype=float)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(f"poses must have shape (..., 4, 4), got {T.shape}")
    shape = T.shape[:-2]
    Tf = np.ascontiguousarray(T.reshape(-1, 4, 4))
    N = Tf.shape[0]
    q = np.empty((N, N_BRANCHES, 6))
    valid = np.empty((N, N_BRANCHES), dtype=bool)
    sing = np.empty((N, N_BRANCHES), dtype=bool)
    fsum = np.empty((N, N_BRANCHES), dtype=bool)
    fval = np.empty((N, N_BRANCHES))
    status = np.empty(N, dtype=np.int8)
    pe = np.empty((N, N_BRANCHES))
    re = np.empty((N, N_BRANCHES))
    outs = (q, valid, sing, fsum, fval, status, pe, re)
    if backend == "numba":
        kernel = _pk.reverse_batch if N >= _PARALLEL_MIN else _pk.reverse_serial
        if kernel(Tf, float(tol), float(s5_tol), bool(verify), *outs):
            raise InputError("poses contain NaN or infinity")
    else:
        if not np.all(np.isfinite(Tf)):
            raise InputError("poses contain NaN or infinity")
        for rows in chunk_slices(N):
            for out, part in zip(outs, reverse_numpy(Tf[rows], verify, tol, s5_tol),
                                 strict=True):
                out[rows] = part
    return ReverseBatch(q=q.reshape(shape + (N_BRANCHES, 6)),
                        valid=valid.reshape(shape + (N_BRANCHES,)),
                        singular=sing.reshape(shape + (N_BRANCHES,)),
                        family_sum=fsum.reshape(shape + (N_BRANCHES,)),
                        family_value=fval.reshape(shape + (N_BRANCHES,)),
                        status=status.reshape(shape),
                        position_error=pe.reshape(shape + (N_BRANCHES,)),
                        rotation_error=re.reshape(shape + (N_BRANCHES,)), verified=bool(verify))


def iter_reverse_batch_pose(pose6, *, chunk_rows: int = CHUNK_ROWS, verify: bool = True,
                            tol: float = 1e-9, s5_tol: float = 1e-10,
                            backend: Backend = "numba") -> Iterator[tuple[slice, ReverseBatch]]:
    """Stream :func:`reverse_batch_pose` over a large batch ``(N, 4, 4)`` chunk by chunk:
    yields ``(rows, batch)`` so that 10^7 poses need only one chunk of results at a time.

    >>> from kinestat.robots.puma762.forward import forward
    >>> T = forward(np.full((5, 6), 0.3)).pose
    >>> [(rows.start, b.q.shape) for rows, b in iter_reverse_batch_pose(T, chunk_rows=2)]
    [(0, (2, 8, 6)), (2, (2, 8, 6)), (4, (1, 8, 6))]
    """
    T = np.asarray(pose6, dtype=float)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(f"poses must have shape (..., 4, 4), got {T.shape}")
    if chunk_rows < 1:
        raise InputError(f"chunk_rows must be at least 1, got {chunk_rows}")
    Tf = T.reshape(-1, 4, 4)
    for rows in chunk_slices(Tf.shape[0], chunk_rows):
        yield rows, reverse_batch_pose(Tf[rows], verify=verify, tol=tol, s5_tol=s5_tol,
                                       backend=backend)


@dataclass(frozen=True)
class WristFamily:
    """A one-parameter family of solutions at a wrist singularity (sin θ5 = 0).

    ``kind`` is ``"difference"`` (θ5 = 0: θ6 − θ4 = ``value``) or ``"sum"`` (θ5 = 180°:
    θ4 + θ6 = ``value``); φ1, θ2, θ3, θ5 are fixed. ``representative`` is one member.

    >>> from kinestat.robots.puma762.forward import forward
    >>> fam = reverse_pose(forward(np.zeros(6)).pose).families[0]
    >>> fam.kind, bool(np.allclose(forward(fam.member(0.7)).pose, forward(np.zeros(6)).pose))
    ('difference', True)
    """

    phi1: float
    theta2: float
    theta3: float
    theta5: float
    kind: str
    value: float
    representative: np.ndarray
    branch: int

    def member(self, theta4: float) -> np.ndarray:
        """The family member with the given θ4 (radians)."""
        th6 = self.value + theta4 if self.kind == "difference" else self.value - theta4
        return np.array([self.phi1, self.theta2, self.theta3, theta4, self.theta5, th6])


@dataclass(frozen=True, eq=False)
class ReverseResult:
    """Every solution of one reverse analysis.

    Attributes:
        solutions: ``(k, 6)`` the distinct isolated solutions (radians, in [-π, π)), k ≤ 8.
        branches: ``(k,)`` the branch index (solution tree, 0..7) of each solution.
        families: the distinct wrist-singular one-parameter families.
        reason: None when every branch exists; otherwise why some are missing.
        batch: the underlying :class:`ReverseBatch` (batch shape ``()``).

    >>> from kinestat.robots.puma762.forward import forward
    >>> r = reverse_pose(forward(np.full(6, 0.3)).pose)
    >>> r.solutions.shape, r.branches.tolist(), r.families, r.reason
    ((8, 6), [0, 1, 2, 3, 4, 5, 6, 7], (), None)
    """

    solutions: np.ndarray
    branches: np.ndarray
    families: tuple[WristFamily, ...]
    reason: str | None
    batch: ReverseBatch


def _same_angles(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    return bool(np.all(np.abs(_wrap(a - b)) <= tol))


def _single_vec3(v, name: str) -> np.ndarray:
    try:  # a fresh, writeable C-contiguous copy: the one argument type the kernel compiles for
        a = np.array(v, dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if a is None or a.shape != (3,):
        raise InputError(f"{name} must be 3 numbers for a single pose, got shape "
                         f"{np.shape(v)}; use reverse_batch for many poses")
    return a


def reverse(
    tool_point,
    s6,
    a67,
    tool_point_6=(0.0, 0.0, 0.0),
    *,
    tol: float = 1e-9,
    unit_tol: float = 1e-6,
    s5_tol: float = 1e-10,
    backend: Backend = "numba",
) -> ReverseResult:
    """Closed-form reverse analysis of one pose: every isolated solution and singular family.

    Each returned solution reproduces the pose under :func:`forward` within ``tol``. Raises
    :class:`UnreachableError` (saying which step has no real solution) when there is none.
    ``backend="numpy"`` (deprecated, for the tests) runs the NumPy reference instead of the
    compiled kernel. The theses' name; :func:`kinestat.ik` is the generic numerical solver.

    >>> from kinestat.robots.puma762.forward import forward
    >>> q = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    >>> f = forward(q)
    >>> r = reverse(f.tool_point, f.s6, f.a67)
    >>> r.solutions.shape, bool(np.any(np.all(np.abs(r.solutions - q) < 1e-9, axis=-1)))
    ((8, 6), True)
    """
    p = _single_vec3(tool_point, "tool_point")
    z = _single_vec3(s6, "s6")
    x = _single_vec3(a67, "a67")
    p6 = _single_vec3(tool_point_6, "tool_point_6")
    if backend == "numba":
        return _result_one(_pk.reverse_vectors_one(p, z, x, p6, float(unit_tol), float(tol),
                                                   float(s5_tol)), tol, unit_tol)
    _check_backend(backend)
    T = frame6(p, z, x, p6, tol=unit_tol)
    return reverse_one(T, tol=tol, s5_tol=s5_tol, backend=backend)


def reverse_pose(pose6, *, tol: float = 1e-9, s5_tol: float = 1e-10,
                 backend: Backend = "numba") -> ReverseResult:
    """:func:`reverse` for the pose of frame 6 ``T_F_6`` given as a 4x4 matrix.

    >>> from kinestat.robots.puma762.forward import forward
    >>> r = reverse_pose(forward(np.zeros(6)).pose)
    >>> len(r.families), r.solutions.shape  # θ5 = 0: the wrist is singular
    (2, (4, 6))
    """
    T = np.asarray(pose6, dtype=float)
    if T.shape != (4, 4):
        raise InputError(f"pose must be a 4x4 matrix, got shape {T.shape}")
    if backend == "numba":
        return _result_one(_pk.reverse_pose_one(T, float(tol), float(s5_tol)), tol, 1e-6)
    _check_backend(backend)
    R = T[:3, :3]
    if not np.all(np.isfinite(T)) or np.max(np.abs(R @ R.T - np.eye(3))) > 1e-6 \
            or np.linalg.det(R) < 0:
        raise InputError(_frame6_message(_pk.ERR_NOT_RIGID, 0.0, 0.0))
    return reverse_one(frame6(T[:3, 3], T[:3, 2], T[:3, 0]), tol=tol, s5_tol=s5_tol,
                        backend=backend)


def _unreachable(T: np.ndarray, status: int) -> UnreachableError:
    W = wrist_center(T)
    r = float(np.hypot(W[0], W[1]))
    ux = math.sqrt(max(r * r - S2 * S2, 0.0))
    return UnreachableError(
        "PUMA 762 pose out of reach: "
        + status_message(status, wrist_radius=r, reach=math.hypot(ux, W[2]))
    )


def _failed_reason(n_bad: int, tol: float) -> str:
    return (f"{n_bad} of 8 branches failed verification (forward residual above "
            f"{tol:g}); numerically ill-conditioned pose")


def _family(b: ReverseBatch, k: int) -> WristFamily:
    qk = b.q[k]
    return WristFamily(phi1=float(qk[0]), theta2=float(qk[1]), theta3=float(qk[2]),
                       theta5=float(qk[4]), kind="sum" if b.family_sum[k] else "difference",
                       value=float(b.family_value[k]), representative=qk.copy(), branch=k)


_STATUS_0D = {s: np.array(s, dtype=np.int8) for s in range(4)}


def _result_one(out, tol: float, unit_tol: float) -> ReverseResult:
    """A :class:`ReverseResult` from the single-pose kernel's output."""
    err, bad, status, T, q, valid, sing, fsum, fval, pe, re, sols, branches, n_fam, n_bad = out
    if err:
        raise InputError(_frame6_message(err, bad, unit_tol))
    if status:
        raise _unreachable(T, status)
    b = ReverseBatch(q=q, valid=valid, singular=sing, family_sum=fsum, family_value=fval,
                     status=_STATUS_0D[status].copy(), position_error=pe, rotation_error=re,
                     verified=True)
    fams: tuple[WristFamily, ...] = ()
    if n_fam:
        fams = _distinct_families(b, tol)
    reason = None
    if n_bad:
        reason = _failed_reason(n_bad, tol)
        if branches.size == 0 and not fams:
            raise UnreachableError("PUMA 762 reverse analysis: " + reason)
    return ReverseResult(solutions=sols, branches=branches, families=fams, reason=reason,
                         batch=b)


def _distinct_families(b: ReverseBatch, tol: float) -> tuple[WristFamily, ...]:
    """The distinct wrist-singular families among the valid branches, in branch order."""
    fams: list[WristFamily] = []
    dup_tol = max(1e3 * tol, 1e-9)
    for k in range(N_BRANCHES):
        if not (b.valid[k] and b.singular[k]):
            continue
        qk = b.q[k]
        kind = "sum" if b.family_sum[k] else "difference"
        val = float(b.family_value[k])
        if not any(
            f.kind == kind
            and _same_angles(np.array([f.phi1, f.theta2, f.theta3, f.value]),
                             np.array([qk[0], qk[1], qk[2], val]), dup_tol)
            for f in fams
        ):
            fams.append(_family(b, k))
    return tuple(fams)


def reverse_one(T: np.ndarray, *, tol: float, s5_tol: float,
                 backend: Backend = "numpy") -> ReverseResult:
    """The reference single-pose analysis (``backend="numpy"``): a batch of one, then duplicates
    removed in Python."""
    b = reverse_batch_pose(T, verify=True, tol=tol, s5_tol=s5_tol, backend=backend)
    status = int(b.status)
    if status != STATUS_OK:
        raise _unreachable(T, status)
    sols: list[np.ndarray] = []
    branches: list[int] = []
    fams: list[WristFamily] = []
    dup_tol = max(1e3 * tol, 1e-9)
    for k in range(N_BRANCHES):
        if not b.valid[k]:
            continue
        qk = b.q[k]
        if b.singular[k]:
            kind = "sum" if b.family_sum[k] else "difference"
            val = float(b.family_value[k])
            if any(
                f.kind == kind
                and _same_angles(np.array([f.phi1, f.theta2, f.theta3, f.value]),
                                 np.array([qk[0], qk[1], qk[2], val]), dup_tol)
                for f in fams
            ):
                continue
            fams.append(_family(b, k))
            continue
        if any(_same_angles(s, qk, dup_tol) for s in sols):
            continue
        sols.append(qk.copy())
        branches.append(k)
    n_bad = int(np.sum(~b.valid))
    reason = None
    if n_bad:
        reason = _failed_reason(n_bad, tol)
        if not sols and not fams:
            raise UnreachableError("PUMA 762 reverse analysis: " + reason)
    out = np.array(sols).reshape(-1, 6)
    return ReverseResult(solutions=out, branches=np.array(branches, dtype=int),
                         families=tuple(fams), reason=reason, batch=b)
