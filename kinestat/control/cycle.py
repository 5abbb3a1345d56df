"""Per-cycle data: what a cycle's decision computes from its measurement, computed once.

In the spirit of Pinocchio's Model/Data split: the :class:`~kinestat.control.model.ControlModel`
is immutable and knows nothing of the cycle; :class:`CycleData` holds the values the decision
needs more than once at the measured pose — the platform's loaded stiffness ``K`` (axis order
``[δφ; δx_O]``, Vibhute eq. 2-17), the tool tip in the base and fixed frames, the tip's
translational compliance ``C_tip`` (eq. 2-16/2-17) and the leg directions — each computed on
first use (K by :func:`kinestat.parallel.stiffness.stiffness`, C_tip by
:func:`kinestat.parallel.stiffness.tip_compliance`). :func:`cycle_data` finds a measurement's
data (kept with the measurement, so that :func:`~kinestat.control.controller.decide`, the
prediction (:mod:`kinestat.control.predict`) and the follow task's control law share it without
passing it around, and it goes with the measurement).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from kinestat.control.model import ControlModel
from kinestat.control.wrench import Measurement
from kinestat.parallel.legs import leg_directions_trusted
from kinestat.parallel.stiffness import stiffness, tip_compliance
from kinestat.spatial.transforms import apply_one, cross3

__all__ = ["CycleData", "cycle_data", "cross3"]


class CycleData:
    """Values of one measurement at the model's platform, each computed on first use.

    Attributes:
        K: (6, 6) the platform stiffness at the measured top pose, axis order.
        tip_base: (3,) the tool tip in the platform base frame (the measured, deflected tip).
        tip_fixed: (3,) the same in the fixed frame (:meth:`Measurement.tip`).
        C_tip: (3, 3) the tip's translational compliance, base frame (mm/N).
        leg_directions: ((6, 3), (6,)) unit leg directions and leg lengths at the top pose.
    """

    def __init__(self, model: ControlModel, meas: Measurement) -> None:
        self.model = model
        self.meas = meas
        # the platform's forward kinematics made this pose (checked there): used unchecked
        self.top_pose = np.asarray(meas.top_pose, dtype=float)

    @cached_property
    def K(self) -> np.ndarray:
        return stiffness(self.model.platform, self.top_pose, twist_order="axis")

    @cached_property
    def tip_base(self) -> np.ndarray:
        return apply_one(self.top_pose, self.model.tool_tip_top)

    @cached_property
    def tip_fixed(self) -> np.ndarray:
        return self.meas.tip(self.model)

    @cached_property
    def C_tip(self) -> np.ndarray:
        return tip_compliance(self.model.platform, self.top_pose, self.tip_base,
                              stiffness_axis=self.K)

    @cached_property
    def leg_directions(self) -> tuple[np.ndarray, np.ndarray]:
        return leg_directions_trusted(self.model.platform, self.top_pose)


def cycle_data(model: ControlModel, meas: Measurement) -> CycleData:
    """The :class:`CycleData` of ``meas`` at ``model``, made on first use (and again for
    another model). Kept in the measurement's instance dictionary beside
    :meth:`Measurement.tip`'s cache (a cache, not a field: the measurement stays frozen, and
    the data goes with it)."""
    d = meas.__dict__.get("_cycle_data")
    if d is None or d.model is not model or d.meas is not meas:
        d = meas.__dict__["_cycle_data"] = CycleData(model, meas)
    return d
