"""Reverse kinematics of the platform: leg vectors and leg lengths from a pose, batched."""

from __future__ import annotations

import numpy as np

from kinestat.errors import InputError
from kinestat.parallel.platform import Platform
from kinestat.spatial.transforms import apply, as_array

__all__ = ["as_pose", "top_points_in_base", "leg_vectors", "leg_lengths"]


def as_pose(pose, name: str = "pose") -> np.ndarray:
    """Check and convert poses ``(..., 4, 4)``: finite, rigid (orthonormal, det +1)."""
    T = as_array(pose, shape_tail=(4, 4), name=name)
    R = T[..., :3, :3]
    err = np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)).max(axis=(-1, -2), initial=0.0)
    det = np.linalg.det(R)
    bad_rot = (err > 1e-6) | (np.abs(det - 1.0) > 1e-6)
    bad_row = np.abs(T[..., 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=-1) > 1e-12

    def first(bad: np.ndarray) -> tuple[tuple[int, ...], str]:
        if T.ndim == 2:
            return (), ""
        i = tuple(int(k) for k in np.argwhere(bad)[0])
        return i, f" at batch index {i}"

    if np.any(bad_row):
        _, where = first(bad_row)
        raise InputError(f"{name} is not a rigid transform{where}: its last row must be 0 0 0 1")
    if np.any(bad_rot):
        i, where = first(bad_rot)
        raise InputError(
            f"{name} is not a rigid transform{where}: its rotation part has max|R R^T - I| = "
            f"{float(err[i]):.2g} and det = {float(det[i]):.6g}; it must be orthonormal with "
            "det +1 (tolerance 1e-06: give the rotation to enough digits)")
    return T


def top_points_in_base(platform: Platform, pose) -> np.ndarray:
    """Top attachment points in base coordinates, ``(..., 6, 3)`` (Vibhute eq_wrench.m)."""
    T = as_pose(pose)
    return apply(T[..., None, :, :], platform.top_points)


def leg_vectors(platform: Platform, pose) -> np.ndarray:
    """Vectors from each base point to its top point, base frame, ``(..., 6, 3)``."""
    return top_points_in_base(platform, pose) - platform.base_points


def leg_lengths(platform: Platform, pose) -> np.ndarray:
    """Leg lengths ``(..., 6)`` of the platform at ``pose`` (the reverse kinematic analysis)."""
    return np.linalg.norm(leg_vectors(platform, pose), axis=-1)
