"""PUMA 762 forward analysis and the end effector as a frame (Vibhute eqs. 2-26..2-34,
Appendix D.3): ``F_6T(q)`` by the link product, the thesis's end-effector description
(``P_tool_F``, ``S6_F``, ``a67_F``) and the wrist centre."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError
from kinestat.robots.puma762 import _cycle_kernels as _ck
from kinestat.robots.puma762 import _kernels as _pk
from kinestat.robots.puma762.params import _A, _CA, _S, _SA, S6
from kinestat.spatial.se3 import pose_error
from kinestat.spatial.validate import as_vector3

__all__ = ["link_transform", "ForwardResult", "forward", "pose_one", "frame6", "wrist_center",
           "pose_residuals"]

def link_transform(cos_alpha, sin_alpha, a, theta, s) -> np.ndarray:
    """``iT_j = Rx(α_ij) Tx(a_ij) Rz(θ_j) Tz(S_j)``, batched over ``theta`` (Vibhute eq. 2-26).

    Takes cos α and sin α (so that 270° is exact) and θ in radians.

    >>> link_transform(0.0, 1.0, 0.0, 0.0, 190.0) + 0.0  # link 1-2: α12 = 90°, S2 = 190
    array([[   1.,    0.,    0.,    0.],
           [   0.,    0.,   -1., -190.],
           [   0.,    1.,    0.,    0.],
           [   0.,    0.,    0.,    1.]])
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

    >>> f = forward(np.zeros((4, 6)))
    >>> f.tool_point.shape, f.pose.shape
    ((4, 3), (4, 4, 4))
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
    return as_vector3(v, name)


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

    Returns the tool point ``P_tool_F = F_6T · P_tool_6``, ``S6_F``, ``a67_F`` and the pose
    ``F_6T`` (frame 6 in the fixed frame F; the generic :func:`kinestat.fk` of the
    ``puma762`` model gives the same pose).

    >>> f = forward(np.zeros(6))
    >>> np.round(f.tool_point, 9) + 0.0  # a23 along x, S2 to the side, S4 − S6 up
    array([ 650., -190.,  475.])
    >>> f.s6 + 0.0, f.a67 + 0.0
    (array([ 0.,  0., -1.]), array([1., 0., 0.]))
    """
    q = _check_q(q)
    p6 = _check_vec3(tool_point_6, "tool_point_6")
    T = _pose_06(q)
    tool = np.einsum("...ij,...j->...i", T[..., :3, :3], p6) + T[..., :3, 3]
    return ForwardResult(tool_point=tool, s6=T[..., :3, 2].copy(), a67=T[..., :3, 0].copy(),
                         pose=T)


def pose_one(q) -> np.ndarray:
    """``F_6T`` (4, 4) of one configuration ``q`` (6,) (eq. 2-33), compiled: the pose
    :func:`forward` returns, the same operations in the same order (the single-pose path of
    a control cycle; ``q`` finite, checked by the caller).

    >>> bool(np.array_equal(pose_one(np.full(6, 0.3)), forward(np.full(6, 0.3)).pose))
    True
    """
    q = np.asarray(q, dtype=float)
    T = np.empty((4, 4))
    _ck.pose_one(np.stack([np.cos(q), np.sin(q)], axis=-1), T)
    return T


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

    >>> T_F_6 = frame6([650.0, -190.0, 475.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0])
    >>> bool(np.allclose(T_F_6, forward(np.zeros(6)).pose))
    True
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
    """The wrist centre (intersection of S4, S5, S6): frame 6's origin minus S6 · S6_F.

    >>> np.round(wrist_center(forward(np.zeros(6)).pose), 9) + 0.0
    array([ 650., -190.,  600.])
    """
    T = np.asarray(pose6, dtype=float)
    return T[..., :3, 3] - S6 * T[..., :3, 2]


def pose_residuals(q, pose6) -> tuple[np.ndarray, np.ndarray]:
    """Position error (mm) of frame 6's origin and rotation angle (rad), F_6T(q) against pose6:
    :func:`kinestat.spatial.se3.pose_error` (``2 asin(|R − R_t|_F / (2√2))``).

    >>> pos, rot = pose_residuals(np.zeros(6), forward(np.zeros(6)).pose)
    >>> float(pos), float(rot)
    (0.0, 0.0)
    """
    return pose_error(_pose_06(np.asarray(q, dtype=float)), pose6)
