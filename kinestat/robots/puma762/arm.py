"""The PUMA 762 behind the controller's :class:`kinestat.control.arm.Arm` protocol.

:class:`Puma762Arm` answers the controller's questions with the thesis's closed form
(:mod:`kinestat.robots.puma762.closed_form`): axis 1 = φ1 + 180° (its kinematic correction,
App. D.2), the forward analysis with the tool, its ``ik_all`` through the generic dispatch
(``method="puma762"``) and the thesis's least-motion selection within the axis limits — the
calls a recorded thesis run was made with. ``THESIS_ARM`` is the arm of the thesis's cell (the
controller's default).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.robots.puma762 import METHOD
from kinestat.robots.puma762 import closed_form as puma762

if TYPE_CHECKING:
    from kinestat.serial.analytic import IKAllResult

__all__ = ["Puma762Arm", "THESIS_ARM"]


@dataclass(frozen=True, eq=False)
class Puma762Arm:
    """The thesis's PUMA 762 (Vibhute §2.2.3, App. D.2): closed form, axis 1 = φ1 + 180°.

    >>> arm = Puma762Arm()
    >>> np.degrees(arm.axis_from_q(np.zeros(6)))[0]
    np.float64(180.0)
    """

    limits_deg: np.ndarray = field(default_factory=lambda: puma762.AXIS_LIMITS_DEG)

    @property
    def model(self) -> ChainModel:
        """The PUMA 762 as a chain (equal to ``kinestat.load("puma762")``)."""
        # the thesis path (reverse, select, forward) does not need the all-solutions package
        from kinestat.robots.puma762.analytic import puma762_chain  # lazy: scipy.linalg

        return puma762_chain()

    def q_from_axis(self, axis) -> np.ndarray:
        return puma762.from_axis_angles(axis)

    def axis_from_q(self, q) -> np.ndarray:
        return puma762.to_axis_angles(q)

    def forward(self, q, tool_point_6=(0.0, 0.0, 0.0)):
        return puma762.forward(q, tool_point_6)

    def ik_all(self, T_base_end) -> IKAllResult:
        from kinestat.serial.analytic import ik_all  # lazy: scipy.linalg, ~0.3 s at import

        return ik_all(self.model, T_base_end, method=METHOD)

    def flange_pose(self, q) -> np.ndarray:
        """``F_6T`` (4, 4) of one joint vector (:func:`kinestat.robots.puma762.forward.forward`)."""
        return puma762.forward(q).pose

    def solve_axis(self, tool_point, s6, a67, tool_point_6, q_now, limits_deg) -> np.ndarray:
        # the reverse analysis (Vibhute App. C) and the least-motion selection within limits
        res = puma762.reverse(tool_point, s6, a67, tool_point_6)
        return puma762.select(res, np.asarray(q_now, dtype=float), limits_deg).axis


THESIS_ARM = Puma762Arm()
"""The PUMA 762 of the thesis's cell (the controller's default arm)."""
