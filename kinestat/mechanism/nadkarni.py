"""Nadkarni's description of a mechanism in the global frame (DISP's TRANSM, MS = 2).

For every joint i of a mechanism given in Nadkarni's notation (r_i, α_i, a_i, θ_i, pitch) and
placed by three points on x*(1) (SET FIVE):

- x*(i): origin at the intersection of the ith normal with the ith axis, z along axis i,
  x along normal i;  x*(i) = x(i-1) · Rz(θi) · Tz(ri)  (eq. 2-3)
- x(i):  origin at the intersection of normal i with axis i+1, z along axis i+1;
  x(i) = x*(i) · Tx(ai) · Rx(αi)  (eq. 2-1)
- U(i): unit vector along axis i (eqs. 2-16 to 2-18); ρn(i): foot of the perpendicular from
  the global origin to axis i.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinestat.errors import ModelError
from kinestat.mechanism.chain import frame_from_three_points
from kinestat.spatial.transforms import inv, rot_x, rot_z, trans_x, trans_z
from kinestat.spatial.validate import as_pose

__all__ = ["MechanismFrames", "mechanism_frames", "hand_points"]


@dataclass(frozen=True)
class MechanismFrames:
    """Frames and axes of every joint, in the global frame (arrays batch-first).

    ``x_star`` and ``x`` are ``(..., N, 4, 4)``; ``origin_star``/``origin`` ``(..., N, 3)`` are
    their origins X*(i), X(i); ``axis`` U(i) and ``normal`` ρn(i) are ``(..., N, 3)``.

    >>> SET_FIVE = [[0, 0, 0], [0, 0, 1], [1, 0, 0]]  # x*(1) at the origin, z up, x along x
    >>> f = mechanism_frames([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]], SET_FIVE)
    >>> f.origin_star, f.axis
    (array([[0., 0., 0.],
           [1., 0., 0.]]), array([[0., 0., 1.],
           [0., 0., 1.]]))
    """

    x_star: np.ndarray
    x: np.ndarray

    @property
    def origin_star(self) -> np.ndarray:
        return self.x_star[..., :3, 3]

    @property
    def origin(self) -> np.ndarray:
        return self.x[..., :3, 3]

    @property
    def axis(self) -> np.ndarray:
        return self.x_star[..., :3, 2]

    @property
    def normal(self) -> np.ndarray:
        p, u = self.origin_star, self.axis
        return p - np.sum(p * u, axis=-1, keepdims=True) * u


def mechanism_frames(rows, frame_points, initial_rows=None) -> MechanismFrames:
    """x*(i) and x(i) of every joint (Nadkarni ch. II; DISP TRANSM).

    Args:
        rows: ``(..., N, 4+)`` current (r, alpha, a, theta[, pitch]) per joint, angles in radians.
        frame_points: SET FIVE, three points on x*(1) in the initial configuration.
        initial_rows: the configuration in which SET FIVE was measured (default: ``rows``).
            x*(0) is x*(1) there; a later θ1/r1 moves x*(1) about/along x*(0)'s z (eq. 2-13).

    >>> SET_FIVE = [[0, 0, 0], [0, 0, 1], [1, 0, 0]]
    >>> f = mechanism_frames([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, np.pi / 2]], SET_FIVE)
    >>> np.round(f.origin, 12) + 0.0
    array([[1., 0., 0.],
           [1., 1., 0.]])
    """
    R = np.asarray(rows, dtype=float)
    if R.ndim < 2 or R.shape[-1] < 4:
        raise ModelError(f"mechanism rows must be (..., N, 4 or 5), got {R.shape}")
    R0 = R if initial_rows is None else np.asarray(initial_rows, dtype=float)
    fp = np.asarray(frame_points, dtype=float)
    xstar0 = frame_from_three_points(fp[0], fp[1], fp[2], what="SET FIVE frame points")
    base = xstar0 @ inv(rot_z(R0[..., 0, 3]) @ trans_z(R0[..., 0, 0]))  # x(0)
    r, alpha, a, theta = R[..., 0], R[..., 1], R[..., 2], R[..., 3]
    head = rot_z(theta) @ trans_z(r)  # x(i-1) -> x*(i)
    tail = trans_x(a) @ rot_x(alpha)  # x*(i) -> x(i)
    N = R.shape[-2]
    xs = np.empty(R.shape[:-1] + (4, 4))
    xx = np.empty_like(xs)
    T = np.broadcast_to(base, R.shape[:-2] + (4, 4))
    for i in range(N):
        T = T @ head[..., i, :, :]
        xs[..., i, :, :] = T
        T = T @ tail[..., i, :, :]
        xx[..., i, :, :] = T
    return MechanismFrames(x_star=xs, x=xx)


def hand_points(hand_pose) -> np.ndarray:
    """The three hand points DISP reports: origin, unit point on +z, unit point on +x.

    Returns ``(..., 3, 3)`` (rows are points), the form of a SET TWO body position.

    >>> hand_points(np.eye(4))
    array([[0., 0., 0.],
           [0., 0., 1.],
           [1., 0., 0.]])
    """
    T = as_pose(hand_pose, "hand_pose")
    o = T[..., :3, 3]
    return np.stack([o, o + T[..., :3, 2], o + T[..., :3, 0]], axis=-2)
