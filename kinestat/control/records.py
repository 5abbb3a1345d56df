"""The records of the cycle log (:mod:`kinestat.control.log`) the loop writes: the run's
settings, each measurement and command, and each cycle's entry of the report's ``cycles``."""

from __future__ import annotations

import numpy as np

from kinestat.control.controller import STATES, Command, ControllerConfig, ControllerState
from kinestat.control.wrench import Measurement

__all__ = ["meas_record", "cmd_record", "config_record", "cycle_summary"]


def meas_record(config: ControllerConfig, m: Measurement) -> dict:
    model = config.model
    return {
        "joints_deg": np.degrees(m.q),
        "counts": m.counts,
        "leg_lengths": m.leg_lengths,
        "deflections": m.deflections(model),
        "force": m.force,
        "force_magnitude": m.force_magnitude,
        "point_force": m.point_force,
        "point_residual": m.point_residual,
        "estimate": m.estimate(config.estimator),
        "torque": m.torque,
        "moment_origin": m.wrench[3:],
        "torque_about_tool": m.torque,
        "torque_about_base": m.wrench[3:],
        "tool_point": m.tool_point,
        "tool_axis": m.s6,
        "a67": m.a67,
        "tip": m.tip(model),
        "torque_about_tip": m.torque_about_tip(model),
        "top_pose": m.top_pose,
        "seq": m.seq,
        "age": m.age,
    }


def cmd_record(cmd: Command) -> dict | None:
    if cmd.kind != "move":
        return None
    t = cmd.target
    p = cmd.prediction
    rec = {
        "action": cmd.action,
        "tool_point": t.tool_point,
        "tool_axis": t.s6,
        "a67": t.a67,
        "axis_counts": cmd.axis_counts,
        "axis_deg": cmd.axis_deg,
        "joints_deg": np.degrees(cmd.q),
        "step": cmd.step,
        "rotation_deg": cmd.rotation_deg,
        "predicted_force": None if p is None else p.force,
        "predicted_force_magnitude": None if p is None else p.force_magnitude,
        "predicted_deflections": None if p is None else p.deflections,
        "predicted_top_pose": None if p is None else p.top_pose,
    }
    if cmd.accel_limit is not None:  # 1/s²: the move's accelerations capped (Command)
        rec["accel_limit"] = cmd.accel_limit
    return rec


def config_record(config: ControllerConfig) -> dict:
    env = config.envelope
    return {
        "force": config.force,
        "force_target": config.force_target,
        "force_tol": config.force_tol,
        "align_tol_deg": config.align_tol_deg,
        "method": config.method,
        "step": config.step,
        "approach_step": config.approach,
        "contact_force": config.contact_force,
        "max_iterations": config.max_iterations,
        "vernier": config.vernier,
        "estimator": config.estimator,
        "procedure": config.procedure,
        "calibration": config.model.calibration_name,
        "force_source": config.model.force_source,
        "start_tool_point": config.start_tool_point,
        "start_s6": config.start_s6,
        "start_a67": config.start_a67,
        "tool_point_6": config.model.tool_point_6,
        "mount": config.model.mount,
        "envelope": {"max_deflection": env.max_deflection, "max_load": env.max_load,
                     "max_joint_step_deg": env.max_joint_step_deg,
                     "max_stream_faults": env.max_stream_faults,
                     "motion_range": env.motion_range},
        "states": STATES,
    }


def cycle_summary(cmd: Command, state: ControllerState, meas: Measurement,
                   truth: dict | None) -> dict:
    """The cycle's entry of the report's ``cycles``: state, action, the commanded tool point
    and S6 (the last commanded ones for measure/done/stop), the measured force (the
    equivalent wrench's) and, simulated, the true force, tip and surface normal."""
    t = cmd.target if cmd.target is not None else state.target
    tf = None if not truth or truth.get("tool_force") is None else np.asarray(
        truth["tool_force"], dtype=float)
    out = {"cycle": state.cycle, "state": cmd.label,
           "action": cmd.action if cmd.kind in ("move", "measure") else cmd.kind,
           "tool_point": t.tool_point.copy(), "s6": t.s6.copy(),
           "force": meas.wrench[:3].copy(), "true_force": tf}
    if cmd.info:  # a task's own figures (the follow task's)
        out.update(cmd.info)
    for key, src in (("true_normal", "normal"), ("true_tip", "tip")):
        v = None if not truth else truth.get(src)
        out[key] = None if v is None else np.asarray(v, dtype=float).copy()
    return out
