"""Reverse kinematics of the platform: leg vectors, lengths and lines from a pose, batched.

Leg ``i`` lies on the line ``{S_i; B_i × S_i}`` (Vibhute 2011 eq. A-7), ``S_i`` the unit vector
from the base point ``B_i`` to the top point, base frame; the line Jacobian ``j`` has these
lines as columns (eq. 2-6). They live here, below :mod:`~kinestat.parallel.statics` and
:mod:`~kinestat.parallel.singularity`, because the platform builder's design check needs them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from kinestat.errors import SingularityError
from kinestat.spatial.transforms import apply
from kinestat.spatial.validate import as_pose as _as_pose

if TYPE_CHECKING:  # the platform module imports this one (its design check)
    from kinestat.parallel.platform import Platform

_LAST_ROW_TOL = 1e-12  # poses computed here carry rounding in their last row at most

__all__ = ["as_pose", "top_points_in_base", "leg_vectors", "leg_lengths", "leg_directions",
           "leg_directions_trusted", "leg_lines", "line_jacobian",
           "line_jacobian_trusted"]


def as_pose(pose, name: str = "pose") -> np.ndarray:
    """Poses ``(..., 4, 4)`` checked by :func:`kinestat.spatial.validate.as_pose` (finite,
    rotation orthonormal with det +1 to 1e-6), the last row ``[0, 0, 0, 1]`` to 1e-12."""
    return _as_pose(pose, name, last_row_tol=_LAST_ROW_TOL)


def top_points_in_base(platform: Platform, pose) -> np.ndarray:
    """Top attachment points in base coordinates, ``(..., 6, 3)`` (Vibhute eq_wrench.m)."""
    T = as_pose(pose)
    return apply(T[..., None, :, :], platform.top_points)


def leg_vectors(platform: Platform, pose) -> np.ndarray:
    """Vectors from each base point to its top point, base frame, ``(..., 6, 3)``."""
    return top_points_in_base(platform, pose) - platform.base_points


def leg_lengths(platform: Platform, pose) -> np.ndarray:
    """Leg lengths ``(..., 6)`` of the platform at ``pose`` (the reverse kinematic analysis).

    At home they are the free lengths (the default of :func:`~kinestat.parallel.special_6_6`):

    >>> import numpy as np
    >>> from kinestat.parallel.platform import special_6_6
    >>> p = special_6_6()
    >>> bool(np.allclose(leg_lengths(p, p.home_pose), p.free_lengths))
    True
    """
    return np.linalg.norm(leg_vectors(platform, pose), axis=-1)


def leg_directions(platform: Platform, pose) -> tuple[np.ndarray, np.ndarray]:
    """Unit leg directions S_i (base → top) (..., 6, 3) and leg lengths (..., 6)."""
    return leg_directions_trusted(platform, as_pose(pose))


def leg_directions_trusted(platform: Platform, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`leg_directions` of poses ``T`` (..., 4, 4) the caller has checked (float arrays,
    rigid): no validation, the same values (the hot path of a control cycle)."""
    d = apply(T[..., None, :, :], platform.top_points) - platform.base_points
    l = np.linalg.norm(d, axis=-1)
    if np.any(l <= 0):
        raise SingularityError("a leg has zero length at this pose: its line is undefined")
    return d / l[..., None], l


def leg_lines(platform: Platform, pose) -> np.ndarray:
    """Plücker coordinates ``{S_i; B_i × S_i}`` of the six legs, (..., 6 legs, 6) (eq. A-7)."""
    S, _ = leg_directions(platform, pose)
    return np.concatenate([S, np.cross(platform.base_points, S)], axis=-1)


def line_jacobian(platform: Platform, pose) -> np.ndarray:
    """The line Jacobian ``j`` (..., 6, 6), columns ``[S_i; B_i × S_i]`` (Vibhute eq. 2-6).

    >>> from kinestat.parallel.platform import special_6_6
    >>> p = special_6_6()
    >>> line_jacobian(p, p.home_pose).shape
    (6, 6)
    """
    return np.swapaxes(leg_lines(platform, pose), -1, -2)


def line_jacobian_trusted(platform: Platform, T: np.ndarray) -> np.ndarray:
    """:func:`line_jacobian` of poses ``T`` (..., 4, 4) the caller has checked (float arrays,
    rigid; e.g. the pose forward kinematics just returned): no validation, compiled
    (:func:`kinestat.parallel._fk_kernels.line_jacobian_kernel`; equal to it to rounding).

    Raises:
        SingularityError: a leg has zero length (its line is undefined).
    """
    from kinestat.parallel import _fk_kernels  # lazy: numba (~0.5 s) at start-up

    T = np.ascontiguousarray(T, dtype=float).view()
    T.flags.writeable = False  # one argument type (read-only, like the platform's points)
    j = np.empty(T.shape[:-2] + (6, 6))
    if not _fk_kernels.line_jacobian_kernel(platform.base_points, platform.top_points,
                                            T.reshape(-1, 4, 4), j.reshape(-1, 6, 6)):
        raise SingularityError("a leg has zero length at this pose: its line is undefined")
    return j
