"""The PUMA 762 in closed form: forward and reverse (inverse) position analysis, batched.

Crane–Duffy convention (Vibhute 2011 §2.2; Crane & Duffy 1998 ch. 10): frame j has z along the
joint axis S_j and x along the common normal a_jk; frame j is placed in frame i by
``Rx(α_ij) · Tx(a_ij) · Rz(θ_j) · Tz(S_j)`` (eq. 2-26) and the fixed frame F shares frame 1's
origin and z axis, ``F_1T = Rz(φ1)`` (eq. 2-28). Joint values are ``q = (φ1, θ2, θ3, θ4, θ5, θ6)``
in radians. Mechanism parameters (Tables 2-2 and 2-3, millimetres)::

    a12 = 0    α12 = 90°
    a23 = 650  α23 = 0     S2 = 190
    a34 = 0    α34 = 270°  S3 = 0
    a45 = 0    α45 = 90°   S4 = 600
    a56 = 0    α56 = 90°   S5 = 0
               α67 = 90°   S6 = 125

The end effector is described as the thesis does: the tool point ``P_tool_F`` (fixed frame), the
sixth joint axis ``S6_F`` (z of frame 6) and the link direction ``a67_F`` (x of frame 6); the tool
point's coordinates in frame 6 are ``P_tool_6``. The reverse analysis closes the loop with the
hypothetical seventh link (:func:`close_loop`) and solves φ1, θ3, θ2, θ5, θ4, θ6 in turn: two φ1 ×
two θ3 × two θ5 = eight branches, in the order of the solution tree (Figure 2-14): branch index
``4·i1 + 2·i3 + i5``. Branches that fall on a wrist singularity (sin θ5 = 0) are one-parameter
families (θ6 − θ4 fixed when θ5 = 0, θ4 + θ6 fixed when θ5 = 180°), reported as such.

The robot's axis angles differ from q by the thesis's kinematic correction (Appendix D.2,
``Pos_A_KCorrection``): axis 1 = φ1 + 180°, the others equal θ2..θ6; joint limits are applied to
axis angles (:data:`AXIS_LIMITS_DEG`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError, JointLimitError, UnreachableError
from kinestat.serial import _puma762_kernels as _pk

__all__ = [
    "A23",
    "S2",
    "S4",
    "S6",
    "ALPHA_DEG",
    "AXIS_OFFSET",
    "AXIS_LIMITS_DEG",
    "AXIS_LIMITS_MATLAB_DEG",
    "AXIS_LIMITS_TABLE_2_1_DEG",
    "N_BRANCHES",
    "STATUS_OK",
    "STATUS_INSIDE_CYLINDER",
    "STATUS_TOO_FAR",
    "STATUS_TOO_NEAR",
    "link_transform",
    "ForwardResult",
    "forward",
    "frame6",
    "wrist_center",
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
    "CHUNK_ROWS",
    "pose_residuals",
    "to_axis_angles",
    "from_axis_angles",
    "wrap_into_limits",
    "Selection",
    "select_batch",
    "select",
    "within_limits",
    "status_message",
]

# -- mechanism parameters (Vibhute Tables 2-2 and 2-3, mm) ------------------------------------
A23 = 650.0
"""Link length a23 (mm)."""
S2 = 190.0
"""Joint offset S2 (mm): the shoulder offset, radius of the cylinder the wrist cannot enter."""
S4 = 600.0
"""Joint offset S4 (mm): the forearm."""
S6 = 125.0
"""Joint offset S6 (mm) chosen to close the loop (Table 2-3): frame 6 origin beyond the wrist."""

ALPHA_DEG = (90.0, 0.0, 270.0, 90.0, 90.0)
"""Twist angles α12, α23, α34, α45, α56 (degrees, Table 2-2)."""

# Exact cosines and sines of the twist angles (avoid cos(270°) = -1.8e-16).
_CA = (0.0, 1.0, 0.0, 0.0, 0.0)
_SA = (1.0, 0.0, -1.0, 1.0, 1.0)
_A = (0.0, A23, 0.0, 0.0, 0.0)  # a12, a23, a34, a45, a56
_S = (S2, 0.0, S4, 0.0, S6)  # S2, S3, S4, S5, S6

AXIS_OFFSET = np.array([math.pi, 0.0, 0.0, 0.0, 0.0, 0.0])
"""Axis angle − joint angle (radians): axis 1 = φ1 + 180° (Appendix D.2, Pos_A_KCorrection)."""
AXIS_OFFSET.setflags(write=False)

AXIS_LIMITS_MATLAB_DEG = np.array(
    [[-160.0, 160.0], [-110.0, 110.0], [-135.0, 135.0], [-266.0, 266.0], [-100.0, 100.0],
     [-266.0, 266.0]]
)
"""Axis limits "as per manufacturer" in puma_rev_analysis.m (Appendix D.2), degrees."""
AXIS_LIMITS_MATLAB_DEG.setflags(write=False)

AXIS_LIMITS_TABLE_2_1_DEG = np.array(
    [[-160.0, 160.0], [-110.0, 110.0], [-135.0, 135.0], [-266.0, 266.0], [-110.0, 110.0],
     [-266.0, 266.0]]
)
"""Table 2-1's software movement ranges (320, 220, 270, 532, 220, 532°) split symmetrically."""
AXIS_LIMITS_TABLE_2_1_DEG.setflags(write=False)

AXIS_LIMITS_DEG = AXIS_LIMITS_MATLAB_DEG
"""Default axis limits: the MATLAB ones, which are the tighter set (joint 5 ±100° rather than
Table 2-1's ±110°) and the ones the thesis's controller actually enforced."""

N_BRANCHES = 8

BACKENDS = ("numba", "numpy")
"""Implementations of the reverse analysis: ``"numba"`` (compiled kernels,
:mod:`kinestat.serial._puma762_kernels`, the default) and ``"numpy"`` (the plain array reference
they are tested against)."""

CHUNK_ROWS = 1 << 15
"""Poses per chunk of the NumPy reference and of :func:`iter_reverse_batch_pose`."""

_PARALLEL_MIN = 64  # smaller batches run on one thread (starting the workers costs more)

STATUS_OK = 0
STATUS_INSIDE_CYLINDER = 1
STATUS_TOO_FAR = 2
STATUS_TOO_NEAR = 3

_TWO_PI = 2.0 * math.pi


def _wrap(x):
    """Angles wrapped to [-π, π)."""
    return (np.asarray(x) + math.pi) % _TWO_PI - math.pi


# -- forward analysis ------------------------------------------------------------------------
def link_transform(cos_alpha, sin_alpha, a, theta, s) -> np.ndarray:
    """``iT_j = Rx(α_ij) Tx(a_ij) Rz(θ_j) Tz(S_j)``, batched over ``theta`` (Vibhute eq. 2-26).

    Takes cos α and sin α (so that 270° is exact) and θ in radians.
    """
    th = np.asarray(theta, dtype=float)
    c, s_ = np.cos(th), np.sin(th)
    T = np.zeros(th.shape + (4, 4))
    T[..., 0, 0] = c
    T[..., 0, 1] = -s_
    T[..., 0, 3] = a
    T[..., 1, 0] = s_ * cos_alpha
    T[..., 1, 1] = c * cos_alpha
    T[..., 1, 2] = -sin_alpha
    T[..., 1, 3] = -sin_alpha * s
    T[..., 2, 0] = s_ * sin_alpha
    T[..., 2, 1] = c * sin_alpha
    T[..., 2, 2] = cos_alpha
    T[..., 2, 3] = cos_alpha * s
    T[..., 3, 3] = 1.0
    return T


@dataclass(frozen=True, eq=False)
class ForwardResult:
    """Result of :func:`forward`, batched like ``q[..., 0]``.

    Attributes:
        tool_point: ``P_tool_F`` ``(..., 3)``, the tool point in the fixed frame (eq. 2-34).
        s6: ``S6_F`` ``(..., 3)``, the sixth joint axis (z of frame 6).
        a67: ``a67_F`` ``(..., 3)``, the link direction a67 (x of frame 6).
        pose: ``F_6T`` ``(..., 4, 4)``, frame 6 in the fixed frame (eq. 2-33).
    """

    tool_point: np.ndarray
    s6: np.ndarray
    a67: np.ndarray
    pose: np.ndarray


def _check_q(q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.ndim == 0 or q.shape[-1] != 6:
        raise InputError(f"PUMA 762 joint angles must have shape (..., 6), got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise InputError("PUMA 762 joint angles contain NaN or infinity")
    return q


def _check_vec3(v, name: str) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    if v.ndim == 0 or v.shape[-1] != 3:
        raise InputError(f"{name} must have shape (..., 3), got {v.shape}")
    if not np.all(np.isfinite(v)):
        raise InputError(f"{name} contains NaN or infinity")
    return v


def _frame_columns(q: np.ndarray):
    """Columns x, y, z ``(..., 3)`` and origin p of ``F_6T`` (eq. 2-33), by the link product.

    ``F_6T = F_1T · 1_2T · 2_3T · 3_4T · 4_5T · 5_6T`` with ``F_1T = Rz(φ1)`` (eq. 2-28) and
    ``i_jT = Rx(α_ij) Tx(a_ij) Rz(θ_j) Tz(S_j)`` (eq. 2-26), multiplied out on the columns of the
    running frame: ``·Rx(α)`` turns (y, z) into (cα y + sα z, −sα y + cα z), ``·Tx(a)`` moves the
    origin by a·x, ``·Rz(θ)`` turns (x, y) into (cθ x + sθ y, −sθ x + cθ y) and ``·Tz(S)`` moves
    it by S·z. Same product as puma_fwd_analysis.m, without 4x4 matrix products.
    """
    c1, s1 = np.cos(q[..., 0]), np.sin(q[..., 0])
    zero = np.zeros_like(c1)
    one = np.ones_like(c1)
    X = np.stack([c1, s1, zero], axis=-1)
    Y = np.stack([-s1, c1, zero], axis=-1)
    Z = np.stack([zero, zero, one], axis=-1)
    p = np.zeros_like(X)
    for k in range(5):
        ca, sa, a, S = _CA[k], _SA[k], _A[k], _S[k]
        if a:
            p = p + a * X
        if sa:
            Y, Z = ca * Y + sa * Z, ca * Z - sa * Y
        th = q[..., k + 1, None]
        c, s_ = np.cos(th), np.sin(th)
        X, Y = c * X + s_ * Y, c * Y - s_ * X
        if S:
            p = p + S * Z
    return X, Y, Z, p


def _pose_06(q: np.ndarray) -> np.ndarray:
    """``F_6T`` ``(..., 4, 4)`` (eq. 2-33)."""
    X, Y, Z, p = _frame_columns(q)
    T = np.zeros(q.shape[:-1] + (4, 4))
    T[..., :3, 0] = X
    T[..., :3, 1] = Y
    T[..., :3, 2] = Z
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def forward(q, tool_point_6=(0.0, 0.0, 0.0)) -> ForwardResult:
    """Forward analysis (Vibhute eqs. 2-33, 2-34; Appendix D.3): q ``(..., 6)`` in radians.

    Returns the tool point ``P_tool_F = F_6T · P_tool_6``, ``S6_F``, ``a67_F`` and the pose.
    """
    q = _check_q(q)
    p6 = _check_vec3(tool_point_6, "tool_point_6")
    T = _pose_06(q)
    tool = np.einsum("...ij,...j->...i", T[..., :3, :3], p6) + T[..., :3, 3]
    return ForwardResult(tool_point=tool, s6=T[..., :3, 2].copy(), a67=T[..., :3, 0].copy(),
                         pose=T)


# -- the end effector as a frame ----------------------------------------------------------------
def _frame6_message(code: int, bad: float, tol: float) -> str:
    """The words of :func:`frame6`'s input errors (codes of :mod:`._puma762_kernels`)."""
    if code == _pk.ERR_NONFINITE_P:
        return "tool_point (P_tool_F) contains NaN or infinity"
    if code == _pk.ERR_NONFINITE_Z:
        return "s6 (S6_F) contains NaN or infinity"
    if code == _pk.ERR_NONFINITE_X:
        return "a67 (a67_F) contains NaN or infinity"
    if code == _pk.ERR_NONFINITE_P6:
        return "tool_point_6 (P_tool_6) contains NaN or infinity"
    if code == _pk.ERR_Z_NOT_UNIT:
        return (f"s6 (S6_F) must be a unit vector: |S6_F| differs from 1 by {bad:.3g} "
                f"(tolerance {tol:g}); normalise it first")
    if code == _pk.ERR_X_NOT_UNIT:
        return (f"a67 (a67_F) must be a unit vector: |a67_F| differs from 1 by {bad:.3g} "
                f"(tolerance {tol:g}); normalise it first")
    if code == _pk.ERR_NOT_PERPENDICULAR:
        return (f"s6 (S6_F) and a67 (a67_F) must be perpendicular: S6_F·a67_F = {bad:.3g} "
                f"(tolerance {tol:g})")
    return "pose must be a finite rigid transform (orthonormal rotation, det +1)"


def frame6(tool_point, s6, a67, tool_point_6=(0.0, 0.0, 0.0), *, tol: float = 1e-6) -> np.ndarray:
    """Pose of frame 6 ``(..., 4, 4)`` from the thesis's description of the end effector.

    ``S6_F`` and ``a67_F`` must be unit vectors and perpendicular to within ``tol``; they are
    then re-orthonormalised (Gram–Schmidt) so that the frame is exactly a rotation. The origin is
    ``P_tool_F − R · P_tool_6``. The inputs broadcast against each other.
    """
    p = _check_vec3(tool_point, "tool_point (P_tool_F)")
    z = _check_vec3(s6, "s6 (S6_F)")
    x = _check_vec3(a67, "a67 (a67_F)")
    p6 = _check_vec3(tool_point_6, "tool_point_6 (P_tool_6)")
    try:
        shape = np.broadcast_shapes(p.shape, z.shape, x.shape, p6.shape)[:-1]
    except ValueError as exc:
        raise InputError(
            f"tool_point {p.shape}, s6 {z.shape}, a67 {x.shape} and tool_point_6 {p6.shape} "
            "do not broadcast to one batch of poses"
        ) from exc
    rows = [np.ascontiguousarray(np.broadcast_to(v, shape + (3,)).reshape(-1, 3))
            for v in (p, z, x, p6)]
    T = np.empty((rows[0].shape[0], 4, 4))
    dz, dx, dd = _pk.frame6_rows(*rows, T)
    for code, dev in ((_pk.ERR_Z_NOT_UNIT, dz), (_pk.ERR_X_NOT_UNIT, dx),
                      (_pk.ERR_NOT_PERPENDICULAR, dd)):
        if dev > tol:
            raise InputError(_frame6_message(code, dev, tol))
    return T.reshape(shape + (4, 4))


def wrist_center(pose6) -> np.ndarray:
    """The wrist centre (intersection of S4, S5, S6): frame 6's origin minus S6 · S6_F."""
    T = np.asarray(pose6, dtype=float)
    return T[..., :3, 3] - S6 * T[..., :3, 2]


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
    """Explain a :class:`ReverseBatch` status code (which step has no real solution)."""
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


def pose_residuals(q, pose6) -> tuple[np.ndarray, np.ndarray]:
    """Position error (mm) of frame 6's origin and rotation angle (rad), F_6T(q) against pose6.

    The angle is ``2 asin(|R − R_t|_F / (2√2))`` as in :func:`kinestat.serial.ik.pose_error`.
    """
    X, Y, Z, p = _frame_columns(np.asarray(q, dtype=float))
    T = np.asarray(pose6, dtype=float)
    pos = np.sqrt(np.sum((p - T[..., :3, 3]) ** 2, axis=-1))
    d2 = (np.sum((X - T[..., :3, 0]) ** 2, axis=-1) + np.sum((Y - T[..., :3, 1]) ** 2, axis=-1)
          + np.sum((Z - T[..., :3, 2]) ** 2, axis=-1))
    rot = 2.0 * np.arcsin(np.minimum(np.sqrt(d2) / (2.0 * math.sqrt(2.0)), 1.0))
    return pos, rot


def _reverse_kernel(T: np.ndarray, tol: float, s5_tol: float):
    """φ1, θ3, θ2, θ5, θ4, θ6 for poses of frame 6 ``T (*B, 4, 4)``: pure array arithmetic.

    Branch axes: φ1 (i1), θ3 (i3), θ5 (i5); arrays shaped ``(*B, 2, 1)`` depend on φ1 only,
    ``(*B, 1, 2)`` on θ3 only, ``(*B, 2, 2)`` on the arm, ``(*B, 2, 2, 2)`` on all three.
    """
    shape = T.shape[:-2]
    r00, r10, r20 = T[..., 0, 0], T[..., 1, 0], T[..., 2, 0]  # a67_F (x6)
    r02, r12, r22 = T[..., 0, 2], T[..., 1, 2], T[..., 2, 2]  # S6_F (z6)
    # wrist centre W = P6 − S6 · S6_F (the loop closed through the hypothetical link 7)
    wx = T[..., 0, 3] - S6 * r02
    wy = T[..., 1, 3] - S6 * r12
    wz = T[..., 2, 3] - S6 * r22

    # φ1 (eq. 2-47 in fixed-frame form): −sin φ1 Wx + cos φ1 Wy = −S2, two roots; ux is the
    # wrist's distance from S1 along the arm plane, ±sqrt(r² − S2²).
    r = np.hypot(wx, wy)
    inside = r < S2 - tol
    ux = np.sqrt(np.maximum((r - S2) * (r + S2), 0.0))
    ux2 = np.stack([ux, -ux], axis=-1)[..., :, None]  # (*B, 2, 1)
    phi = _wrap(np.arctan2(wy, wx)[..., None, None] + np.arctan2(S2, ux2))

    # θ3 (eq. 2-53): ux² + Wz² = a23² + S4² − 2 a23 S4 sin θ3, two roots ±cos θ3
    rho = np.hypot(ux, wz)
    too_far = rho > A23 + S4 + tol
    too_near = rho < abs(A23 - S4) - tol
    s3 = np.clip((A23 * A23 + S4 * S4 - rho * rho) / (2.0 * A23 * S4), -1.0, 1.0)
    d_near, d_far = abs(A23 - S4), A23 + S4  # cos θ3 from the factored (1 − s3)(1 + s3)
    c3 = np.sqrt(np.maximum((rho - d_near) * (rho + d_near), 0.0)
                 * np.maximum((d_far - rho) * (d_far + rho), 0.0)) / (2.0 * A23 * S4)
    c3_2 = np.stack([c3, -c3], axis=-1)[..., None, :]  # (*B, 1, 2)
    s3b = s3[..., None, None]
    th3 = np.arctan2(s3b, c3_2)

    # θ2 (eqs. 2-50, 2-51): Rz(θ2) (a23 − S4 s3, S4 c3) = (ux, Wz)
    th2 = _wrap(np.arctan2(wz[..., None, None], ux2)
                - np.arctan2(S4 * c3_2, (A23 - S4 * s3b)))  # (*B, 2, 2)

    # Wrist: N = Rx(90°) · F_3R^T · F_6R = Rz(θ4) · Rx(90°) Rz(θ5) Rx(90°) · Rz(θ6), where
    # F_3R = Rz(φ1) Rx(90°) Rz(θ2 + θ3); only N's third column and first column are needed.
    cf, sf = np.cos(phi), np.sin(phi)  # (*B, 2, 1)
    th23 = th2 + th3
    c23, s23 = np.cos(th23), np.sin(th23)  # (*B, 2, 2)
    e = lambda v: v[..., None, None]  # noqa: E731  (*B) -> (*B, 1, 1)
    hz = cf * e(r02) + sf * e(r12)
    hx = cf * e(r00) + sf * e(r10)
    n02 = c23 * hz + s23 * e(r22)
    n12 = cf * e(r12) - sf * e(r02)
    n22 = c23 * e(r22) - s23 * hz
    n00 = c23 * hx + s23 * e(r20)
    n10 = cf * e(r10) - sf * e(r00)
    n20 = c23 * e(r20) - s23 * hx

    # θ5: N[:, 2] = (c4 s5, s4 s5, −c5), two roots ±; |s5| from the first two components
    # (not sqrt(1 − c5²), which loses half the digits near θ5 = 0 or π).
    c5 = -n22
    s5m = np.hypot(n02, n12)
    sign = np.array([1.0, -1.0])
    f = lambda v: v[..., None]  # noqa: E731  (*B, 2, 2) -> (*B, 2, 2, 1)
    s5 = f(s5m) * sign  # (*B, 2, 2, 2)
    th5 = np.arctan2(s5, f(c5))
    sing = np.broadcast_to(f(s5m < s5_tol), s5.shape)
    # θ4 from the third column (scale-free atan2). On a singular branch any θ4 will do: the
    # representative is θ4 = 0 when that moves frame 6 by far less than ``tol`` (|ΔS6| ≤ 2|s5|),
    # otherwise the computed θ4, which reproduces the pose exactly.
    th4 = np.arctan2(f(n12) * sign, f(n02) * sign)
    clean = s5m * 2.0 * (S6 + 1.0) <= 1e-3 * tol
    th4 = np.where(f(clean), 0.0, th4)
    # θ6 from the remainder Rz(θ6) = (Rz(θ4) Rx90 Rz(θ5) Rx90)^T N, exact even near singular:
    # with v = Rz(−θ4) N[:, 0], cos θ6 = c5 v0 + s5 v2 and sin θ6 = −v1.
    c4, s4 = np.cos(th4), np.sin(th4)
    v0 = c4 * f(n00) + s4 * f(n10)
    v1 = c4 * f(n10) - s4 * f(n00)
    th6 = np.arctan2(-v1, f(c5) * v0 + s5 * f(n20))

    q = np.empty(shape + (2, 2, 2, 6))
    q[..., 0] = f(phi)
    q[..., 1] = f(th2)
    q[..., 2] = f(th3)
    q[..., 3] = th4
    q[..., 4] = th5
    q[..., 5] = th6
    q = q.reshape(shape + (N_BRANCHES, 6))
    sing = sing.reshape(shape + (N_BRANCHES,))
    fam_sum = np.broadcast_to(f(c5 < 0.0), s5.shape).reshape(shape + (N_BRANCHES,))
    fam_val = np.where(sing, _wrap(np.where(fam_sum, q[..., 5] + q[..., 3],
                                            q[..., 5] - q[..., 3])), np.nan)

    status = np.full(shape, STATUS_OK, dtype=np.int8)
    status[too_near] = STATUS_TOO_NEAR
    status[too_far] = STATUS_TOO_FAR
    status[inside] = STATUS_INSIDE_CYLINDER
    return q, sing, fam_sum, fam_val, status


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
    backend: str = "numba",
) -> ReverseBatch:
    """Reverse analysis of a batch of end-effector descriptions, all eight branches.

    Args:
        tool_point: ``P_tool_F (*B, 3)`` in mm.
        s6, a67: ``S6_F``, ``a67_F (*B, 3)``, unit and perpendicular to ``unit_tol``.
        tool_point_6: ``P_tool_6 (*B, 3)`` or ``(3,)``.
        verify: run the forward analysis on every branch and keep only those that reproduce the
            pose within ``tol`` (mm for the position, radians for the rotation).
        tol: reach tolerance (a wrist centre up to ``tol`` mm outside the workspace is clamped onto
            its boundary) and verification tolerance.
        s5_tol: |sin θ5| below which a branch is reported as a wrist-singular family.
        backend: ``"numba"`` (compiled, parallel over the poses) or ``"numpy"`` (the plain
            array reference); both give the same results.

    No Python loop over poses. See :class:`ReverseBatch`.
    """
    _check_backend(backend)
    T = frame6(tool_point, s6, a67, tool_point_6, tol=unit_tol)
    return reverse_batch_pose(T, verify=verify, tol=tol, s5_tol=s5_tol, backend=backend)


def _reverse_numpy(T: np.ndarray, verify: bool, tol: float, s5_tol: float):
    """The plain array reference: :func:`_reverse_kernel` and :func:`pose_residuals`."""
    q, sing, fam_sum, fam_val, status = _reverse_kernel(T, tol, s5_tol)
    valid = np.broadcast_to((status == STATUS_OK)[..., None], sing.shape).copy()
    if verify:
        pe, re = pose_residuals(np.where(valid[..., None], q, 0.0), T[..., None, :, :])
        valid &= (pe <= tol) & (re <= tol)
    else:
        pe = np.full(sing.shape, np.nan)
        re = np.full(sing.shape, np.nan)
    q = np.where(valid[..., None], q, np.nan)
    sing = sing & valid
    fam_val = np.where(sing, fam_val, np.nan)
    return q, valid, sing, fam_sum & sing, fam_val, status, pe, re


def reverse_batch_pose(pose6, *, verify: bool = True, tol: float = 1e-9,
                       s5_tol: float = 1e-10, backend: str = "numba") -> ReverseBatch:
    """:func:`reverse_batch` for poses of frame 6 ``(*B, 4, 4)`` given directly.

    The poses must be rigid transforms; only their finiteness is checked here (this is the
    fast path). A rotation part that is not orthonormal fails the verification. Memory: the
    compiled path needs nothing beyond its outputs (about 0.5 kB per pose); the NumPy reference
    works in chunks of :data:`CHUNK_ROWS` poses. :func:`iter_reverse_batch_pose` streams the
    results of very large batches chunk by chunk.
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
        for start in range(0, N, CHUNK_ROWS):
            rows = slice(start, start + CHUNK_ROWS)
            for out, part in zip(outs, _reverse_numpy(Tf[rows], verify, tol, s5_tol),
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
                            backend: str = "numba") -> Iterator[tuple[slice, ReverseBatch]]:
    """Stream :func:`reverse_batch_pose` over a large batch ``(N, 4, 4)`` chunk by chunk:
    yields ``(rows, batch)`` so that 10^7 poses need only one chunk of results at a time."""
    T = np.asarray(pose6, dtype=float)
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(f"poses must have shape (..., 4, 4), got {T.shape}")
    if chunk_rows < 1:
        raise InputError(f"chunk_rows must be at least 1, got {chunk_rows}")
    Tf = T.reshape(-1, 4, 4)
    for start in range(0, Tf.shape[0], chunk_rows):
        rows = slice(start, min(start + chunk_rows, Tf.shape[0]))
        yield rows, reverse_batch_pose(Tf[rows], verify=verify, tol=tol, s5_tol=s5_tol,
                                       backend=backend)


# -- reverse analysis for one pose: solutions, families, reasons ----------------------------------
@dataclass(frozen=True)
class WristFamily:
    """A one-parameter family of solutions at a wrist singularity (sin θ5 = 0).

    ``kind`` is ``"difference"`` (θ5 = 0: θ6 − θ4 = ``value``) or ``"sum"`` (θ5 = 180°:
    θ4 + θ6 = ``value``); φ1, θ2, θ3, θ5 are fixed. ``representative`` is one member.
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
    """

    solutions: np.ndarray
    branches: np.ndarray
    families: tuple[WristFamily, ...]
    reason: str | None
    batch: ReverseBatch


def _same_angles(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    return bool(np.all(np.abs(_wrap(a - b)) <= tol))


def _single_vec3(v, name: str) -> np.ndarray:
    try:
        a = np.asarray(v, dtype=np.float64)
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
    backend: str = "numba",
) -> ReverseResult:
    """Closed-form reverse analysis of one pose: every isolated solution and singular family.

    Each returned solution reproduces the pose under :func:`forward` within ``tol``. Raises
    :class:`UnreachableError` (saying which step has no real solution) when there is none.
    ``backend="numpy"`` runs the plain array reference instead of the compiled kernel.
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
    return _reverse_one(T, tol=tol, s5_tol=s5_tol, backend=backend)


def reverse_pose(pose6, *, tol: float = 1e-9, s5_tol: float = 1e-10,
                 backend: str = "numba") -> ReverseResult:
    """:func:`reverse` for the pose of frame 6 given as a 4x4 matrix."""
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
    return _reverse_one(frame6(T[:3, 3], T[:3, 2], T[:3, 0]), tol=tol, s5_tol=s5_tol,
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


def _reverse_one(T: np.ndarray, *, tol: float, s5_tol: float,
                 backend: str = "numpy") -> ReverseResult:
    """The reference single-pose analysis: a batch of one, then duplicates removed in Python."""
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


# -- axis angles, limits, selection -----------------------------------------------------------
def to_axis_angles(q) -> np.ndarray:
    """Robot axis angles (radians) from joint angles: axis 1 = φ1 + π, others unchanged.

    The thesis's kinematic correction (Appendix D.2, Pos_A_KCorrection = 180°).
    """
    return np.asarray(q, dtype=float) + AXIS_OFFSET


def from_axis_angles(a) -> np.ndarray:
    """Joint angles (radians) from robot axis angles: φ1 = axis 1 − π wrapped to [-π, π), the
    other joints unchanged (their whole turns matter: axes 4 and 6 span more than 360°).

    Joint 1's axis range (320°) is less than a turn, so wrapping φ1 loses nothing;
    ``from_axis_angles(to_axis_angles(q)) == q`` for φ1 in [-π, π).
    """
    q = np.asarray(a, dtype=float) - AXIS_OFFSET
    return np.concatenate([_wrap(q[..., :1]), q[..., 1:]], axis=-1)


def _limits_rad(limits_deg) -> tuple[np.ndarray, np.ndarray]:
    L = np.asarray(AXIS_LIMITS_DEG if limits_deg is None else limits_deg, dtype=float)
    if L.shape != (6, 2) or not np.all(np.isfinite(L)) or np.any(L[:, 0] > L[:, 1]):
        raise InputError(f"axis limits must be 6 finite (lower, upper) pairs in degrees, "
                         f"got shape {L.shape}")
    return np.radians(L[:, 0]), np.radians(L[:, 1])


def wrap_into_limits(angles, current, lower, upper) -> tuple[np.ndarray, np.ndarray]:
    """Shift each angle by a multiple of 2π to the value nearest ``current`` inside its limits.

    All arrays broadcast; the last axis is the joint. Returns ``(wrapped, ok)`` where ``ok`` is
    False for a joint whose every shift is outside its limits (``wrapped`` is then the shift
    nearest ``current``).
    """
    a = np.asarray(angles, dtype=float)
    c = np.asarray(current, dtype=float)
    base = c + _wrap(a - c)
    ks = np.array([-2.0, -1.0, 0.0, 1.0, 2.0]) * _TWO_PI
    cand = base[..., None] + ks
    lo = np.asarray(lower, dtype=float)[..., None]
    hi = np.asarray(upper, dtype=float)[..., None]
    eps = 1e-12
    inside = (cand >= lo - eps) & (cand <= hi + eps)
    dist = np.where(inside, np.abs(cand - c[..., None]), np.inf)
    idx = np.argmin(dist, axis=-1)
    wrapped = np.take_along_axis(cand, idx[..., None], axis=-1)[..., 0]
    ok = np.isfinite(np.take_along_axis(dist, idx[..., None], axis=-1)[..., 0])
    return np.where(ok, wrapped, base), ok


def within_limits(q, limits_deg=None) -> np.ndarray:
    """True where some 2π-shift of every axis angle of ``q (..., 6)`` lies inside the limits."""
    q = _check_q(q)
    lo, hi = _limits_rad(limits_deg)
    _, ok = wrap_into_limits(to_axis_angles(q), np.zeros(6), lo, hi)
    return np.all(ok, axis=-1)


@dataclass(frozen=True, eq=False)
class Selection:
    """The selected solution(s) of :func:`select_batch`, batched like the poses.

    Attributes:
        q: ``(*B, 6)`` joint angles (radians) of the selected solution,
            ``from_axis_angles(axis)`` (φ1 in [-π, π); θ4, θ6 may exceed ±π).
        axis: ``(*B, 6)`` the robot axis angles to command (radians): each shifted by multiples
            of 2π to the value nearest the current one inside the limits.
        branch: ``(*B,)`` the branch index chosen (−1 when none).
        ok: ``(*B,)`` a solution within the limits exists.
        motion: ``(*B,)`` total axis motion Σ|Δaxis| (radians) from the current configuration.
        candidates_axis: ``(*B, 8, 6)`` every branch wrapped the same way (NaN if invalid).
        candidates_ok: ``(*B, 8)`` which branches are within the limits.
    """

    q: np.ndarray
    axis: np.ndarray
    branch: np.ndarray
    ok: np.ndarray
    motion: np.ndarray
    candidates_axis: np.ndarray
    candidates_ok: np.ndarray


def select_batch(batch: ReverseBatch, current_q=None, limits_deg=None, *,
                 current_axis=None) -> Selection:
    """Pick, for each pose, the branch nearest the current configuration within the axis limits.

    Each joint's angle is shifted by multiples of 2π to the value nearest the current one inside
    its limits (joints 4 and 6, ±266°, may sit more than half a turn away); the branch with the
    least total axis motion Σ|Δ| is chosen (the thesis's criterion, measured from the current
    configuration rather than from zero). On a wrist-singular branch the free motion is split
    evenly between joints 4 and 6.

    The current configuration is given either as joint angles ``current_q`` or, exactly as the
    controller reports it, as axis angles ``current_axis`` (``(*B, 6)`` or ``(6,)``, radians);
    neither means all axis angles zero (the thesis's choice). Joint angles do not say which
    turn axis 1 is on: its axis angle is taken inside the limits when possible.
    """
    lo, hi = _limits_rad(limits_deg)
    shape = batch.valid.shape[:-1]
    if current_q is not None and current_axis is not None:
        raise InputError("give the current configuration once: current_q or current_axis")
    if current_axis is not None:
        cur_axis = np.broadcast_to(_check_q(current_axis), shape + (6,))
    elif current_q is not None:
        cur_axis = to_axis_angles(_check_q(current_q)).copy()
        a1, _ = wrap_into_limits(cur_axis[..., 0], cur_axis[..., 0], lo[0], hi[0])
        cur_axis[..., 0] = a1
        cur_axis = np.broadcast_to(cur_axis, shape + (6,))
    else:
        cur_axis = np.zeros(shape + (6,))
    cur = cur_axis[..., None, :]  # (*B, 1, 6)
    a = to_axis_angles(np.where(batch.valid[..., None], batch.q, 0.0))
    # singular families: choose θ4, θ6 in the family, splitting the motion between them
    c4, c6 = cur[..., 3], cur[..., 5]
    fam = np.where(batch.singular, batch.family_value, 0.0)
    e_sum = _wrap(fam - (c4 + c6))
    e_dif = _wrap(fam - (c6 - c4))
    t4 = np.where(batch.family_sum, c4 + e_sum / 2, c4 - e_dif / 2)
    t6 = np.where(batch.family_sum, c6 + e_sum / 2, c6 + e_dif / 2)
    a = a.copy()
    a[..., 3] = np.where(batch.singular, t4, a[..., 3])
    a[..., 5] = np.where(batch.singular, t6, a[..., 5])
    wrapped, ok = wrap_into_limits(a, cur, lo, hi)
    cand_ok = np.all(ok, axis=-1) & batch.valid
    motion = np.where(cand_ok, np.sum(np.abs(wrapped - cur), axis=-1), np.inf)
    best = np.argmin(motion, axis=-1)
    any_ok = np.any(cand_ok, axis=-1)
    sel_axis = np.take_along_axis(wrapped, best[..., None, None], axis=-2)[..., 0, :]
    sel_axis = np.where(any_ok[..., None], sel_axis, np.nan)
    return Selection(
        q=from_axis_angles(sel_axis),
        axis=sel_axis,
        branch=np.where(any_ok, best, -1),
        ok=any_ok,
        motion=np.where(any_ok, np.take_along_axis(motion, best[..., None], axis=-1)[..., 0],
                        np.inf),
        candidates_axis=np.where(batch.valid[..., None], wrapped, np.nan),
        candidates_ok=cand_ok,
    )


def select(result: ReverseResult, current_q=None, limits_deg=None, *,
           current_axis=None) -> Selection:
    """:func:`select_batch` for one :class:`ReverseResult`; raises :class:`JointLimitError`
    when no solution (or family member) lies within the axis limits."""
    sel = select_batch(result.batch, current_q, limits_deg, current_axis=current_axis)
    if not bool(sel.ok):
        lo, hi = _limits_rad(limits_deg)
        worst = []
        for k in np.flatnonzero(result.batch.valid):
            ax = sel.candidates_axis[k]
            _, ok = wrap_into_limits(ax, ax, lo, hi)
            bad = [j + 1 for j in range(6) if not ok[j]]
            worst.append(f"branch {k}: axis {', '.join(map(str, bad))}")
        joint = None
        if worst:
            first = worst[0].split("axis ")[1].split(",")[0]
            joint = int(first)
        raise JointLimitError(
            "no PUMA 762 solution lies within the axis limits ("
            + "; ".join(worst)
            + "); leave the robot where it is or choose another pose",
            joint=joint,
        )
    return sel
