"""SO(3)/SE(3) exponential and logarithm and the pose error — one formula each, batch-first.

Twists are ``[ω; v_O]`` ``(..., 6)``: angular velocity and the velocity of the body point at the
origin (Nadkarni eq. 4-11; Modern Robotics' spatial twist). Rotation vectors are axis × angle
``(..., 3)``. Poses ``(..., 4, 4)`` are named by their frames in calling code (``T_base_tool``).
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.spatial.displacement import pose_from_screw
from kinestat.spatial.transforms import as_array, trans
from kinestat.spatial.validate import as_pose, as_rotation, as_vector3

__all__ = ["so3_exp", "so3_exp_trusted", "so3_log", "twist_exp", "twist_exp_one",
           "rotvec_matrix_one", "pose_error"]


def so3_exp(w) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of rotation vectors ``w (..., 3)`` (Rodrigues' formula,
    ``R = I + sinθ/θ [w] + (1 − cosθ)/θ² [w]²``, Taylor terms below θ = 1e-8).

    >>> np.round(so3_exp([0.0, 0.0, np.pi / 2]), 12) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    return so3_exp_trusted(as_vector3(w, "w"))


def so3_exp_trusted(w: np.ndarray) -> np.ndarray:
    """:func:`so3_exp` of float rotation vectors ``(..., 3)`` the caller has checked (no
    validation; the Newton steps of the platform solvers)."""
    th = np.sqrt(np.sum(w * w, axis=-1))
    small = th < 1e-8
    safe = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th**2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - th**2 / 24.0, (1.0 - np.cos(safe)) / safe**2)
    K = np.zeros(w.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2] = -w[..., 2], w[..., 1]
    K[..., 1, 0], K[..., 1, 2] = w[..., 2], -w[..., 0]
    K[..., 2, 0], K[..., 2, 1] = -w[..., 1], w[..., 0]
    return np.eye(3) + a[..., None, None] * K + b[..., None, None] * (K @ K)


def so3_log(R) -> np.ndarray:
    """Rotation vectors ``(..., 3)`` (axis × angle, angle in [0, π]) of rotations ``(..., 3, 3)``:
    the SO(3) logarithm, via SciPy's ``Rotation.as_rotvec``.

    >>> np.round(so3_log(so3_exp([0.1, -0.2, 0.3])), 12)
    array([ 0.1, -0.2,  0.3])
    """
    from scipy.spatial.transform import Rotation  # lazy: start-up (scipy.spatial ~0.5 s)
    R = as_rotation(R, "R")
    flat = R.reshape(-1, 3, 3)
    if flat.shape[0] == 0:
        return np.zeros(R.shape[:-2] + (3,))
    return Rotation.from_matrix(flat).as_rotvec().reshape(R.shape[:-2] + (3,))


def twist_exp(V) -> np.ndarray:
    """Rigid displacement ``(..., 4, 4)`` produced by the twist ``V = [ω; v_O]`` ``(..., 6)``
    (the matrix exponential of :func:`kinestat.spatial.screws.twist_matrix`), via its screw:
    θ = |ω|, u = ω/θ, d = u·v, ρn = ω×v/θ² (Nadkarni eqs. 4-19a read backwards); a pure
    translation when ω = 0.

    >>> D = twist_exp([0.0, 0.0, np.pi / 2, 0.0, 0.0, 0.0])
    >>> np.round(D @ [1.0, 0.0, 0.0, 1.0], 12) + 0.0
    array([0., 1., 0., 1.])
    >>> twist_exp([0.0, 0.0, 0.0, 1.0, 2.0, 3.0])[:3, 3]
    array([1., 2., 3.])
    """
    V = as_array(V, shape_tail=(6,), name="twist")
    w, v = V[..., :3], V[..., 3:]
    th = np.linalg.norm(w, axis=-1)
    rot = th > 1e-15
    ths = np.where(rot, th, 1.0)
    u = np.where(rot[..., None], w / ths[..., None], np.array([0.0, 0.0, 1.0]))
    d = np.sum(u * v, axis=-1)
    point = np.where(rot[..., None], np.cross(w, v) / (ths**2)[..., None], 0.0)
    D = pose_from_screw(u, point, np.where(rot, th, 0.0), np.where(rot, d, 0.0))
    return np.where(rot[..., None, None], D, trans(v))


def _rodrigues(u0: float, u1: float, u2: float, s: float, h2: float) -> list[list[float]]:
    """``I + s [u]x + h2 [u]x²`` for a unit axis u (Rodrigues; h2 = 1 − cos θ)."""
    return [[1.0 - h2 * (u1 * u1 + u2 * u2), -s * u2 + h2 * u0 * u1, s * u1 + h2 * u0 * u2],
            [s * u2 + h2 * u0 * u1, 1.0 - h2 * (u0 * u0 + u2 * u2), -s * u0 + h2 * u1 * u2],
            [-s * u1 + h2 * u0 * u2, s * u0 + h2 * u1 * u2, 1.0 - h2 * (u0 * u0 + u1 * u1)]]


def twist_exp_one(V) -> np.ndarray:
    """:func:`twist_exp` of ONE finite twist ``V = [ω; v_O]`` (6,), in scalars: the same screw
    (θ = |ω|, u = ω/θ, d = u·v, the axis through ω×v/θ²) and Rodrigues' formula, without the
    batched validation (a control cycle's hot path); equal to :func:`twist_exp` to rounding.

    >>> bool(np.allclose(twist_exp_one([0.1, -0.2, 0.3, 1.0, 2.0, 3.0]),
    ...                  twist_exp([0.1, -0.2, 0.3, 1.0, 2.0, 3.0]), rtol=0, atol=1e-14))
    True
    """
    w0, w1, w2, v0, v1, v2 = np.asarray(V, dtype=float).tolist()
    th = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    out = np.eye(4)
    if not th > 1e-15:
        out[:3, 3] = (v0, v1, v2)
        return out
    u0, u1, u2 = w0 / th, w1 / th, w2 / th
    d = u0 * v0 + u1 * v1 + u2 * v2
    t2 = th * th
    c0, c1, c2 = (w1 * v2 - w2 * v1) / t2, (w2 * v0 - w0 * v2) / t2, (w0 * v1 - w1 * v0) / t2
    cu = c0 * u0 + c1 * u1 + c2 * u2
    c0, c1, c2 = c0 - cu * u0, c1 - cu * u1, c2 - cu * u2  # the axis point normal to u
    s, h2 = math.sin(th), 2.0 * math.sin(0.5 * th) ** 2
    out[:3, :3] = _rodrigues(u0, u1, u2, s, h2)
    out[:3, 3] = (h2 * c0 - s * (u1 * c2 - u2 * c1) + d * u0,
                  h2 * c1 - s * (u2 * c0 - u0 * c2) + d * u1,
                  h2 * c2 - s * (u0 * c1 - u1 * c0) + d * u2)
    return out


def rotvec_matrix_one(r) -> np.ndarray:
    """The rotation matrix (3, 3) of ONE rotation vector ``r`` (3,) (radians): Rodrigues'
    formula in scalars, equal to SciPy's ``Rotation.from_rotvec(r).as_matrix()`` to rounding.

    >>> bool(np.allclose(rotvec_matrix_one([0.0, 0.0, np.pi / 2]),
    ...                  [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15))
    True
    """
    r0, r1, r2 = np.asarray(r, dtype=float).tolist()
    th = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
    if not th > 0.0:
        return np.eye(3)
    s, h2 = math.sin(th), 2.0 * math.sin(0.5 * th) ** 2
    return np.array(_rodrigues(r0 / th, r1 / th, r2 / th, s, h2))


_SQRT8 = 2.0 * math.sqrt(2.0)


def pose_error(T, T_target) -> tuple[np.ndarray, np.ndarray]:
    """Position distance and rotation angle between poses ``(..., 4, 4)`` (broadcast).

    The one pose-error formula of kinestat (also in the compiled kernels): the distance
    ``|p − p_t|`` between the origins and the angle ``θ = 2 asin(|R − R_t|_F / (2√2))`` of
    ``R_tᵀ R`` (``|R − R_t|_F² = 8 sin²(θ/2)``: exact, accurate at small angles, ~1e-8 near π).
    Both numbers are the same whether the error is seen in the base frame or the body frame, so
    there is no frame argument.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> pos, rot = pose_error(trans([3.0, 4.0, 0.0]) @ rot_z(0.25), np.eye(4))
    >>> float(pos), round(float(rot), 12)
    (5.0, 0.25)
    """
    T = as_pose(T, "T")
    Tt = as_pose(T_target, "T_target")
    pos = np.linalg.norm(T[..., :3, 3] - Tt[..., :3, 3], axis=-1)
    d = np.sqrt(np.sum((T[..., :3, :3] - Tt[..., :3, :3]) ** 2, axis=(-1, -2)))
    rot = 2.0 * np.arcsin(np.minimum(d / _SQRT8, 1.0))
    return pos, rot
