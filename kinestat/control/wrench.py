"""The measurement chain: encoder counts → leg lengths → top pose → the contact wrench.

Vibhute 2011 ch. 4 step 2 (serialdaq_plat.m → leg_to_T10.m → eq_wrench.m): the leg counts
become leg lengths through the calibration, the platform's forward kinematics (tracking mode,
from the previous pose) gives the top's pose, the leg forces along the legs — from the
calibration's count → force maps (``ControlModel.force_source = "calibration"``, the thesis's
``legf``) or the springs ``k (l − l0)`` — give the wrench, and the flange pose ``F_6T``
(from the robot's encoders) carries it into the fixed frame.

Two estimates of the contact force come out of each measurement:

* the **equivalent wrench** ``W_eq = −j f`` (the thesis's eq_wrench.m): all six
  components, straight from the six leg forces;
* the **point-contact force**: a tool tip touching a workpiece at a point transmits a pure
  force through the tip, ``w = [F; p × F]``, so the three components of F are fitted to the six
  leg forces by least squares, ``F = argmin |k (l − l0) − j⁻¹ [I; [p]×] F|`` (the legs'
  encoder errors are independent and alike, so this is the maximum-likelihood estimate). With
  the thesis's 0.0254 mm counts it halves the direction error of ``W_eq`` (mean 0.37° → 0.14°
  at 4 N); the magnitude is no better (both ±0.03 N typical, 0.1 N worst). Its leg-force
  residual tells whether the contact really is a point.

Sign: the measured wrench is the one the **tool applies to the workpiece** — the thesis's
``W_eq`` (the legs' compressive forces along the leg lines), the sense of ``F_req``. A top
with weight (``ControlModel.payload``) has it subtracted first
(:func:`kinestat.control.payload.gravity_wrench`). It is the
negative of :func:`kinestat.parallel.statics.spring_wrench`, the external wrench on the top.
Moments are about the fixed origin, the robot's base (ray coordinates ``[f; m_O]``);
:attr:`Measurement.torque` is the moment about the commanded tool point ``P_tool_F`` (the unloaded
tip carried by the flange) and :meth:`Measurement.torque_about_tip` the moment about the measured
(deflected) tip, which vanishes for a point contact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from kinestat.control.model import ControlModel
from kinestat.control.payload import gravity_wrench
from kinestat.errors import InputError
from kinestat.hardware.leg_calibration import counts_to_forces, counts_to_lengths
from kinestat.parallel.fk import fk_tracking
from kinestat.parallel.legs import line_jacobian_trusted
from kinestat.parallel.statics import spring_forces
from kinestat.spatial.transforms import apply, apply_one, cross3, skew

__all__ = ["Estimator", "Measurement", "measure", "tool_frame"]

Estimator = Literal["point", "wrench"]
"""The force a measurement offers the controller (:meth:`Measurement.estimate`): the
point-contact fit or the equivalent wrench's force (as the thesis)."""


@dataclass(frozen=True, eq=False)
class Measurement:
    """One cycle's measured state of the cell (fixed frame unless said otherwise).

    Attributes:
        q: (6,) joint angles from the robot's encoders (radians, Crane–Duffy).
        counts: (6,) leg encoder counts, sensor legs 1..6.
        leg_lengths: (6,) leg lengths, platform leg order (mm).
        top_pose: (4, 4) the top frame in the base frame (tracking forward kinematics).
        flange_pose: (4, 4) ``F_6T``.
        base_pose: (4, 4) the platform base in the fixed frame.
        wrench: (6,) ``[f; m_O]`` the tool applies to the workpiece, fixed frame, moment about
            the fixed origin (N, N·mm).
        tool_point: (3,) ``P_tool_F``: the unloaded tool point carried by the flange.
        s6, a67: (3,) the tool axis ``S6_F`` and ``a67_F``.
        point_force: (3,) the point-contact estimate of the force the tool applies (fixed
            frame, N).
        point_residual: RMS leg-force residual of the point-contact fit (N).
        seq, age: sequence number and age (s) of the sensor packet, if known.
    """

    q: np.ndarray
    counts: np.ndarray
    leg_lengths: np.ndarray
    top_pose: np.ndarray
    flange_pose: np.ndarray
    base_pose: np.ndarray
    wrench: np.ndarray
    tool_point: np.ndarray
    s6: np.ndarray
    a67: np.ndarray
    point_force: np.ndarray | None = None
    point_residual: float = 0.0
    seq: int | None = None
    age: float | None = None

    @property
    def force(self) -> np.ndarray:
        """Force the tool applies to the workpiece (N)."""
        return self.wrench[:3]

    @property
    def force_magnitude(self) -> float:
        return float(np.linalg.norm(self.wrench[:3]))

    @property
    def torque(self) -> np.ndarray:
        """Moment of the measured wrench about the commanded tool point ``P_tool_F`` (N·mm): the
        unloaded tip carried by the flange, not the deflected tip (:meth:`torque_about_tip`)."""
        return self.wrench[3:] - np.cross(self.tool_point, self.wrench[:3])

    def estimate(self, estimator: Estimator = "point") -> np.ndarray:
        """The force the controller acts on: ``"point"`` (point-contact fit, default) or
        ``"wrench"`` (the equivalent wrench's force, as the thesis)."""
        if estimator == "point" and self.point_force is not None:
            return self.point_force
        if estimator in ("point", "wrench"):
            return self.wrench[:3]
        raise InputError(f"unknown force estimator {estimator!r}; use 'point' or 'wrench'")

    def deflections(self, model: ControlModel) -> np.ndarray:
        """Leg deflections ``l − l0`` (mm), platform leg order."""
        return self.leg_lengths - model.platform.free_lengths

    def torque_about_tip(self, model: ControlModel) -> np.ndarray:
        """Moment of the measured wrench about the measured tip :meth:`tip` (N·mm): zero, within
        the leg encoders' resolution, when the tool touches the workpiece at a point."""
        p = self.tip(model)
        return self.wrench[3:] - np.cross(p, self.wrench[:3])

    def tip(self, model: ControlModel) -> np.ndarray:
        """The measured (deflected) tool tip, fixed frame (read-only; computed once per model:
        a cycle asks for it several times)."""
        got = self.__dict__.get("_tip")
        if got is not None and got[0] is model:
            return got[1]
        p = apply_one(self.base_pose @ self.top_pose, model.tool_tip_top)
        p.setflags(write=False)
        self.__dict__["_tip"] = (model, p)  # a cache, not a field: the instance stays frozen
        return p


    def tip_centre(self, model: ControlModel) -> np.ndarray:
        """The measured centre of the tool's ball tip (``model.tip_radius``), fixed frame: the
        point of the tool that rides on the surface offset by the radius whatever the tool's
        lean; :meth:`tip` itself for a point tip."""
        if model.tip_radius == 0.0:
            return self.tip(model)
        return apply_one(self.base_pose @ self.top_pose, model.tip_centre_top)


def tool_frame(q, model: ControlModel):
    """Forward analysis of the robot with the model's tool: ``(P_tool_F, S6_F, a67_F, F_6T)``
    of one joint vector ``q`` (6,), from the arm's ``flange_pose``."""
    T = model.arm.flange_pose(q)
    return apply_one(T, model.tool_point_6), T[:3, 2].copy(), T[:3, 0].copy(), T


def measure(model: ControlModel, q, counts, previous_top_pose, *, seq: int | None = None,
            age: float | None = None, lengths=None) -> Measurement:
    """Run the measurement chain for one cycle (Vibhute ch. 4 step 2).

    Args:
        q: (6,) the robot's joint angles (radians) read from its encoders.
        counts: (6,) leg encoder counts, sensor legs 1..6 (as the reader returns them).
        previous_top_pose: (4, 4) the last measured top pose (start: the platform's home).
        lengths: (6,) the leg lengths of ``counts`` (mm) when the caller already has them.

    Raises:
        InputError: bad shapes or values; the platform's FK errors (no assembly, a crossed
            singularity) propagate as their own :class:`~kinestat.errors.KinestatError`.
    """
    q = np.asarray(q, dtype=float)
    c = np.asarray(counts, dtype=float)
    if q.shape != (6,) or c.shape != (6,):
        raise InputError(f"measure: expected 6 joint angles and 6 leg counts, got shapes "
                         f"{q.shape} and {c.shape}")
    if not all(map(math.isfinite, q.tolist() + c.tolist())):
        raise InputError("measure: joint angles or leg counts contain NaN or infinity")
    plat = model.platform
    if lengths is None:
        lengths = counts_to_lengths(c, model.calibration, plat.leg_names)
    # tracking FK from the previous pose (checked: no singularity crossed, nearest mode), then
    # w = j f, the external wrench on the top (base frame, about O0), with the leg tensions f
    # from the calibration's force maps or the springs k (l - l0)
    tension = (counts_to_forces(c, model.calibration, plat.leg_names)
               if model.force_source == "calibration" else spring_forces(plat, lengths))
    top = fk_tracking(plat, lengths, previous_top_pose)
    j = line_jacobian_trusted(plat, top)  # a pose fk_tracking returned: rigid, finite
    tool, s6, a67, T6 = tool_frame(q, model)
    TB = T6 @ model.mount
    R, t = TB[:3, :3], TB[:3, 3]
    w_ext = j @ tension
    if model.payload is not None:  # the legs also carry the top's and the tool's weight
        w_ext = w_ext - gravity_wrench(model.payload, top, R)
    f_fixed = R @ -w_ext[:3]  # the wrench in the fixed frame, moment about its origin
    w_fixed = np.concatenate([f_fixed, R @ -w_ext[3:] + cross3(t, f_fixed)])
    # point contact at the tip: tensions = j^-1 [I; [p]x] F_ext, least squares in F_ext
    p = apply(top, model.tool_tip_top)
    M = np.linalg.solve(j, np.vstack([np.eye(3), skew(p)]))
    if model.payload is not None:  # fit the contact's share of the tensions
        tension = np.linalg.solve(j, w_ext)
    # by the normal equations: M is well conditioned (cond ~8 on the 2011 prototype; its
    # square loses nothing at the leg encoders' resolution), and they cost a third of lstsq
    F_ext = np.linalg.solve(M.T @ M, M.T @ tension)
    resid = float(np.sqrt(np.mean((M @ F_ext - tension) ** 2)))
    point = -(TB[:3, :3] @ F_ext)
    return Measurement(q=q.copy(), counts=c.copy(), leg_lengths=lengths, top_pose=top,
                       flange_pose=T6, base_pose=TB, wrench=w_fixed, tool_point=tool, s6=s6,
                       a67=a67, point_force=point, point_residual=resid, seq=seq, age=age)
