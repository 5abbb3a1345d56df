"""The Jacobian in the twist form of Nadkarni eq. 4-11, batched.

Column j is ``[u_j; h_j u_j − u_j × ρ_j]`` for revolute (h = 0) and screw joints, and
``[0; u_j]`` for prismatic joints, where ``u_j`` is the unit joint axis and ``ρ_j`` any point
on it, both in the base frame. With twists ``[ω; v_O]`` (v_O the velocity of the point at the
origin), ``J(q) · δq = B`` is Nadkarni's eq. 4-11 literally.
"""

from __future__ import annotations

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.fk import fk_frames

__all__ = ["jacobian", "jacobian_from_frames"]


def jacobian_from_frames(model: ChainModel, frames: np.ndarray) -> np.ndarray:
    """Jacobian ``(..., 6, n)`` from the link frames returned by :func:`fk_frames`."""
    F = frames[..., :-1, :, :]
    u = F[..., :3, 2]
    rho = F[..., :3, 3]
    h = model.pitches[:, None]
    pris = model.prismatic[:, None]
    w = np.where(pris, 0.0, u)
    v = np.where(pris, u, h * u - np.cross(u, rho))
    return np.swapaxes(np.concatenate([w, v], axis=-1), -1, -2)


def jacobian(model: ChainModel, q) -> np.ndarray:
    """Space Jacobian ``(..., 6, n)`` mapping joint rates to the end twist ``[ω; v_O]``."""
    return jacobian_from_frames(model, fk_frames(model, q))
