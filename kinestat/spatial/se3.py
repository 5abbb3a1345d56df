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

__all__ = ["so3_exp", "so3_log", "twist_exp", "pose_error"]


def so3_exp(w) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of rotation vectors ``w (..., 3)`` (Rodrigues' formula,
    ``R = I + sinθ/θ [w] + (1 − cosθ)/θ² [w]²``, Taylor terms below θ = 1e-8).

    >>> np.round(so3_exp([0.0, 0.0, np.pi / 2]), 12) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    w = np.asarray(w, dtype=float)
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
    R = np.asarray(R, dtype=float)
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
    T = np.asarray(T, dtype=float)
    Tt = np.asarray(T_target, dtype=float)
    pos = np.linalg.norm(T[..., :3, 3] - Tt[..., :3, 3], axis=-1)
    d = np.sqrt(np.sum((T[..., :3, :3] - Tt[..., :3, :3]) ** 2, axis=(-1, -2)))
    rot = 2.0 * np.arcsin(np.minimum(d / _SQRT8, 1.0))
    return pos, rot
