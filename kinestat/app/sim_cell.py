"""Composition root: the simulated cell wired to the simulated devices (``kinestat control``
without hardware).

:class:`SimHarness` starts the Galil simulator (:mod:`kinestat.sim.galil_server`, loopback
only) and the encoder emitter (:mod:`kinestat.sim.encoder_emitter`, on a pty) and connects
them through the cell: at every packet the emitter asks :meth:`SimHarness.counts_now`, which
reads the simulator's TRUE axis positions (including the axis 4 → 5 coupling the encoders do
not see), solves the contact equilibrium of the platform at that flange pose
(:func:`kinestat.sim.contact.equilibrium`, quasi-statically along the robot's motion so that a
friction anchor follows the path) and turns the true leg lengths into encoder counts
(:class:`kinestat.sim.sensor.Sensor`). The controller then drives the cell through the real
client and reader (:class:`kinestat.devices.cell_io.DeviceIO`), over TCP loopback and the pty.

:class:`InProcessIO` is the same cell without devices (an exact robot, counts straight from the
sensor model): fast, deterministic, for tests of the control law. Given a
:class:`~kinestat.sim.arm.SimulatedArm` it carries that arm instead of the PUMA 762 (joints set
directly within the arm's limits, the flange pose from the arm's model): the cell of
``kinestat control --arm`` (:mod:`kinestat.app.arm_cell`).
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from kinestat.control.arm import Arm
from kinestat.control.controller import ControllerConfig, axis_counts_to_q
from kinestat.control.model import ControlModel
from kinestat.devices.cell_io import DeviceIO, SensorSample
from kinestat.devices.encoder_stream import EncoderReader, Format
from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX, GalilClient
from kinestat.devices.motion import coordinated_move_plan, limit_accel
from kinestat.errors import DeviceError, JointLimitError, KinestatError, UnreachableError
from kinestat.robots.puma762.arm import THESIS_ARM
from kinestat.robots.puma762.axes import (
    AXIS4_TO_5_COUPLING,
    AXIS_DEG_PER_COUNT,
    axis_deg_to_counts,
    counts_to_joint_rad,
)
from kinestat.sim.arm import SimulatedArm
from kinestat.sim.contact import Cell, Equilibrium, unloaded_tip
from kinestat.sim.dmc import DmcSimulator, SimClock
from kinestat.sim.encoder_emitter import EncoderEmitter
from kinestat.sim.galil_server import GalilSimServer
from kinestat.sim.sensor import Sensor
from kinestat.sim.surface import solve as solve_contact
from kinestat.sim.surface import surface_normal

__all__ = ["CellState", "DeviceWiring", "SimHarness", "stop_devices", "SimCheckedReader",
           "InProcessIO", "control_model", "simulator_fault", "start_counts"]


def control_model(cell: Cell, sensor: Sensor, *, coupling: float = AXIS4_TO_5_COUPLING,
                  **kw: Any) -> ControlModel:
    """The controller's model of a simulated cell: same platform, mount, tool and calibration."""
    return ControlModel(platform=cell.platform, mount=cell.mount, tool_point_6=cell.tool_point_6,
                        calibration=sensor.calibration, coupling=coupling, **kw)


_LEAVE_IT = "; leave the robot where it is or choose another pose"
"""The PUMA 762 selection's advice, replaced by the start pose's (:func:`start_counts`)."""


def start_counts(config: ControllerConfig, current_counts=(0, 0, 0, 0, 0, 0)) -> np.ndarray:
    """Axis counts of the start pose (the solution nearest ``current_counts``), where a
    simulated robot is placed before the run so that the first move is short."""
    model = config.model
    c = np.asarray(current_counts, dtype=np.int64)
    try:
        axis = model.arm.solve_axis(config.start_tool_point, config.start_s6, config.start_a67,
                                    model.tool_point_6, axis_counts_to_q(model, c),
                                    model.limits_deg)
    except (UnreachableError, JointLimitError) as exc:
        p = ", ".join(f"{v:g}" for v in np.round(config.start_tool_point, 3))
        d = ", ".join(f"{v:.4f}" for v in config.start_s6)
        why = str(exc).removesuffix(_LEAVE_IT)
        raise type(exc)(f"the start pose (tool point ({p}) mm, tool axis along F_req ({d})) "
                        f"is out of reach: {why}; choose another --start or --direction") from exc
    return axis_deg_to_counts(np.degrees(axis))



SIM_STALE_AFTER = 1.0
"""Staleness limit (s) of the reader on the simulated encoder stream (:meth:`SimHarness.reader`)."""

def stop_devices(opened: list, emitter, server) -> None:
    """Close the clients and readers a harness opened (newest first, never failing), then
    stop its encoder emitter and its Galil server."""
    for obj in reversed(opened):
        try:
            obj.close()
        except Exception:  # noqa: BLE001 - closing must not fail
            pass
    opened.clear()
    emitter.stop()
    server.stop()


class CellState:
    """The evolving state of a simulated cell (thread-safe): friction anchor, last solution.

    :meth:`solve` is quasi-static: call it along the robot's motion (the emitter does, at its
    rate) so that a sticking contact's anchor and the first-contact point follow the path.
    ``arm``: the simulated arm carrying the platform (:class:`~kinestat.sim.arm.SimulatedArm`);
    None: the robot ``robot`` moved by the simulated Galil, seen through the controller's
    :class:`~kinestat.control.arm.Arm` protocol (default the thesis's PUMA 762).
    """

    def __init__(self, cell: Cell, sensor: Sensor | None = None, *, seed: int | None = 0,
                 arm: SimulatedArm | None = None, robot: Arm = THESIS_ARM) -> None:
        self.cell = cell
        self.arm = arm
        self.robot = robot
        self.sensor = sensor if sensor is not None else Sensor()
        self._rng = np.random.default_rng(seed)
        self._lock = threading.Lock()
        self._anchor: np.ndarray | None = None
        self._free_tip: np.ndarray | None = None
        self._key: bytes | None = None
        self._eq: Equilibrium | None = None
        self.error: KinestatError | None = None

    def solve(self, q) -> Equilibrium:
        """Equilibrium at joint angles ``q`` (radians), updating the contact history."""
        q = np.asarray(q, dtype=float)
        key = q.tobytes()
        with self._lock:
            if key == self._key and self._eq is not None:
                return self._eq
            T = (self.robot if self.arm is None else self.arm).flange_pose(q)
            try:
                guess = (self._eq.top_pose if self._eq is not None and self._eq.in_contact
                         else None)  # continuation along the robot's motion
                eq = solve_contact(self.cell, T, anchor=self._anchor,
                                   approach_from=self._free_tip, top_pose_guess=guess)
            except KinestatError as exc:
                self.error = exc
                raise
            if eq.in_contact:
                self._anchor = eq.anchor
            else:
                self._anchor = None
                self._free_tip = unloaded_tip(self.cell, T)
            self._key, self._eq = key, eq
            return eq

    def counts(self, q) -> np.ndarray:
        """Sensor counts (legs 1..6) at joint angles ``q``."""
        eq = self.solve(q)
        with self._lock:
            return self.sensor.counts(self.cell.platform, eq.leg_lengths, self._rng)

    def truth(self, q, tool_point_6) -> dict:
        """The true state at ``q`` for logs and reports (fixed frame)."""
        eq = self.solve(q)
        if self.arm is None:
            fwd = self.robot.forward(np.asarray(q, dtype=float), tool_point_6)
            tool_axis, tool_point = fwd.s6, fwd.tool_point
        else:
            T = self.arm.flange_pose(q)
            tool_axis, tool_point = T[:3, 2].copy(), T[:3, :3] @ tool_point_6 + T[:3, 3]
        return {
            "tool_force": eq.tool_force,
            "tool_force_magnitude": float(np.linalg.norm(eq.tool_force)),
            "in_contact": eq.in_contact,
            "sticking": eq.sticking,
            "tip": eq.tip,
            "leg_lengths": eq.leg_lengths,
            "tool_axis": tool_axis,
            "tool_point": tool_point,
            "joints_deg": np.degrees(q),
            "residual": eq.residual,
            "normal": (surface_normal(self.cell.workpiece, eq.tip) if eq.in_contact
                       else None),
        }


class DeviceWiring:
    """What a simulated cell's harness shares: a context manager over its ``start``/``stop``,
    and the addresses of its Galil server (``server``) and encoder emitter (``emitter``)."""

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    @property
    def galil_address(self) -> tuple[str, int]:
        return self.server.address

    @property
    def serial_path(self) -> str:
        return self.emitter.path


class SimHarness(DeviceWiring):
    """The simulated cell behind real device protocols (context manager).

    Args:
        cell: the simulated cell; ``sensor`` its leg encoders (default thesis resolution).
        start_counts: the robot's axis counts at start (see :func:`start_counts`).
        rate_hz: encoder packet rate; ``fmt``: "ks" or "legacy" packets.
        clock: None for real time, or a :class:`~kinestat.sim.galil_server.SimClock`.
        coupling: the simulated robot's axis 4 → 5 coupling.
        seed: noise seed. ``emitter_options``: passed to the emitter (fault rates...).
        record: keep every command the simulated Galil received (``controller.commands``).
    """

    def __init__(self, cell: Cell, sensor: Sensor | None = None, *, start_counts=(0,) * 6,
                 rate_hz: float = 200.0, fmt: Format = "ks", clock: SimClock | None = None,
                 coupling: float = AXIS4_TO_5_COUPLING, seed: int | None = 0,
                 emitter_options: dict | None = None, record: bool = False) -> None:
        self.state = CellState(cell, sensor, seed=seed)
        self.cell = cell
        self.fmt = fmt
        self.controller = DmcSimulator(clock=clock, initial_counts=start_counts,
                                       coupling=coupling, record=record)
        # the robot is placed at known, calibrated counts: homed by construction
        self.controller.variables["HOMED"] = 1.0
        self.server = GalilSimServer(controller=self.controller)
        # the box re-zeroes each leg at its strip's index mark (where the sensor's maps put it)
        options = {"index_counts": self.state.sensor.calibration.index_counts,
                   **(emitter_options or {})}
        self.emitter = EncoderEmitter(self.counts_now, rate_hz=rate_hz, fmt=fmt,  # type: ignore[arg-type]
                                      **options)
        self._opened: list[Any] = []

    # -- life cycle
    def start(self) -> SimHarness:
        """Start the Galil simulator's server and the encoder emitter."""
        self.server.start()
        try:
            self.emitter.start()
        except BaseException:
            self.server.stop()
            raise
        return self

    def stop(self) -> None:
        """Close the clients and readers it opened, stop the emitter and the server."""
        stop_devices(self._opened, self.emitter, self.server)

    def true_q(self) -> np.ndarray:
        """The robot's true joint angles (radians)."""
        return counts_to_joint_rad(self.server.true_axis_counts())

    def counts_now(self) -> np.ndarray:
        """Leg counts for the emitter: the cell at the robot's true pose, through the sensor."""
        return self.state.counts(self.true_q())

    def truth(self) -> dict:
        """The true state now (what the controller cannot see)."""
        if self.emitter.error is not None:
            return {"error": str(self.emitter.error)}
        try:
            return self.state.truth(self.true_q(), self.cell.tool_point_6)
        except KinestatError as exc:
            return {"error": str(exc)}

    def client(self, timeout: float = 2.0) -> GalilClient:
        """A connected Galil client (closed with the harness)."""
        host, port = self.galil_address
        c = GalilClient(host, port, timeout=timeout).connect()
        self._opened.append(c)
        return c

    def reader(self, **kw: Any) -> EncoderReader:
        """An open encoder reader on the emitter's pty (closed with the harness).

        Its staleness limit defaults to :data:`SIM_STALE_AFTER`: the simulated encoder box is
        a thread of this Python process and shares it with the contact solver, so on a loaded
        machine its packets can be late by more than real hardware's would."""
        kw.setdefault("fmt", self.fmt)
        kw.setdefault("stale_after", SIM_STALE_AFTER)
        r = EncoderReader(self.serial_path, **kw).open()
        self._opened.append(r)
        return r

    def device_io(self, *, reader_options: dict | None = None, client_timeout: float = 2.0,
                  **kw: Any) -> DeviceIO:
        """A :class:`DeviceIO` through the real client and reader, with the truth attached."""
        kw.setdefault("truth", self.truth)
        kw.setdefault("settle", 2.5 / self.emitter.rate_hz)
        reader = SimCheckedReader(self.reader(**(reader_options or {})), self.emitter)
        return DeviceIO(self.client(client_timeout), reader, **kw)


#: what a failed contact solve means for the run (docs/control.md, *The simulated cell*)
LOAD_LIMIT_HINT = ("the tool was pushed beyond what the simulated platform can carry at this "
                   "pose; ask for a smaller --force")


def simulator_fault(err: BaseException) -> DeviceError:
    """The error that stops the run when the simulated cell itself failed (e.g. no contact
    equilibrium, a leg beyond its stroke): the simulator's own reason, not the stale stream it
    leaves behind."""
    hint = f"; {LOAD_LIMIT_HINT}" if isinstance(err, UnreachableError) else ""
    return DeviceError(f"the simulated cell failed ({type(err).__name__}): {err}{hint}")


class SimCheckedReader:
    """An :class:`EncoderReader` on the emitter's pty that reports the emitter's error.

    When the simulated cell raises inside the emitter's thread, the emitter keeps the error
    and goes silent; the reader would see only stale data. Every read and poll checks the
    emitter first (and again when the reader reports stale data) and raises
    :func:`simulator_fault` with the real cause; the loop then stops the cell (ST, ``fault``
    and ``end`` records). Everything else is the reader's.
    """

    def __init__(self, reader: EncoderReader, emitter: EncoderEmitter) -> None:
        self._reader = reader
        self._emitter = emitter

    def __getattr__(self, name: str) -> Any:
        return getattr(self._reader, name)

    def _check(self) -> None:
        err = self._emitter.error
        if err is not None:
            raise simulator_fault(err) from err

    def _checked(self, fn, *args: Any, **kw: Any) -> Any:
        self._check()
        try:
            return fn(*args, **kw)
        except DeviceError:
            self._check()
            raise

    def read(self, *args: Any, **kw: Any) -> Any:
        return self._checked(self._reader.read, *args, **kw)

    def poll(self) -> Any:
        return self._checked(self._reader.poll)

    def latest(self, *args: Any, **kw: Any) -> Any:
        return self._checked(self._reader.latest, *args, **kw)

    def drain(self, *args: Any, **kw: Any) -> Any:
        return self._checked(self._reader.drain, *args, **kw)


class InProcessIO:
    """The simulated cell as a :class:`~kinestat.control.loop.CellIO` without devices.

    The robot reaches every commanded count exactly (no coupling, no motion time); the sensor
    counts come straight from the cell. Moves are evaluated quasi-statically at ``substeps``
    points along the straight joint-space path (for friction's history).

    With ``arm`` (a :class:`~kinestat.sim.arm.SimulatedArm`) the robot is that arm: axis angle
    = counts · ``axis_deg_per_count``, joint = axis − ``axis_offset`` (radians), set directly on
    the arm, which refuses (DeviceError, nothing moves) a joint outside its limits; ``guard``
    (``guard(sent_counts, counts_now)``, e.g. the envelope's
    :func:`~kinestat.control.envelope.sent_command_guard`) checks every command before that.
    """

    def __init__(self, cell: Cell, sensor: Sensor | None = None, *, start_counts,
                 axis_deg_per_count=None, seed: int | None = 0, substeps: int = 4,
                 arm: SimulatedArm | None = None, axis_offset=None, guard=None) -> None:
        self.state = CellState(cell, sensor, seed=seed, arm=arm)
        self.cell = cell
        self.arm = arm
        self._offset = np.zeros(6) if axis_offset is None else np.asarray(axis_offset, float)
        self._guard = guard
        self._res = np.asarray(AXIS_DEG_PER_COUNT if axis_deg_per_count is None
                               else axis_deg_per_count, dtype=float)
        self._counts = np.asarray(start_counts, dtype=np.int64).copy()
        if arm is not None:
            arm.move_to(self._q(self._counts))
        self.substeps = int(substeps)
        self.stopped = False
        self.moves: list[np.ndarray] = []

    def _q(self, counts) -> np.ndarray:
        axis = np.radians(np.asarray(counts, dtype=float) * self._res)
        if self.arm is not None:
            return axis - self._offset
        return self.state.robot.q_from_axis(axis)

    def robot_counts(self) -> np.ndarray:
        """The exact robot's axis counts A..F."""
        return self._counts.copy()

    def move(self, axis_counts, accel_limit: float | None = None) -> dict:
        """Reach ``axis_counts`` exactly, solving the cell at ``substeps`` points on the way
        (the straight joint-space path of a coordinated move; quasi-static, so the profile
        does not change the result); returns the coordinated plan
        (:func:`kinestat.devices.motion.coordinated_move_plan`, the thesis's maxima, its
        accelerations capped by ``accel_limit``: :func:`~kinestat.devices.motion.limit_accel`)."""
        new = np.asarray(axis_counts, dtype=np.int64)
        old = self._counts.astype(float)
        if self._guard is not None:
            self._guard(new, self._counts)
        if self.arm is not None:
            return self._move_arm(new, old)
        for s in np.linspace(0.0, 1.0, self.substeps + 1)[1:]:
            self.state.solve(self._q(old + s * (new - old)))
        self._counts = new.copy()
        self.moves.append(new.copy())
        plan = limit_accel(coordinated_move_plan(old, new, THESIS_SPEED_MAX, THESIS_ACCEL), old,
                           accel_limit)
        return {"delta_counts": (new - old).astype(np.int64).tolist(),
                "speed": plan.speed.tolist(), "accel": plan.accel.tolist(),
                "rule": "coordinated"}

    def _move_arm(self, new: np.ndarray, old: np.ndarray) -> dict:
        """The simulated arm's move: its joints checked first (nothing moves when refused),
        then the cell solved along the straight joint-space path."""
        q_new = self.arm.move_to(self._q(new))  # the limits, before any state changes
        q_old = self._q(old)
        for s in np.linspace(0.0, 1.0, self.substeps + 1)[1:]:
            self.state.solve(q_old + s * (q_new - q_old))
        self._counts = new.copy()
        self.moves.append(new.copy())
        return {"delta_counts": (new - old).astype(np.int64).tolist(),
                "joints_deg": np.degrees(q_new).tolist(), "rule": "direct"}

    def sensor(self) -> SensorSample:
        """Leg counts of the cell at the present pose, through the sensor model."""
        try:
            return SensorSample(counts=self.state.counts(self._q(self._counts)))
        except KinestatError as exc:
            raise DeviceError(f"simulated sensor failed: {exc}") from exc

    def stop(self) -> str:
        """Record that a stop was requested."""
        self.stopped = True
        return "stopped (in-process)"

    def truth(self) -> dict:
        """The true state at the present pose (or the simulator's error)."""
        try:
            return self.state.truth(self._q(self._counts), self.cell.tool_point_6)
        except KinestatError as exc:
            return {"error": str(exc)}


