"""The I/O driver of the kinestatic controller: devices in, pure decisions, devices out.

:func:`run` repeats one cycle — read the robot's axis counts and a fresh packet of leg
counts, run the measurement chain, call the pure :func:`~kinestat.control.controller.decide`,
log the cycle, send the command — until the goal is reached or something stops it. It talks to
the cell through a small :class:`CellIO` protocol and imports no driver:
:class:`kinestat.devices.cell_io.DeviceIO` implements it with the real Galil client and encoder
reader, and :class:`kinestat.app.sim_cell.InProcessIO` with the simulated cell in-process.

Safe stop: any device fault (a ``?`` from the Galil, a dropped link, a timeout), stale or
unreliable sensor data (no fresh packet in time, a frozen sequence, more stream faults than
the envelope tolerates), an envelope violation, a measurement the platform's kinematics cannot
explain, Ctrl-C, SIGTERM or SIGHUP (:mod:`kinestat.app.signals`) ends the run with ``ST``
sent to the motion controller (on a fresh connection if the link failed), a ``fault`` record
in the log and a report saying why (:class:`RunReport`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from kinestat.control.controller import (
    STATES,
    Command,
    ControllerConfig,
    ControllerState,
    StepMethod,
    axis_counts_to_q,
    decide,
    start,
)
from kinestat.control.envelope import require
from kinestat.control.log import CycleLog
from kinestat.control.procedure import decide_thesis
from kinestat.control.wrench import Estimator, Measurement, measure
from kinestat.errors import DeviceError, KinestatError, SafetyStop, StopRequested

__all__ = ["SensorReading", "CellIO", "RunReport", "refuse", "run"]


class SensorReading(Protocol):
    """One measurement of the leg counts as the loop reads it (sensor legs 1..6), with the
    stream's bookkeeping (:class:`kinestat.devices.cell_io.SensorSample` is one)."""

    @property
    def counts(self) -> np.ndarray: ...

    @property
    def seq(self) -> int | None: ...

    @property
    def age(self) -> float | None: ...

    @property
    def faults(self) -> tuple[str, ...]: ...


class CellIO(Protocol):
    """What the loop needs from the cell."""

    def robot_counts(self) -> np.ndarray:
        """The robot's axis positions, encoder counts A..F."""

    def move(self, axis_counts: np.ndarray) -> dict | None:
        """Move to absolute axis counts and return when the motion is complete; optionally
        return the move's plan (``{"delta_counts": [6], "speed": [6], ...}``) for the log."""

    def sensor(self) -> SensorReading:
        """Leg counts measured after the last motion completed."""

    def stop(self) -> object:
        """Stop the robot now (best effort); say what was done (its ``str``; a ``confirmed``
        attribute, when present, is logged as ``stop_confirmed``)."""

    def truth(self) -> dict | None:
        """The true state when simulated (for the log and report), else None."""


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


def _meas_record(config: ControllerConfig, m: Measurement) -> dict:
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


def _cmd_record(cmd: Command) -> dict | None:
    if cmd.kind != "move":
        return None
    t = cmd.target
    p = cmd.prediction
    return {
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


def _config_record(config: ControllerConfig) -> dict:
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


@dataclass
class _Run:
    """What a run has accumulated so far (mutable, private to :func:`run`)."""

    t0: float
    state: ControllerState | None = None
    states: list[str] = field(default_factory=list)
    faults: list[str] = field(default_factory=list)
    last_meas: Measurement | None = None
    last_truth: dict | None = None
    last_counts: np.ndarray | None = None
    moves: int = 0
    converged: bool = False
    reason: str = ""
    cycles: list[dict] = field(default_factory=list)
    decide_fn: DecideFn | None = None

    def t(self) -> float:
        return time.monotonic() - self.t0


DecideFn = Callable[[ControllerState, Measurement], tuple[Command, ControllerState]]
"""A task's pure decision function with its settings bound, e.g.
``functools.partial(decide_follow, follow_config)``."""


def run(config: ControllerConfig, io: CellIO, log: CycleLog, *,
        progress: Callable[[dict], None] | None = None,
        extra_header: dict | None = None, decide_fn: DecideFn | None = None) -> RunReport:
    """Run the kinestatic procedure (Vibhute 2011 ch. 5, Fig. 5-2) on ``io`` until the goal, a
    stop or ``max_iterations``.

    ``decide_fn`` replaces the press task's decision (:func:`decide` or the thesis's
    procedure) by another task's, e.g. the follow task's
    (:func:`kinestat.control.follow.decide_follow`); the start move, the measurement chain,
    the log and the safe stop are the same.

    Never raises for a fault of the cell: the run ends with a safe stop and the report says
    why. Every cycle is written to ``log`` before its command is sent.
    """
    r = _Run(t0=time.monotonic(), decide_fn=decide_fn)
    log.write(_start_record(config, extra_header))
    try:
        _start_move(config, io, log, r)
        while not _cycle(config, io, log, r, progress):
            pass
    except (KinestatError, KeyboardInterrupt) as exc:
        r.reason = _safe_stop(io, log, _fault_reason(exc), r.faults, r.t0)
    except Exception as exc:  # a bug: stop the robot first, keep the log, then let it show
        r.reason = _safe_stop(io, log, f"internal error {type(exc).__name__}: {exc}", r.faults,
                              r.t0)
        _once_more_if_interrupted(_finish, config, r, log)
        raise
    return _once_more_if_interrupted(_finish, config, r, log)


def _start_record(config: ControllerConfig, extra_header: dict | None) -> dict:
    header = {"type": "start", "time": time.strftime("%Y-%m-%dT%H:%M:%S"),
              "config": _config_record(config)}
    if extra_header:
        header.update(extra_header)
    return header


def refuse(config: ControllerConfig, log: CycleLog, reason: str, *,
           extra_header: dict | None = None) -> RunReport:
    """A run refused before anything was sent (e.g. an unhomed robot): the log still gets its
    ``start``, a ``fault`` (action "nothing sent") and the ``end`` record with the report."""
    r = _Run(t0=time.monotonic())
    log.write(_start_record(config, extra_header))
    r.faults.append(reason)
    log.write({"type": "fault", "t": r.t(), "reason": reason, "action": "nothing sent"})
    r.reason = reason
    return _once_more_if_interrupted(_finish, config, r, log)


def _once_more_if_interrupted(fn, *args):
    """``fn(*args)``, called again if a signal interrupted it (a stop or the final log must not
    be cut short; :mod:`kinestat.app.signals` raises only on the first signal)."""
    try:
        return fn(*args)
    except KeyboardInterrupt:
        return fn(*args)


def _start_move(config: ControllerConfig, io: CellIO, log: CycleLog, r: _Run) -> None:
    """Step 1: command the start pose (:func:`~kinestat.control.controller.start`)."""
    counts_now = io.robot_counts()
    q_now = axis_counts_to_q(config.model, counts_now)
    cmd, r.state = start(config, q_now, counts_now=counts_now)
    log.write({"type": "command", "cycle": 0, "t": r.t(), "decision": cmd.kind,
               "reason": cmd.reason, "commanded": _cmd_record(cmd)})
    if cmd.kind == "stop":
        raise SafetyStop(cmd.reason)
    n = len(cmd.waypoints) + 1
    for k, wp in enumerate(cmd.waypoints, 1):  # a long start move, one command at a time
        log.write({"type": "approach", "cycle": 0, "t": r.t(), "waypoint": k, "of": n,
                   "axis_counts": np.asarray(wp).tolist(),
                   "axis_deg": (np.asarray(wp) * config.model.axis_deg_per_count).tolist()})
        _move(io, log, replace(cmd, axis_counts=np.asarray(wp)), 0, r)
    _move(io, log, cmd, 0, r)


def _move(io: CellIO, log: CycleLog, cmd: Command, cycle: int, r: _Run) -> None:
    """Send one move; log its plan (per-axis deltas and speeds) when the cell reports one."""
    plan = io.move(cmd.axis_counts)
    r.moves += 1
    if plan:
        log.write({"type": "move", "cycle": cycle, "t": r.t(), "move": plan})


def _cycle(config: ControllerConfig, io: CellIO, log: CycleLog, r: _Run,
           progress: Callable[[dict], None] | None) -> bool:
    """One cycle: sense, measure, decide, log, act. True when the goal is attained."""
    sample = io.sensor()
    if sample.faults:
        r.faults.extend(sample.faults)
        log.write({"type": "stream_faults", "cycle": r.state.cycle + 1,
                   "faults": list(sample.faults)})
    if len(sample.faults) > config.envelope.max_stream_faults:
        raise SafetyStop(f"sensor link unreliable: {len(sample.faults)} stream faults "
                         f"while acquiring one measurement (limit "
                         f"{config.envelope.max_stream_faults}); first: {sample.faults[0]}")
    if not np.all(np.isfinite(np.asarray(sample.counts, dtype=float))):
        raise SafetyStop("the sensor returned no valid leg counts for this measurement")
    counts_r = io.robot_counts()
    r.last_counts = np.asarray(counts_r)
    q = axis_counts_to_q(config.model, counts_r)
    meas = measure(config.model, q, sample.counts, r.state.top_pose, seq=sample.seq,
                   age=sample.age)
    r.last_meas = meas
    if r.decide_fn is not None:
        cmd, r.state = r.decide_fn(r.state, meas)
    else:
        decide_fn = decide_thesis if config.procedure == "thesis" else decide
        cmd, r.state = decide_fn(config, r.state, meas)
    r.states.append(cmd.label)
    r.last_truth = io.truth()
    r.cycles.append(_cycle_summary(cmd, r.state, meas, r.last_truth))
    rec = {"type": "cycle", "cycle": r.state.cycle, "t": r.t(),
           "state": cmd.label, "decision": cmd.kind, "action": cmd.action,
           "reason": cmd.reason, "force_error": cmd.force_error,
           "misalignment_deg": cmd.misalignment_deg,
           "measured": _meas_record(config, meas), "commanded": _cmd_record(cmd),
           "true": r.last_truth, "violations": list(cmd.violations)}
    if cmd.info:
        rec["task"] = cmd.info
    log.write(rec)
    if progress is not None:
        progress(rec)
    if cmd.kind == "done":
        r.converged = True
        r.reason = cmd.reason
        return True
    if cmd.kind == "stop":
        raise SafetyStop(cmd.reason)
    if cmd.kind == "measure":  # measure again without moving (the thesis's procedure)
        return False
    require([] if cmd.axis_counts is not None else ["a move without axis counts"])
    _move(io, log, cmd, r.state.cycle, r)
    return False


def _cycle_summary(cmd: Command, state: ControllerState, meas: Measurement,
                   truth: dict | None) -> dict:
    """The cycle's entry of the report's ``cycles``: state, action, the commanded tool point
    and S6 (the last commanded ones for measure/done/stop), the measured force (the
    equivalent wrench's) and, simulated, the true force."""
    t = cmd.target if cmd.target is not None else state.target
    tf = None if not truth or truth.get("tool_force") is None else np.asarray(
        truth["tool_force"], dtype=float)
    out = {"cycle": state.cycle, "state": cmd.label,
           "action": cmd.action if cmd.kind in ("move", "measure") else cmd.kind,
           "tool_point": t.tool_point.copy(), "s6": t.s6.copy(),
           "force": meas.wrench[:3].copy(), "true_force": tf}
    if cmd.info:  # a task's own figures (the follow task's), with the true normal and tip
        out.update(cmd.info)
        for key, src in (("true_normal", "normal"), ("true_tip", "tip")):
            v = None if not truth else truth.get(src)
            out[key] = None if v is None else np.asarray(v, dtype=float).copy()
    return out


def _fault_reason(exc: BaseException) -> str:
    """The report's reason for a fault that ends the run."""
    if isinstance(exc, StopRequested):
        return f"stopped by {exc.signal_name}"
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted by the user"
    if isinstance(exc, SafetyStop):
        return str(exc)
    kind = "device fault" if isinstance(exc, DeviceError) else type(exc).__name__
    return f"{kind}: {exc}"


def _finish(config: ControllerConfig, r: _Run, log: CycleLog) -> RunReport:
    """The report of the run, also written as the log's ``end`` record."""
    report = _report(config, r.converged, r.state, r.states, r.moves, r.reason, r.last_meas,
                     r.last_truth, log, r.faults, r.t(), r.last_counts)
    report.cycles = r.cycles
    log.write({"type": "end", "report": report.as_dict()})
    return report


def _safe_stop(io: CellIO, log: CycleLog, reason: str, faults: list[str], t0: float) -> str:
    """Stop the robot (best effort), log the fault; return the reason with what was done.

    A signal arriving during the stop (while ``ST`` is sent, or a fresh connection is opened
    for it) does not cut it short: the stop is sent again and the fault still logged.
    """
    try:
        stopped = _once_more_if_interrupted(io.stop)
    except Exception as exc:  # noqa: BLE001 - a failing stop must not hide the fault
        stopped = f"stopping failed: {exc}"
    faults.append(reason)
    rec = {"type": "fault", "t": time.monotonic() - t0, "reason": reason, "action": str(stopped)}
    if isinstance(getattr(stopped, "confirmed", None), bool):  # what the controller confirmed
        rec["stop_confirmed"] = stopped.confirmed
    _once_more_if_interrupted(log.write, rec)
    return f"{reason} ({stopped})"


def _report(config, converged, state, states, moves, reason, m, truth, log, faults, elapsed,
            counts=None) -> RunReport:
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
        axis = truth.get("tool_axis")
        axis = m.s6 if axis is None and m is not None else axis
        if axis is not None and rep.true_force_magnitude > 0:
            c = float(np.clip(tf @ np.asarray(axis, dtype=float) / rep.true_force_magnitude,
                              -1.0, 1.0))
            rep.axis_error_deg = math.degrees(math.acos(c))
    return rep
