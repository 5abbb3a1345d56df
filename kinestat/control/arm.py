"""The robot arm as the kinestatic controller sees it: any 6-joint arm with an analytic solver.

The controller (Vibhute ch. 4) asks four things of the robot: the axis angles it reports and is
commanded in (``axis = q + offset``), the forward analysis with the tool
(:meth:`Arm.forward`: tool point, sixth axis, link direction, pose of the end frame), and the
reverse analysis of a target described as the thesis does — tool point ``P_tool_F``, ``S6_F``,
``a67_F`` and ``P_tool_6`` — reduced to one solution within the axis limits nearest the current
configuration (:meth:`Arm.solve_axis`). :class:`Arm` is that protocol; two instances:

- :class:`~kinestat.robots.puma762.arm.Puma762Arm`: the thesis's PUMA 762, one robot in
  :mod:`kinestat.robots.puma762` (closed form, axis 1 = φ1 + 180°, least-motion selection; the
  default of :class:`kinestat.control.model.ControlModel`); re-exported here with
  ``THESIS_ARM`` (deprecated import path: use ``kinestat.robots.puma762``);
- :class:`ChainArm`: any :class:`~kinestat.mechanism.chain.ChainModel` that
  :func:`kinestat.ik_all` solves (spherical wrist, three parallel axes, general 6R), with the
  shared selection step :func:`kinestat.serial.analytic.select_nearest`.

Encoder counts stay in :class:`~kinestat.control.model.ControlModel` (``axis_deg_per_count``
and the axis 4 → 5 ``coupling``, a PUMA 762 convention from :mod:`kinestat.robots.puma762.axes`:
give 0 for an arm without it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

from kinestat.errors import JointLimitError, ModelError, UnreachableError
from kinestat.mechanism.chain import ChainModel
from kinestat.robots.puma762.arm import THESIS_ARM, Puma762Arm
from kinestat.serial.fk import fk
from kinestat.spatial.validate import frozen

if TYPE_CHECKING:
    from kinestat.serial.analytic import IKAllResult

__all__ = ["Arm", "ToolFrame", "Puma762Arm", "ChainArm", "THESIS_ARM", "frame_from_tool"]


@dataclass(frozen=True, eq=False)
class ToolFrame:
    """Forward analysis with a tool, batched like ``q[..., 0]`` (lengths in the model's unit).

    Attributes: ``tool_point`` (…, 3) ``P_tool_F``; ``s6`` (…, 3) z of the end frame;
    ``a67`` (…, 3) x of the end frame; ``pose`` (…, 4, 4) ``T_base_end``.
    """

    tool_point: np.ndarray
    s6: np.ndarray
    a67: np.ndarray
    pose: np.ndarray


@runtime_checkable
class Arm(Protocol):
    """A 6-joint arm with an analytic solver, as the controller needs it (all angles radians)."""

    model: ChainModel
    limits_deg: np.ndarray  # (6, 2) axis limits, degrees

    def q_from_axis(self, axis) -> np.ndarray:
        """Joint values ``(…, 6)`` from axis angles ``(…, 6)``."""
        ...

    def axis_from_q(self, q) -> np.ndarray:
        """Axis angles ``(…, 6)`` from joint values ``(…, 6)``."""
        ...

    def forward(self, q, tool_point_6=(0.0, 0.0, 0.0)):
        """The :class:`ToolFrame`-like forward analysis (``tool_point, s6, a67, pose``)."""
        ...

    def flange_pose(self, q) -> np.ndarray:
        """The end frame's pose ``(4, 4)`` of one joint vector ``(6,)`` (the envelope's
        prediction)."""
        ...

    def ik_all(self, T_base_end) -> IKAllResult:
        """Every solution for poses of the end frame ``(…, 4, 4)``."""
        ...

    def solve_axis(self, tool_point, s6, a67, tool_point_6, q_now, limits_deg) -> np.ndarray:
        """Axis angles ``(6,)`` of the solution nearest ``q_now`` within ``limits_deg``; raises
        :class:`UnreachableError` (no solution) or :class:`JointLimitError` (none in limits)."""
        ...


def frame_from_tool(tool_point, s6, a67, tool_point_6) -> np.ndarray:
    """``T_base_end`` (4, 4) with z = ``s6``, x = ``a67`` (made perpendicular to z) and
    ``T · P_tool_6 = tool_point``: the thesis's target description as a pose.

    >>> T = frame_from_tool([0, 0, 300.0], [0, 0, 1.0], [1.0, 0, 0], [0, 0, 100.0])
    >>> T[:3, 3].tolist()
    [0.0, 0.0, 200.0]
    """
    # in scalars (a control cycle builds two frames): the norms and the dot product sum in
    # order, as NumPy's do on the reference machine
    z0, z1, z2 = np.asarray(s6, dtype=float).tolist()
    x0, x1, x2 = np.asarray(a67, dtype=float).tolist()
    n = math.sqrt(z0 * z0 + z1 * z1 + z2 * z2)
    z0, z1, z2 = z0 / n, z1 / n, z2 / n
    d = x0 * z0 + x1 * z1 + x2 * z2
    x0, x1, x2 = x0 - d * z0, x1 - d * z1, x2 - d * z2
    n = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    x0, x1, x2 = x0 / n, x1 / n, x2 / n
    y0, y1, y2 = z1 * x2 - z2 * x1, z2 * x0 - z0 * x2, z0 * x1 - z1 * x0
    T = np.array([[x0, y0, z0, 0.0], [x1, y1, z1, 0.0], [x2, y2, z2, 0.0],
                  [0.0, 0.0, 0.0, 1.0]])
    T[:3, 3] = np.asarray(tool_point, dtype=float) - T[:3, :3] @ np.asarray(tool_point_6, float)
    return T


@dataclass(frozen=True, eq=False)
class ChainArm:
    """Any 6R :class:`ChainModel` with an analytic solver (:func:`kinestat.ik_all`).

    ``axis_offset`` (6,) radians: axis angle − joint value (default 0); ``limits_deg`` the axis
    limits (default the model's joint limits shifted by the offset).

    >>> import kinestat
    >>> arm = ChainArm(kinestat.load("puma560"))
    >>> q = np.array([0.1, -0.4, 0.3, 0.2, 0.5, -0.1])
    >>> f = arm.forward(q)
    >>> ax = arm.solve_axis(f.tool_point, f.s6, f.a67, np.zeros(3), q, arm.limits_deg)
    >>> bool(np.allclose(arm.q_from_axis(ax), q))
    True
    """

    model: ChainModel
    axis_offset: np.ndarray = field(default_factory=lambda: np.zeros(6))
    limits_deg: np.ndarray | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.model, ChainModel) or self.model.n != 6:
            raise ModelError("ChainArm: the controller needs a 6-joint ChainModel")
        for i, j in enumerate(self.model.joints):  # ik_all also solves prismatic arms now
            if j.kind != "revolute":
                raise ModelError(f"ChainArm: joint {i + 1} of model {self.model.name!r} is "
                                 f"{j.kind}; the controller's arm has revolute joints only (axis "
                                 f"angles and limits in degrees)")
        off = np.asarray(self.axis_offset, dtype=float)
        if off.shape != (6,):
            raise ModelError(f"ChainArm: axis_offset must be 6 numbers, got shape {off.shape}")
        object.__setattr__(self, "axis_offset", frozen(off, float))
        if self.limits_deg is None:
            lim = np.degrees(np.column_stack([self.model.lower, self.model.upper]) + off[:, None])
        else:
            lim = np.asarray(self.limits_deg, dtype=float)
        object.__setattr__(self, "limits_deg", frozen(lim, float))
        self.ik_all(np.eye(4))  # refuses a model no analytic solver handles

    def q_from_axis(self, axis) -> np.ndarray:
        return np.asarray(axis, dtype=float) - self.axis_offset

    def axis_from_q(self, q) -> np.ndarray:
        return np.asarray(q, dtype=float) + self.axis_offset

    def forward(self, q, tool_point_6=(0.0, 0.0, 0.0)) -> ToolFrame:
        T = fk(self.model, np.asarray(q, dtype=float))
        p = np.einsum("...ij,j->...i", T[..., :3, :3], np.asarray(tool_point_6, float))
        return ToolFrame(tool_point=p + T[..., :3, 3], s6=T[..., :3, 2].copy(),
                         a67=T[..., :3, 0].copy(), pose=T)

    def flange_pose(self, q) -> np.ndarray:
        return fk(self.model, np.asarray(q, dtype=float))

    def ik_all(self, T_base_end) -> IKAllResult:
        from kinestat.serial.analytic import ik_all  # lazy: scipy.linalg, ~0.3 s at import

        return ik_all(self.model, T_base_end)

    def solve_axis(self, tool_point, s6, a67, tool_point_6, q_now, limits_deg) -> np.ndarray:
        from kinestat.serial.analytic import (  # lazy: scipy.linalg, ~0.3 s at import
            select_nearest,
            wrap_to_limits,
        )

        res = self.ik_all(frame_from_tool(tool_point, s6, a67, tool_point_6))
        if int(res.n_solutions) == 0:
            raise UnreachableError(f"{self.model.name}: no inverse-kinematics solution "
                                   f"({res.reason[()]})")
        lim = np.radians(np.asarray(limits_deg, dtype=float)) - self.axis_offset[:, None]
        # joint values do not say which turn a joint is on: take the current one in the limits
        cur = np.asarray(q_now, dtype=float)
        cur, _ = wrap_to_limits(cur, cur, lim[:, 0], lim[:, 1], ~self.model.prismatic)
        sel = select_nearest(self.model, res, cur, lower=lim[:, 0], upper=lim[:, 1])
        if not bool(sel.ok):
            raise JointLimitError(f"{self.model.name}: no inverse-kinematics solution lies "
                                  "within the axis limits")
        return self.axis_from_q(sel.q)
