"""Homogeneous transforms and rotations, batch-first.

Poses are arrays of shape ``(..., 4, 4)``; rotations ``(..., 3, 3)``; points and vectors
``(..., 3)``. Every function broadcasts over leading dimensions.
"""

from __future__ import annotations

import numpy as np

from kinestat.errors import InputError

__all__ = [
    "as_array",
    "rot_x",
    "rot_y",
    "rot_z",
    "trans",
    "trans_x",
    "trans_z",
    "make_pose",
    "inv",
    "compose",
    "apply",
    "apply_vector",
    "rotation",
    "translation",
    "is_rotation",
    "skew",
    "cross3",
    "apply_one",
]


def as_array(x, *, shape_tail: tuple[int, ...] = (), name: str = "value",
             finite: bool = True) -> np.ndarray:
    """Convert to a float64 array, checking the trailing shape and (unless ``finite`` is
    False) finiteness.

    >>> as_array([1, 2], name='q')
    array([1., 2.])
    """
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:  # strings, ragged lists, None in a list...
        raise InputError(f"{name} must be an array of numbers: {exc}") from exc
    if shape_tail and a.shape[a.ndim - len(shape_tail):] != shape_tail:
        raise InputError(f"{name} must have trailing shape {shape_tail}, got {a.shape}")
    if finite and not np.all(np.isfinite(a)):
        raise InputError(f"{name} contains NaN or infinity")
    return a


def _rot(angle, axis: int) -> np.ndarray:
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    out = np.zeros(a.shape + (4, 4))
    out[..., 3, 3] = 1.0
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out[..., axis, axis] = 1.0
    out[..., i, i] = c
    out[..., j, j] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    return out


def rot_x(angle) -> np.ndarray:
    """4x4 rotation about x by ``angle`` (radians), batched over ``angle``.

    >>> np.round(rot_x(np.pi / 2) @ [0.0, 1.0, 0.0, 1.0], 12) + 0.0
    array([0., 0., 1., 1.])
    """
    return _rot(angle, 0)


def rot_y(angle) -> np.ndarray:
    """4x4 rotation about y by ``angle`` (radians), batched over ``angle``.

    >>> np.round(rot_y(np.pi / 2) @ [0.0, 0.0, 1.0, 1.0], 12) + 0.0
    array([1., 0., 0., 1.])
    """
    return _rot(angle, 1)


def rot_z(angle) -> np.ndarray:
    """4x4 rotation about z by ``angle`` (radians), batched over ``angle``.

    >>> rot_z([0.0, 0.5, 1.0]).shape
    (3, 4, 4)
    """
    return _rot(angle, 2)


def trans(p) -> np.ndarray:
    """4x4 pure translation by the vector(s) ``p`` of shape ``(..., 3)``.

    >>> trans([1.0, 2.0, 3.0])[:3, 3]
    array([1., 2., 3.])
    """
    p = np.asarray(p, dtype=float)
    out = np.zeros(p.shape[:-1] + (4, 4))
    out[..., [0, 1, 2, 3], [0, 1, 2, 3]] = 1.0
    out[..., :3, 3] = p
    return out


def trans_x(d) -> np.ndarray:
    """4x4 translation along x by ``d``.

    >>> trans_x(2.0)[:3, 3]
    array([2., 0., 0.])
    """
    d = np.asarray(d, dtype=float)
    return trans(np.stack([d, np.zeros_like(d), np.zeros_like(d)], axis=-1))


def trans_z(d) -> np.ndarray:
    """4x4 translation along z by ``d``.

    >>> trans_z(2.0)[:3, 3]
    array([0., 0., 2.])
    """
    d = np.asarray(d, dtype=float)
    return trans(np.stack([np.zeros_like(d), np.zeros_like(d), d], axis=-1))


def make_pose(R, p) -> np.ndarray:
    """Pose from rotation ``(..., 3, 3)`` and translation ``(..., 3)``.

    >>> make_pose(np.eye(3), [1.0, 2.0, 3.0])[:, 3]
    array([1., 2., 3., 1.])
    """
    R = np.asarray(R, dtype=float)
    p = np.asarray(p, dtype=float)
    shape = np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    out = np.zeros(shape + (4, 4))
    out[..., :3, :3] = R
    out[..., :3, 3] = p
    out[..., 3, 3] = 1.0
    return out


def rotation(T) -> np.ndarray:
    """Rotation part ``(..., 3, 3)`` of poses.

    >>> rotation(trans([1.0, 2.0, 3.0])).shape
    (3, 3)
    """
    return np.asarray(T)[..., :3, :3]


def translation(T) -> np.ndarray:
    """Translation part ``(..., 3)`` of poses.

    >>> translation(trans([1.0, 2.0, 3.0]))
    array([1., 2., 3.])
    """
    return np.asarray(T)[..., :3, 3]


def inv(T) -> np.ndarray:
    """Inverse of rigid transforms, ``[R p; 0 1]^-1 = [R^T, -R^T p; 0 1]``.

    >>> T_base_tool = trans([1.0, 2.0, 3.0]) @ rot_z(0.3)
    >>> bool(np.allclose(inv(T_base_tool) @ T_base_tool, np.eye(4)))
    True
    """
    T = as_array(T, name="T", finite=False)
    if T.shape[-2:] != (4, 4):  # the rigidity is the caller's (kinestat.spatial.validate)
        raise InputError(f"T must be 4x4 transforms of shape (..., 4, 4), got shape {T.shape}")
    R = T[..., :3, :3]
    Rt = np.swapaxes(R, -1, -2)
    return make_pose(Rt, -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3]))


def compose(*Ts) -> np.ndarray:
    """Product ``T1 @ T2 @ ...`` with broadcasting over leading dimensions.

    >>> compose(trans([1.0, 0.0, 0.0]), trans([0.0, 2.0, 0.0]))[:3, 3]
    array([1., 2., 0.])
    """
    out = np.asarray(Ts[0], dtype=float)
    for T in Ts[1:]:
        out = out @ np.asarray(T, dtype=float)
    return out


def apply(T, points) -> np.ndarray:
    """Transform points ``(..., 3)`` by poses ``(..., 4, 4)``.

    >>> apply(trans([1.0, 0.0, 0.0]), [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    array([[1., 0., 0.],
           [2., 1., 1.]])
    """
    T = np.asarray(T, dtype=float)
    points = np.asarray(points, dtype=float)
    return np.einsum("...ij,...j->...i", T[..., :3, :3], points) + T[..., :3, 3]


def apply_vector(T, vectors) -> np.ndarray:
    """Rotate free vectors ``(..., 3)`` by the rotation part of poses.

    >>> apply_vector(trans([1.0, 0.0, 0.0]), [0.0, 0.0, 1.0])
    array([0., 0., 1.])
    """
    T = np.asarray(T, dtype=float)
    return np.einsum("...ij,...j->...i", T[..., :3, :3], np.asarray(vectors, dtype=float))


def is_rotation(R, tol: float = 1e-9) -> np.ndarray:
    """True where ``R`` is orthonormal with determinant +1 (to ``tol``).

    >>> bool(is_rotation(rot_z(0.5)[:3, :3])), bool(is_rotation(2 * np.eye(3)))
    (True, False)
    """
    R = np.asarray(R, dtype=float)
    eye = np.eye(3)
    ortho = np.max(np.abs(R @ np.swapaxes(R, -1, -2) - eye), axis=(-1, -2)) <= tol
    return ortho & (np.abs(np.linalg.det(R) - 1.0) <= tol)


def skew(v) -> np.ndarray:
    """Skew-symmetric matrices ``[v]x`` of shape ``(..., 3, 3)`` with ``[v]x w = v x w``.

    >>> skew([1.0, 2.0, 3.0]) @ [4.0, 5.0, 6.0]  # = (1, 2, 3) x (4, 5, 6)
    array([-3.,  6., -3.])
    """
    v = np.asarray(v, dtype=float)
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1] = -v[..., 2]
    out[..., 0, 2] = v[..., 1]
    out[..., 1, 0] = v[..., 2]
    out[..., 1, 2] = -v[..., 0]
    out[..., 2, 0] = -v[..., 1]
    out[..., 2, 1] = v[..., 0]
    return out


def cross3(a, b) -> np.ndarray:
    """``a × b`` of two 3-vectors (no batch): :func:`numpy.cross`'s products and differences,
    the same values, without its broadcasting set-up (~1 µs instead of ~8-14 µs); for the
    per-cycle code of the controller.

    >>> cross3([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]).tolist()
    [-3.0, 6.0, -3.0]
    """
    a0, a1, a2 = np.asarray(a, dtype=float).tolist()
    b0, b1, b2 = np.asarray(b, dtype=float).tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def apply_one(T, point) -> np.ndarray:
    """:func:`apply` for ONE pose (4, 4) and ONE point (3,) (no batch), in scalars: each row
    summed as ``(r0 x + r2 z) + r1 y``, the order NumPy's ``einsum`` sums a 3-term row in on
    the reference machine (x86-64), so equal to :func:`apply` bit for bit there and to
    rounding elsewhere; ~0.8 µs instead of ~2 µs (the control cycle's hot path).

    >>> apply_one(trans([1.0, 0.0, 0.0]), [1.0, 1.0, 1.0]).tolist()
    [2.0, 1.0, 1.0]
    """
    (a, b, c, d), (e, f, g, h), (i, j, k, m) = np.asarray(T, dtype=float)[:3].tolist()
    x, y, z = np.asarray(point, dtype=float).tolist()
    return np.array([(a * x + c * z) + b * y + d, (e * x + g * z) + f * y + h,
                     (i * x + k * z) + j * y + m])
