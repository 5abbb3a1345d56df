"""The report of a run of the loop (:mod:`kinestat.control.loop`): the ``end`` record of the
log and the base of ``kinestat control --json``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kinestat.control.controller import ControllerConfig, StepMethod
from kinestat.control.wrench import Estimator

__all__ = ["RunReport", "run_report"]


@dataclass
class RunReport:
    """The outcome of a run (also the ``end`` record of the log and the CLI's ``--json``)."""

    converged: bool
    iterations: int
    moves: int
    stop_reason: str
    method: StepMethod
    states: list[str]
    force: np.ndarray | None = None
    torque: np.ndarray | None = None
    force_magnitude: float | None = None
    tool_axis: np.ndarray | None = None
    tool_point: np.ndarray | None = None
    final_joints_deg: np.ndarray | None = None
    final_axis_deg: np.ndarray | None = None
    final_leg_lengths: np.ndarray | None = None
    true_force: np.ndarray | None = None
    true_force_magnitude: float | None = None
    true_tip: np.ndarray | None = None
    true_normal: np.ndarray | None = None
    axis_error_deg: float | None = None
    log: str | None = None
    elapsed_s: float = 0.0
    target_force: float = 0.0
    faults: list[str] = field(default_factory=list)
    estimator: Estimator = "point"
    equivalent_wrench: np.ndarray | None = None
    torque_about_tool: np.ndarray | None = None
    torque_about_base: np.ndarray | None = None
    tip: np.ndarray | None = None
    torque_about_tip: np.ndarray | None = None
    procedure: str = "kinestat"
    calibration: str = ""
    cycles: list[dict] = field(default_factory=list)

    def as_dict(self) -> dict:
        """The report as plain JSON-ready values (the issue's keys first)."""
        def arr(v):
            return None if v is None else np.asarray(v, dtype=float).tolist()

        return {
            "converged": self.converged,
            "iterations": self.iterations,
            "force": arr(self.force),
            "torque": arr(self.torque),
            "force_magnitude": self.force_magnitude,
            "true_force": arr(self.true_force),
            "true_tip": arr(self.true_tip),
            "true_normal": arr(self.true_normal),
            "tool_axis": arr(self.tool_axis),
            "tool_point": arr(self.tool_point),
            "final_joints_deg": arr(self.final_joints_deg),
            "final_leg_lengths": arr(self.final_leg_lengths),
            "log": self.log,
            "final_axis_deg": arr(self.final_axis_deg),
            "states": "".join(self.states),
            "stop_reason": self.stop_reason,
            "method": self.method,
            "moves": self.moves,
            "target_force": self.target_force,
            "true_force_magnitude": self.true_force_magnitude,
            "axis_error_deg": self.axis_error_deg,
            "elapsed_s": self.elapsed_s,
            "faults": list(self.faults),
            "estimator": self.estimator,
            "equivalent_wrench": arr(self.equivalent_wrench),
            "equivalent_force": (None if self.equivalent_wrench is None
                                 else arr(self.equivalent_wrench[:3])),
            "torque_about_tool": arr(self.torque_about_tool),
            "torque_about_base": arr(self.torque_about_base),
            "tip": arr(self.tip),
            "torque_about_tip": arr(self.torque_about_tip),
            "procedure": self.procedure,
            "calibration": self.calibration,
            "cycles": [{k: (arr(v) if isinstance(v, np.ndarray) else v) for k, v in c.items()}
                       for c in self.cycles],
        }


def run_report(config: ControllerConfig, converged, state, states, moves, reason, m, truth,
               log, faults, elapsed, counts=None) -> RunReport:
    """The report of a run that ended in ``state`` after ``moves`` moves, its last
    measurement ``m``, the true state ``truth`` (simulated) and axis counts ``counts``."""
    rep = RunReport(converged=converged, iterations=0 if state is None else state.cycle,
                    moves=moves, stop_reason=reason, method=config.method, states=states,
                    log=str(log.path), elapsed_s=elapsed, target_force=config.force_target,
                    faults=faults, estimator=config.estimator, procedure=config.procedure,
                    calibration=config.model.calibration_name)
    if m is not None:
        f = m.estimate(config.estimator)
        rep.force = np.array(f, dtype=float)
        rep.torque = m.torque
        rep.force_magnitude = float(np.linalg.norm(f))
        rep.equivalent_wrench = m.wrench.copy()
        rep.torque_about_tool = m.torque
        rep.torque_about_base = m.wrench[3:].copy()
        rep.tip = np.array(m.tip(config.model), dtype=float)
        rep.torque_about_tip = m.torque_about_tip(config.model)
        rep.tool_axis = m.s6.copy()
        rep.tool_point = m.tool_point.copy()
        rep.final_joints_deg = np.degrees(m.q)
        if counts is not None:
            rep.final_axis_deg = counts * config.model.axis_deg_per_count
        rep.final_leg_lengths = m.leg_lengths.copy()
    if truth is not None and truth.get("tool_force") is not None:
        tf = np.asarray(truth["tool_force"], dtype=float)
        rep.true_force = tf
        rep.true_force_magnitude = float(np.linalg.norm(tf))
        for key in ("tip", "normal"):  # the plant's contact point and surface normal
            if truth.get(key) is not None:
                setattr(rep, f"true_{key}", np.asarray(truth[key], dtype=float).copy())
        axis = truth.get("tool_axis")
        axis = m.s6 if axis is None and m is not None else axis
        if axis is not None and rep.true_force_magnitude > 0:
            c = float(np.clip(tf @ np.asarray(axis, dtype=float) / rep.true_force_magnitude,
                              -1.0, 1.0))
            rep.axis_error_deg = math.degrees(math.acos(c))
    return rep
