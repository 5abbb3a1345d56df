"""Joint rates from the displacement analysis (Nadkarni ch. V, suggestion 1, eqs. 5-1 to 5-4).

A displacement step gives joint increments δθ_j (δr_j for prismatic joints) for a hand rotation
δθ; for a small interval they are proportional to the rates, so

    |W_j| = (δθ_j / δθ) |W_H|   (5-1, 5-3),     |V_j| = (δr_j / δθ) |W_H|   (5-2, 5-4),

and, for a pure translation of the hand, |W_H| and δθ are replaced by |V_H| and δr.
"""

from __future__ import annotations

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.guidance.step import characteristic_length, solve_step
from kinestat.serial.jacobian import jacobian
from kinestat.spatial.transforms import as_array

__all__ = ["joint_rates"]


def joint_rates(model: ChainModel, q, twist, speed, *, angle_tol: float = 1e-12) -> np.ndarray:
    """Joint rates ``(..., n)`` that move the hand along ``twist`` at ``speed``.

    Args:
        q: joint values ``(..., n)``.
        twist: the direction of the hand motion ``[ω; v_O]`` ``(..., 6)`` in any scale (e.g. a
            step's B).
        speed: the hand's angular speed |W_H| (rad per unit time) — or, when the twist is a pure
            translation (|ω| ≤ ``angle_tol``·|v|), the speed |V_H| of the hand (length per unit
            time).

    Returns rad per unit time for revolute and screw joints, length per unit time for
    prismatic ones (eqs. 5-1 to 5-4).
    """
    q = model.check_q(q)
    V = as_array(twist, shape_tail=(6,), name="twist")
    speed = as_array(speed, name="speed")
    if np.any(speed < 0):
        raise InputError("speed must be ≥ 0")
    w = np.linalg.norm(V[..., :3], axis=-1)
    v = np.linalg.norm(V[..., 3:], axis=-1)
    if np.any((w == 0) & (v == 0)):
        raise InputError("twist is zero: give the direction of the hand motion")
    pure = w <= angle_tol * np.maximum(v, 1e-300)
    mag = np.where(pure, v, w)
    L = characteristic_length(model, q)  # each configuration's own
    sol = solve_step(jacobian(model, q), V, prismatic=model.prismatic, length=L)
    return sol.dq * (speed / mag)[..., None]
