"""What the kinestatic controller knows about the cell (immutable).

The robot (an :class:`~kinestat.control.arm.Arm`: by default the PUMA 762 in closed form; its
axis limits, its encoder resolution and the axis 4 → 5 coupling its motion controller
compensates), the compliant platform, how the platform is
mounted on the flange, where the unloaded tool tip is (``P_tool_6``, Vibhute App. D.1) and how
the leg encoders are calibrated. Nothing here changes while the controller runs; per-cycle
values live in :class:`kinestat.control.controller.ControllerState`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Literal, get_args

import numpy as np

from kinestat.control.arm import Arm
from kinestat.control.payload import Payload
from kinestat.errors import ModelError
from kinestat.hardware.leg_calibration import THESIS_CALIBRATION, LegCalibration
from kinestat.parallel.platform import Platform
from kinestat.robots.puma762.arm import THESIS_ARM
from kinestat.robots.puma762.axes import AXIS4_TO_5_COUPLING, AXIS_DEG_PER_COUNT
from kinestat.spatial.transforms import apply, as_array, inv
from kinestat.spatial.validate import frozen

__all__ = ["ControlModel", "ForceSource"]

_ARM_METHODS = ("q_from_axis", "axis_from_q", "forward", "solve_axis", "ik_all")

ForceSource = Literal["springs", "calibration"]
"""Where the leg forces come from: the platform's linear springs ``k (l − l0)`` at the measured
lengths, or the calibration's count → force maps (the thesis's eq_wrench.m ``legf``)."""


@dataclass(frozen=True, eq=False)
class ControlModel:
    """The cell as the controller sees it.

    Attributes:
        platform: the compliant platform (springs, free lengths, home pose).
        mount: (4, 4) the platform's base frame in frame 6 (``6_BT``).
        tool_point_6: (3,) the unloaded tool tip in frame 6, mm (``P_tool_6``).
        calibration: encoder counts → leg lengths (sensor legs 1..6).
        limits_deg: (6, 2) robot axis limits, degrees (default the arm's: for the PUMA 762
            the MATLAB code's).
        axis_deg_per_count: (6,) robot encoder resolution, degrees per count.
        coupling: axis-5 counts turned per axis-4 count, compensated by the motion controller
            (:func:`kinestat.robots.puma762.axes.axis45_compensation`); 0 when there is none.
        force_source: "springs" (the platform's ``k (l − l0)``) or "calibration" (the
            calibration's force maps; give the platform its calibrated springs,
            :func:`kinestat.hardware.leg_law.calibrated_platform`, for the predictions).
        calibration_name: a label for reports ("thesis-2011", "nominal", a file name).
        arm: the robot (:class:`kinestat.control.arm.Arm`: axis angles, forward analysis with
            the tool, analytic reverse analysis with selection); default the thesis's PUMA 762.
        payload: the top plate's and the tool's weight the legs carry besides the contact
            (:class:`kinestat.control.payload.Payload`), compensated in every measurement;
            None (default, as the thesis's massless top): no compensation.
        tip_radius: mm, the radius of the tool's ball tip, whose foremost point along the
            top's axis is the tool tip (``P_tool_6``); 0 (default): a point tip. A ball
            touches a surface at its centre less the radius along the surface's normal, so
            where the tool leans the foremost point is off the contact by ``r sin(lean)``
            while the centre rides on the surface offset by ``r``
            (:attr:`tip_centre_top`).
        top_mass: kg, the moving mass of the top plate and the tool (its inertia, whether or
            not its weight is compensated: :attr:`payload`); 0 (default, the thesis's
            quasi-static, massless top): moves are not limited for it. The follow task keeps
            its moves' accelerations so low that the inertia cannot load the contact beyond
            what its slip test resolves (:attr:`kinestat.control.follow.FollowTuning.
            tool_accel`).
    """

    platform: Platform
    mount: np.ndarray
    tool_point_6: np.ndarray
    calibration: LegCalibration = THESIS_CALIBRATION
    limits_deg: np.ndarray | None = None
    axis_deg_per_count: np.ndarray = field(default_factory=lambda: AXIS_DEG_PER_COUNT)
    coupling: float = AXIS4_TO_5_COUPLING
    force_source: ForceSource = "springs"
    calibration_name: str = ""
    arm: Arm = THESIS_ARM
    payload: Payload | None = None
    tip_radius: float = 0.0
    top_mass: float = 0.0

    def __post_init__(self) -> None:
        if not all(callable(getattr(type(self.arm), n, None)) for n in _ARM_METHODS):
            raise ModelError(f"arm must provide kinestat.control.arm.Arm, got "
                             f"{type(self.arm).__name__}")
        if self.force_source not in get_args(ForceSource):
            raise ModelError(f"force_source must be one of {get_args(ForceSource)}, got "
                             f"{self.force_source!r}")
        M = as_array(self.mount, shape_tail=(4, 4), name="mount")
        if M.shape != (4, 4):
            raise ModelError(f"mount must be one 4x4 transform, got shape {M.shape}")
        object.__setattr__(self, "mount", frozen(M, float))
        p6 = as_array(self.tool_point_6, shape_tail=(3,), name="tool_point_6")
        if p6.shape != (3,):
            raise ModelError(f"tool_point_6 must be 3 numbers, got shape {p6.shape}")
        object.__setattr__(self, "tool_point_6", frozen(p6, float))
        L = as_array(self.arm.limits_deg if self.limits_deg is None else self.limits_deg,
                     shape_tail=(2,), name="axis limits")
        if L.shape != (6, 2) or np.any(L[:, 0] >= L[:, 1]):
            raise ModelError(f"axis limits must be 6 (lower, upper) pairs in degrees with "
                             f"lower < upper, got {L.tolist()}")
        object.__setattr__(self, "limits_deg", frozen(L, float))
        r = as_array(self.axis_deg_per_count, name="axis resolution")
        if r.shape != (6,) or np.any(r <= 0):
            raise ModelError(f"axis resolution must be 6 positive degrees-per-count values, "
                             f"got {r.tolist()}")
        object.__setattr__(self, "axis_deg_per_count", frozen(r, float))
        if not math.isfinite(float(self.coupling)):
            raise ModelError("axis 4 -> 5 coupling must be finite")
        object.__setattr__(self, "coupling", float(self.coupling))
        if self.payload is not None and not isinstance(self.payload, Payload):
            raise ModelError(f"payload must be a kinestat.control.payload.Payload or None, got "
                             f"{type(self.payload).__name__}")
        if not (math.isfinite(float(self.tip_radius)) and self.tip_radius >= 0.0):
            raise ModelError(f"tip_radius must be a number of mm >= 0, got {self.tip_radius!r}")
        object.__setattr__(self, "tip_radius", float(self.tip_radius))
        if not (math.isfinite(float(self.top_mass)) and self.top_mass >= 0.0):
            raise ModelError(f"top_mass must be a number of kg >= 0, got {self.top_mass!r}")
        object.__setattr__(self, "top_mass", float(self.top_mass))
        # the platform's legs must match the calibration's
        self.calibration.platform_order(self.platform.leg_names)

    @cached_property
    def tool_tip_top(self) -> np.ndarray:
        """The tool tip in the top frame (where ``P_tool_6`` sits when the platform is at home;
        computed once, read-only)."""
        return frozen(apply(inv(self.mount @ self.platform.home_pose), self.tool_point_6), float)

    @cached_property
    def tip_centre_top(self) -> np.ndarray:
        """The centre of the tool's ball tip in the top frame: :attr:`tool_tip_top` less
        :attr:`tip_radius` along the top's axis (the tip itself for a point tip)."""
        return frozen(self.tool_tip_top - np.array([0.0, 0.0, self.tip_radius]), float)

    @property
    def limits_rad(self) -> np.ndarray:
        """Axis limits in radians, (6, 2)."""
        return np.radians(self.limits_deg)

