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

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from kinestat.control.controller import Command, ControllerConfig, ControllerState, axis_counts_to_q
from kinestat.control.envelope import check_deflection, require
from kinestat.control.log import CycleLog
from kinestat.control.records import cmd_record, config_record, cycle_summary, meas_record
from kinestat.control.report import RunReport, run_report
from kinestat.control.task import Task, as_task
from kinestat.control.wrench import Measurement, measure
from kinestat.errors import DeviceError, KinestatError, SafetyStop, StopRequested
from kinestat.hardware.leg_calibration import counts_to_lengths

__all__ = ["SensorReading", "CellIO", "RunReport", "Task", "refuse", "run"]


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

    def move(self, axis_counts: np.ndarray, accel_limit: float | None = None) -> dict | None:
        """Move to absolute axis counts and return when the motion is complete; optionally
        return the move's plan (``{"delta_counts": [6], "speed": [6], ...}``) for the log.
        ``accel_limit`` (1/s², :attr:`Command.accel_limit`) caps each axis's acceleration at
        that times its travel (:func:`kinestat.devices.motion.limit_accel`)."""

    def sensor(self) -> SensorReading:
        """Leg counts measured after the last motion completed."""

    def stop(self) -> object:
        """Stop the robot now (best effort); say what was done (its ``str``; a ``confirmed``
        attribute, when present, is logged as ``stop_confirmed``)."""

    def truth(self) -> dict | None:
        """The true state when simulated (for the log and report), else None."""


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
    task: Task | None = None

    def t(self) -> float:
        return time.monotonic() - self.t0


DecideFn = Callable[[ControllerState, Measurement], tuple[Command, ControllerState]]
"""A task's pure decision function with its settings bound (the older way of giving a task:
:func:`kinestat.control.task.as_task`)."""


def run(task: Task | ControllerConfig, io: CellIO, log: CycleLog, *,
        progress: Callable[[dict], None] | None = None,
        extra_header: dict | None = None, decide_fn: DecideFn | None = None) -> RunReport:
    """Run ``task`` (:class:`~kinestat.control.task.Task`: the press, the thesis's procedure,
    follow, ...) on ``io`` until its goal, a stop or its ``max_iterations``.

    The loop knows only the task protocol: the start move, the measurement chain, the log and
    the safe stop are the same for every task. A bare
    :class:`~kinestat.control.controller.ControllerConfig` runs its procedure's task, and
    ``decide_fn`` a bound decision after the press's start
    (:func:`~kinestat.control.task.as_task`).

    Never raises for a fault of the cell: the run ends with a safe stop and the report says
    why. Every cycle is written to ``log`` before its command is sent.
    """
    if decide_fn is not None or not isinstance(task, Task):
        task = as_task(getattr(task, "config", task), decide_fn)
    config = task.config
    r = _Run(t0=time.monotonic(), task=task)
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
              "config": config_record(config)}
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
    cmd, r.state = r.task.start(q_now, counts_now)
    log.write({"type": "command", "cycle": 0, "t": r.t(), "decision": cmd.kind,
               "reason": cmd.reason, "commanded": cmd_record(cmd)})
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
    plan = (io.move(cmd.axis_counts) if cmd.accel_limit is None
            else io.move(cmd.axis_counts, accel_limit=cmd.accel_limit))
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
    counts = np.asarray(sample.counts, dtype=float)
    if not np.all(np.isfinite(counts)):
        raise SafetyStop("the sensor returned no valid leg counts for this measurement")
    model = config.model
    # the legs' deflection straight from the counts, before the platform's kinematics: a
    # count the legs cannot reach is named as the sensor's, not as a failed assembly
    lengths = counts_to_lengths(counts, model.calibration, model.platform.leg_names)
    bad = check_deflection(config.envelope, model, lengths)
    if bad:
        raise SafetyStop(f"leg counts outside the envelope: {bad[0]} (sensor counts "
                         f"{[int(c) for c in counts]}: a sensor fault or an overload)")
    counts_r = io.robot_counts()
    r.last_counts = np.asarray(counts_r)
    q = axis_counts_to_q(config.model, counts_r)
    meas = measure(model, q, counts, r.state.top_pose, seq=sample.seq, age=sample.age,
                   lengths=lengths)
    r.last_meas = meas
    cmd, r.state = r.task.decide(r.state, meas)
    r.states.append(cmd.label)
    r.last_truth = io.truth()
    r.cycles.append(cycle_summary(cmd, r.state, meas, r.last_truth))
    rec = {"type": "cycle", "cycle": r.state.cycle, "t": r.t(),
           "state": cmd.label, "decision": cmd.kind, "action": cmd.action,
           "reason": cmd.reason, "force_error": cmd.force_error,
           "misalignment_deg": cmd.misalignment_deg,
           "measured": meas_record(config, meas), "commanded": cmd_record(cmd),
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
    report = run_report(config, r.converged, r.state, r.states, r.moves, r.reason, r.last_meas,
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
