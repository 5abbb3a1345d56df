"""The weight the platform's legs carry besides the contact: the top plate and the tool.

The legs balance every external wrench on the top, so with gravity on they read the top's and
the tool's weight as if the tool pressed on something. A payload of mass ``m`` (kg) with its
centre of mass ``c`` in the top frame (mm) loads the top, in the platform's base frame, with

    ``w_g = [f; c_B × f]``,  ``f = m R_FBᵀ g_F``,  ``c_B = T_BT c``

(N and N·mm, moment about the base origin), ``g_F`` the gravity vector in the fixed frame
(m/s²) and ``R_FB`` the base's orientation there. The measurement chain
(:func:`kinestat.control.wrench.measure`) subtracts it from the legs' wrench before estimating
the contact force, as a force–torque sensor's gravity compensation does.

The thesis's platform carries no stated mass (Vibhute 2011 gives none), so the default
payload is none; a cell whose top has weight declares it (``ControlModel.payload``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinestat.errors import ModelError
from kinestat.spatial.transforms import apply
from kinestat.spatial.validate import frozen

__all__ = ["STANDARD_GRAVITY", "Payload", "gravity_wrench"]

STANDARD_GRAVITY = (0.0, 0.0, -9.80665)
"""Gravity in the fixed frame (m/s²): the robot's base stands on the floor, z up."""


@dataclass(frozen=True)
class Payload:
    """What the top plate carries besides the contact: its own and the tool's mass.

    Attributes:
        mass_kg: the top plate + tool (kg, ≥ 0).
        com_top_mm: (3,) their centre of mass in the top frame (mm).
        gravity: (3,) gravity in the fixed frame (m/s²); default standard gravity along −z.

    >>> round(Payload(0.35, (0.0, 0.0, 20.0)).weight_n, 4)
    3.4323
    """

    mass_kg: float
    com_top_mm: np.ndarray | tuple = (0.0, 0.0, 0.0)
    gravity: np.ndarray | tuple = STANDARD_GRAVITY

    def __post_init__(self) -> None:
        m = float(self.mass_kg)
        if not (math.isfinite(m) and m >= 0.0):
            raise ModelError(f"payload mass must be a finite number of kg ≥ 0, got "
                             f"{self.mass_kg!r}")
        object.__setattr__(self, "mass_kg", m)
        for name in ("com_top_mm", "gravity"):
            v = np.asarray(getattr(self, name), dtype=float)
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise ModelError(f"payload {name} must be 3 finite numbers, got "
                                 f"{getattr(self, name)!r}")
            object.__setattr__(self, name, frozen(v, float))

    @property
    def weight_n(self) -> float:
        """The payload's weight (N)."""
        return float(self.mass_kg * np.linalg.norm(self.gravity))


def gravity_wrench(payload: Payload, T_base_top, R_fixed_base) -> np.ndarray:
    """The payload's weight as a wrench on the top, base frame, about the base origin (N, N·mm).

    Args:
        payload: mass, centre of mass (top frame) and gravity (fixed frame).
        T_base_top: (..., 4, 4) the top's pose in the platform's base frame (mm).
        R_fixed_base: (..., 3, 3) the base's orientation in the fixed frame.

    Returns:
        (..., 6) ``[f; c_B × f]``.

    A top hanging level under a base turned upside down feels its weight along the base's +z;
    its centre of mass 100 mm above the base and 5 mm off along x puts a moment about y:

    >>> T = np.eye(4); T[:3, 3] = (5.0, 0.0, 100.0)
    >>> R = np.diag([1.0, -1.0, -1.0])
    >>> gravity_wrench(Payload(1.0, gravity=(0.0, 0.0, -10.0)), T, R).round(6).tolist()
    [0.0, 0.0, 10.0, 0.0, -50.0, 0.0]
    """
    T = np.asarray(T_base_top, dtype=float)
    R = np.asarray(R_fixed_base, dtype=float)
    f = payload.mass_kg * np.einsum("...ji,j->...i", R, payload.gravity)
    c = apply(T, payload.com_top_mm)
    return np.concatenate([f, np.cross(c, f)], axis=-1)
