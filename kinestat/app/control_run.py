"""Composition root of ``kinestat control``: assemble the cell, the controller and its devices.

The CLI (:mod:`kinestat.cli.control`) parses options into a :class:`ControlRequest` and prints
the report; this module builds what the run needs — the thesis's experiment as a simulated
cell (Vibhute 2011 §5.1: the special 6-6 platform centred on the flange, the tool at
``P_tool_6``, a tilted plane ahead of the start tool point) behind the simulated Galil and
encoder box (:mod:`kinestat.app.sim_cell`), or the real Galil and encoder stream — and runs
the kinestatic loop (:func:`kinestat.control.loop.run`) on it. With another arm
(``ControlRequest.arm``, ``kinestat control --arm``) the same simulated cell carries that arm
in-process (:mod:`kinestat.app.arm_cell`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from kinestat.app.arm_cell import (
    ArmSpec,
    PlacedArm,
    arm_control_model,
    arm_io,
    arm_start_counts,
    place_arm,
)
from kinestat.app.calibrations import (
    MountSpec,
    NamedCalibration,
    calibrated_model,
    ideal_counts,
    resolve_calibration,
    resolve_mount,
    resolve_platform,
)
from kinestat.app.control_defaults import (
    DEFAULT_DIRECTION,
    DEFAULT_PLANE_DISTANCE,
    DEFAULT_PLANE_TILT_DEG,
    DEFAULT_START,
    TASKS,
)
from kinestat.app.sim_cell import SimHarness, start_counts
from kinestat.control.controller import MAX_ITERATIONS, ControllerConfig, Procedure, StepMethod
from kinestat.control.envelope import Envelope, sent_command_guard
from kinestat.control.follow import (
    FollowConfig,
    decide_follow,
    default_travel_dir,
    follow_summary,
)
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import RunReport, refuse, run
from kinestat.control.model import ControlModel
from kinestat.control.payload import Payload
from kinestat.control.probe import PROBE_SPAN
from kinestat.control.wrench import Estimator
from kinestat.devices.cell_io import MAX_SAMPLES, DeviceIO
from kinestat.devices.encoder_stream import EncoderReader, Format
from kinestat.devices.galil import GalilClient
from kinestat.devices.homing import is_homed
from kinestat.devices.motion import MOVE_RULES, MoveRule
from kinestat.errors import InputError
from kinestat.hardware.puma762_axes import THESIS_TOOL_POINT_6
from kinestat.parallel.platform import Platform
from kinestat.sim.contact import Cell, make_cell
from kinestat.sim.sensor import Sensor
from kinestat.sim.surface import Cylinder, approach_distance, cylinder_ahead

__all__ = [
    "MAX_ITERATIONS",
    "MAX_SAMPLES",
    "DEFAULT_START",
    "DEFAULT_DIRECTION",
    "DEFAULT_PLANE_DISTANCE",
    "DEFAULT_PLANE_TILT_DEG",
    "TASKS",
    "CylinderSpec",
    "SimulatedCell",
    "RealDevices",
    "ControlRequest",
    "PreparedRun",
    "prepare_control",
    "default_plane",
    "simulated_cell",
    "device_model",
    "run_control",
    "report_dict",
    "plot_run",
]

PLANTS = ("kinestat", "mujoco")
"""The simulated cell's physics (``--sim``): the built-in contact simulator or MuJoCo."""

FOLLOW_APPROACH_STEP = 0.25
"""The follow task's default approach step (mm): its first contact force stays below 3 N."""
FOLLOW_MAX_ITERATIONS = MAX_ITERATIONS
"""The follow task's default cycle budget."""
MAX_APPROACH = 50.0
"""Default ``--max-approach`` (mm): how far from the start tool point an approach without
contact may carry the tool before the run stops (the default workpiece is
``DEFAULT_PLANE_DISTANCE`` ahead)."""

def default_plane(start_point: np.ndarray, direction: np.ndarray, distance: float,
                  tilt_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """The default workpiece: a plane ``distance`` mm ahead of the start tool point along the
    force direction, its normal tilted by ``tilt_deg`` from −direction (towards the fixed +y,
    or +z when the direction is along y) so that the reorientation (state c, Vibhute Fig. 5-2)
    is visible."""
    d = direction / np.linalg.norm(direction)
    ref = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
    perp = ref - (ref @ d) * d
    perp /= np.linalg.norm(perp)
    t = math.radians(tilt_deg)
    normal = -(math.cos(t) * d + math.sin(t) * perp)
    return start_point + distance * d, normal


@dataclass(frozen=True)
class CylinderSpec:
    """A simulated cylindrical workpiece: ``radius`` (mm), ``axis`` direction and, optionally,
    a ``point`` on its axis (default: its surface :data:`DEFAULT_PLANE_DISTANCE` mm ahead of
    the start tool point along F_req, as the default plane)."""

    radius: float
    axis: np.ndarray
    point: np.ndarray | None = None


@dataclass(frozen=True)
class SimulatedCell:
    """Settings of the simulated cell (``kinestat control`` without devices).

    ``cylinder`` None: a plane workpiece; ``plane_point``/``plane_normal`` None:
    :func:`default_plane`. ``plant``: "kinestat" (the built-in contact simulator behind the
    simulated devices) or "mujoco" (:mod:`kinestat.app.mujoco_cell`, in process).
    ``workpiece_stiffness``: the workpiece's normal stiffness (N/mm,
    :attr:`kinestat.sim.contact.Workpiece.stiffness`; None: rigid). ``noise``: leg-length noise
    (mm, standard deviation); ``ideal_sensor``: 1 nm leg encoders; ``rate_hz``: packet rate.
    """

    plane_point: np.ndarray | None = None
    plane_normal: np.ndarray | None = None
    friction: float = 0.0
    ideal_sensor: bool = False
    noise: float = 0.0
    rate_hz: float = 200.0
    seed: int = 0
    sim_legs: str = "thesis"
    cylinder: CylinderSpec | None = None
    plant: str = "kinestat"
    workpiece_stiffness: float | None = None


@dataclass(frozen=True)
class RealDevices:
    """The real cell: the Galil at ``host``:``port``, the encoder stream on ``serial``."""

    host: str
    port: int
    serial: str
    serial_format: Format = "ks"


@dataclass(frozen=True)
class ControlRequest:
    """One ``kinestat control`` run: the goal, the controller's settings and the cell.

    The tool and mount, as ForceCorrection.m's inputs: ``tool_point_6`` the unloaded tool point
    in frame 6 (``P_tool_6``, mm; None the thesis's (0, 0, 235)), ``a67`` the start pose's
    ``a67_F`` (None :func:`~kinestat.control.controller.default_a67`), ``mount`` the platform
    on the flange (:func:`~kinestat.app.calibrations.resolve_mount`). The simulated cell is
    built with the same tool and mount.
    """

    force: np.ndarray
    start_tool_point: np.ndarray
    cell: SimulatedCell | RealDevices
    force_tol: float = 0.5
    align_tol_deg: float = 0.5
    method: StepMethod = "stiffness"
    step: float = 1.0
    approach_step: float | None = None
    estimator: Estimator = "point"
    samples: int = 1
    max_iterations: int | None = None
    calibration: str = "thesis"
    platform: str | None = None
    procedure: Procedure = "kinestat"
    move_rule: MoveRule = "coordinated"
    assume_homed: bool = False
    task: str = "press"
    travel: float = 50.0
    travel_dir: np.ndarray | None = None
    travel_step: float = 1.0
    tilt_deg: float = 0.0
    auto_tilt: bool | None = None
    arm: ArmSpec | None = None
    probe_span: float | None = None
    max_approach: float = MAX_APPROACH
    tool_point_6: np.ndarray | None = None
    a67: np.ndarray | None = None
    mount: MountSpec = None


def simulated_cell(settings: SimulatedCell, start_point: np.ndarray, direction: np.ndarray,
                   platform: Platform | None = None, truth: NamedCalibration | None = None, *,
                   mount: np.ndarray | None = None, tool_point_6=THESIS_TOOL_POINT_6
                   ) -> tuple[Cell, Sensor]:
    """The thesis's experiment as a simulated cell and its leg sensor (Vibhute §5.1): the
    platform (default the prototype) with legs that follow ``truth`` (default
    ``settings.sim_legs``), the sensor reading counts through the truth's length maps; the
    platform on the flange at ``mount`` (default centred), the tool at ``tool_point_6``."""
    platform = resolve_platform(None) if platform is None else platform
    truth = (resolve_calibration(settings.sim_legs, platform, option="--sim-legs")
             if truth is None else truth)
    legs = truth.calibration
    if settings.ideal_sensor:
        legs, = ideal_counts(legs)
    sensor = Sensor(calibration=legs, noise=settings.noise)
    pp, pn = default_plane(start_point, direction, DEFAULT_PLANE_DISTANCE,
                           DEFAULT_PLANE_TILT_DEG)
    if settings.plane_point is not None:
        pp = settings.plane_point
    if settings.plane_normal is not None:
        pn = settings.plane_normal
    cell = make_cell(platform, plane_point=pp, plane_normal=pn, friction=settings.friction,
                     stiffness=settings.workpiece_stiffness, legs=truth.calibration,
                     mount=mount, tool_point_6=tool_point_6)
    cyl = settings.cylinder
    if cyl is not None:
        wp = (cylinder_ahead(start_point, direction, DEFAULT_PLANE_DISTANCE, cyl.radius, cyl.axis)
              if cyl.point is None else Cylinder(cyl.point, cyl.axis, cyl.radius))
        cell = replace(cell, workpiece=replace(wp, friction=settings.friction,
                                               stiffness=settings.workpiece_stiffness))
    return cell, sensor


def device_model(calibration: str = "thesis", platform: str | None = None) -> ControlModel:
    """The controller's model of the real cell: the platform (default the special 6-6
    prototype) centred on the flange, the thesis's tool point ``P_tool_6`` (App. D.1) and the
    leg calibration (default the thesis's maps)."""
    plat = resolve_platform(platform)
    return calibrated_model(plat, resolve_calibration(calibration, plat))


def _config(req: ControlRequest, model: ControlModel) -> ControllerConfig:
    return ControllerConfig(
        model=model, force=req.force, start_tool_point=req.start_tool_point,
        force_tol=req.force_tol, align_tol_deg=req.align_tol_deg, method=req.method,
        step=req.step, approach_step=_or(req.approach_step, FOLLOW_APPROACH_STEP, 1.0, req),
        estimator=req.estimator,
        max_iterations=_or(req.max_iterations, FOLLOW_MAX_ITERATIONS, 60, req),
        max_approach=req.max_approach, envelope=Envelope(), procedure=req.procedure,
        start_a67=_a67(req.a67, req.force))


A67_DOT_TOL = 1e-3
"""Largest |a67 · S6| of a given ``--a67`` (unit vectors; 0.06° off perpendicular): typed to
four decimals it passes and is made exactly perpendicular to S6."""


def _a67(a67, force) -> np.ndarray | None:
    """``--a67`` as a unit vector exactly perpendicular to the start S6 (along F_req)."""
    if a67 is None:
        return None
    a = np.asarray(a67, dtype=float)
    s6 = force / np.linalg.norm(force)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
        raise InputError(f"--a67 must be 3 finite numbers, not all zero, got {a.tolist()}")
    a = a / np.linalg.norm(a)
    dot = float(a @ s6)
    if abs(dot) > A67_DOT_TOL:
        raise InputError(f"--a67 must be perpendicular to the start tool axis S6 (along "
                         f"--direction): a67 · S6 = {dot:.4g}, more than {A67_DOT_TOL:g}")
    a = a - dot * s6
    return a / np.linalg.norm(a)


def _or(value, follow_default, press_default, req: ControlRequest):
    """``value``, or the task's default when it is None."""
    if value is not None:
        return value
    return follow_default if req.task == "follow" else press_default


@dataclass(frozen=True, eq=False)
class PreparedRun:
    """A run assembled but not started: the controller's settings, the simulated cell and its
    sensor (None with real devices) and the log header describing the cell."""

    request: ControlRequest
    config: ControllerConfig
    header: dict
    cell: Cell | None = None
    sensor: Sensor | None = None
    follow: FollowConfig | None = None
    arm: PlacedArm | None = None
    plant: object | None = None  # the MuJoCo plant (--sim mujoco), built and at rest


def prepare_control(req: ControlRequest) -> PreparedRun:
    """Assemble the cell and the controller of ``req`` (checks every setting; nothing starts).

    The follow task's request is checked here too (:class:`~kinestat.control.follow.FollowConfig`:
    a travel direction along the approach, a force the platform cannot carry inside the
    envelope are refused before anything moves)."""
    if req.task not in TASKS:
        raise InputError(f"--task must be one of {', '.join(TASKS)}, got {req.task!r}")
    prepared = _prepare_cell(req)
    if req.task != "follow":
        return prepared
    travel_dir = (default_travel_dir(prepared.config.start_s6) if req.travel_dir is None
                  else req.travel_dir)
    follow = FollowConfig(base=prepared.config, travel=req.travel, travel_dir=travel_dir,
                          travel_step=req.travel_step, tilt_deg=req.tilt_deg,
                          auto_tilt=req.auto_tilt,
                          probe_span=PROBE_SPAN if req.probe_span is None else req.probe_span)
    header = dict(prepared.header, task="follow", travel=req.travel,
                  travel_dir=follow.travel_dir, tilt_deg=req.tilt_deg, auto_tilt=req.auto_tilt,
                  probe_span=follow.probe_span)
    return replace(prepared, follow=follow, header=header)


def _prepare_cell(req: ControlRequest) -> PreparedRun:
    """The press task's assembly (the follow task adds its settings on top)."""
    if not (isinstance(req.samples, int) and 1 <= req.samples <= MAX_SAMPLES):
        raise InputError(f"samples (sensor packets averaged per measurement) must be in "
                         f"1..{MAX_SAMPLES}, got {req.samples!r}")
    direction = req.force / np.linalg.norm(req.force)
    if req.move_rule not in MOVE_RULES:
        raise InputError(f"--move-rule must be one of {', '.join(MOVE_RULES)}, got "
                         f"{req.move_rule!r}")
    header: dict = {"simulated": isinstance(req.cell, SimulatedCell),
                    "move_rule": req.move_rule}
    platform = resolve_platform(req.platform)
    cal = resolve_calibration(req.calibration, platform)
    mount, mount_source = resolve_mount(req.mount, platform, req.platform)
    tool6 = THESIS_TOOL_POINT_6 if req.tool_point_6 is None else req.tool_point_6
    header["calibration"] = cal.name
    header["platform"] = req.platform or "prototype"
    header["mount_source"] = mount_source
    if isinstance(req.cell, SimulatedCell):
        s = req.cell
        if s.plant not in PLANTS:
            raise InputError(f"--sim must be one of {', '.join(PLANTS)}, got {s.plant!r}")
        header["plant"] = s.plant
        truth = resolve_calibration(s.sim_legs, platform, option="--sim-legs")
        if s.ideal_sensor:  # the controller reads the same fine counts
            _, fine = ideal_counts(truth.calibration, cal.calibration)
            cal = NamedCalibration(cal.name, fine)
        cell, sensor = simulated_cell(s, req.start_tool_point, direction, platform, truth,
                                      mount=mount, tool_point_6=tool6)
        config = _config(req, calibrated_model(platform, cal, tool_point_6=tool6, mount=mount))
        placed_arm = None
        if req.arm is not None:
            config, placed_arm = _with_arm(req.arm, config)
            header["arm"] = placed_arm.header()
        wp = cell.workpiece
        _check_ahead(wp, req.start_tool_point, direction, config.max_approach)
        header.update({"plane_point": wp.point, "plane_normal": wp.normal} if s.cylinder is None
                      else {"workpiece": {"kind": "cylinder", "radius": wp.radius,
                                          "axis": wp.axis, "point": wp.point}})
        header.update({"friction": s.friction, "workpiece_stiffness": s.workpiece_stiffness,
                       "ideal_sensor": s.ideal_sensor, "noise": s.noise,
                       "rate_hz": s.rate_hz, "sim_legs": truth.name})
        prepared = PreparedRun(req, config, header, cell, sensor, arm=placed_arm)
        if s.plant == "mujoco":  # the scene is built now: a model MuJoCo refuses stops here
            prepared = _with_plant(prepared, _mujoco_plant(prepared))
        return prepared
    if req.arm is not None:
        raise InputError("--arm: another arm runs on the in-process simulated cell only; the "
                         "Galil and encoder protocols are the PUMA 762's hardware (drop "
                         "--galil/--serial)")
    d = req.cell
    header.update({"galil": f"{d.host}:{d.port}", "serial": d.serial,
                   "serial_format": d.serial_format})
    return PreparedRun(req, _config(req, calibrated_model(platform, cal, tool_point_6=tool6,
                                                          mount=mount)), header)


def _check_ahead(workpiece, start_point, direction, max_approach: float) -> None:
    """Refuse a simulated workpiece that the approach from the start tool point along F_req
    would not meet within ``max_approach`` (before anything moves)."""
    kind = "cylinder" if isinstance(workpiece, Cylinder) else "plane"
    gap = float(workpiece.gap(start_point))
    if gap < 0.0:
        raise InputError(f"the start tool point lies {-gap:.3g} mm inside the simulated {kind}: "
                         "the run starts unloaded, with the tool clear of the workpiece (move "
                         "the workpiece, or the start with --start)")
    dist = approach_distance(workpiece, start_point, direction)
    if dist <= max_approach:
        return
    where = ("never meets it" if math.isinf(dist)
             else f"meets it only {dist:.1f} mm ahead")
    raise InputError(f"the simulated {kind} is not ahead of the tool: the approach from the "
                     f"start tool point along F_req {where}, beyond --max-approach "
                     f"{max_approach:g} mm (move the workpiece, or the start with --start)")


def _with_arm(spec: ArmSpec, config: ControllerConfig) -> tuple[ControllerConfig, PlacedArm]:
    """The controller's settings with the arm of ``spec`` placed in the cell (its start pose
    checked reachable: an InputError before anything moves). The vernier is off: the arm's
    command resolution (:data:`~kinestat.app.arm_cell.ARM_DEG_PER_COUNT`) is already fine."""
    model = config.model
    placed_arm = place_arm(spec.model, config.start_tool_point, config.start_s6,
                           config.start_a67, model.tool_point_6, base=spec.base,
                           source_name=spec.name)
    return (replace(config, model=arm_control_model(model, placed_arm), vernier=False),
            placed_arm)


def run_control(prepared: PreparedRun, log_path: Path, *,
                progress: Callable[[dict], None] | None = None) -> RunReport:
    """Start the devices (simulated or real) and run the kinestatic procedure (Vibhute ch. 5)
    on the prepared cell, logging every cycle to ``log_path``.

    The devices are started and connected BEFORE the log is created: a refused connection or
    a missing serial device leaves no (empty) log behind. Every final command (axis 5
    compensated) goes through the envelope (:func:`~kinestat.control.envelope.sent_command_guard`).
    """
    req, config, header = prepared.request, prepared.config, prepared.header
    decide_fn = (None if prepared.follow is None
                 else functools.partial(decide_follow, prepared.follow))
    safety = {"guard": sent_command_guard(config.envelope, config.model),
              "max_stream_faults": config.envelope.max_stream_faults,
              "move_rule": req.move_rule}
    if prepared.plant is not None:
        return _run_mujoco(prepared, log_path, safety, progress, decide_fn)
    if prepared.arm is not None:
        io = arm_io(prepared.cell, prepared.sensor, prepared.arm, seed=req.cell.seed,
                    guard=safety["guard"])
        with CycleLog(log_path) as cycle_log:
            return run(config, io, cycle_log, progress=progress, extra_header=header,
                       decide_fn=decide_fn)
    if isinstance(req.cell, SimulatedCell):
        with SimHarness(prepared.cell, prepared.sensor, start_counts=start_counts(config),
                        rate_hz=req.cell.rate_hz, seed=req.cell.seed) as h:
            io = h.device_io(samples=req.samples, **safety)
            with CycleLog(log_path) as cycle_log:
                return run(config, io, cycle_log, progress=progress, extra_header=header,
                           decide_fn=decide_fn)
    d = req.cell
    client = GalilClient(d.host, d.port).connect()
    try:
        if not req.assume_homed and not is_homed(client):
            reason = (f"the robot behind the Galil at {d.host}:{d.port} is not homed in "
                      "this controller session: run `kinestat home --galil "
                      f"{d.host}:{d.port}` first (or pass --assume-homed); nothing moved")
            with CycleLog(log_path) as cycle_log:
                return refuse(config, cycle_log, reason, extra_header=header)
        with EncoderReader(d.serial, fmt=d.serial_format) as reader:
            io = DeviceIO(client, reader, samples=req.samples, settle=0.1, **safety)
            with CycleLog(log_path) as cycle_log:
                return run(config, io, cycle_log, progress=progress, extra_header=header,
                           decide_fn=decide_fn)
    finally:
        client.close()


def _mujoco_plant(prepared: PreparedRun):
    """The MuJoCo plant of a prepared simulated cell at its start pose (at rest)."""
    from kinestat.app.mujoco_cell import mujoco_plant  # lazy: mujoco only for --sim mujoco

    config = prepared.config
    counts = (arm_start_counts(prepared.arm) if prepared.arm is not None
              else start_counts(config))
    return mujoco_plant(prepared.cell, config.model, counts)


def _with_plant(prepared: PreparedRun, plant) -> PreparedRun:
    """The prepared run on ``plant``, its controller told the top's and the tool's weight (the
    scene's, as a user declares a tool's mass and centre of mass)."""
    mass, com, gravity = plant.scene.top_load()
    config = prepared.config
    if mass > 0.0:
        model = replace(config.model, payload=Payload(mass, com, gravity))
        config = replace(config, model=model)
    header = dict(prepared.header, payload={"mass_kg": mass, "com_top_mm": com.tolist()})
    return replace(prepared, plant=plant, config=config, header=header)


def _run_mujoco(prepared: PreparedRun, log_path: Path, safety: dict, progress, decide_fn
                ) -> RunReport:
    """The run on the MuJoCo plant, in process; the report carries its simulated time."""
    from kinestat.app.mujoco_cell import MujocoIO  # lazy: mujoco only for --sim mujoco

    req = prepared.request
    io = MujocoIO(prepared.plant, prepared.config.model, prepared.sensor,
                  move_rule=req.move_rule, guard=safety["guard"], seed=req.cell.seed)
    with CycleLog(log_path) as cycle_log:
        report = run(prepared.config, io, cycle_log, progress=progress,
                     extra_header=prepared.header, decide_fn=decide_fn)
    figures = io.figures()
    if report.iterations:
        figures["sim_seconds_per_cycle"] = figures["sim_time_s"] / report.iterations
    report.plant_figures = figures
    return report


def report_dict(prepared: PreparedRun, report: RunReport) -> dict:
    """The run's JSON report: :meth:`RunReport.as_dict`, and for the follow task ``completed``,
    ``travel`` (mm along the surface), ``normal_force_rms_error``/``normal_force_max_error``
    (N, over the travel cycles), ``contact_lost`` (and the true errors when simulated),
    ``travel_dir`` (the initial travel direction, unit: given, or the default); always the
    run's tool and mount: ``tool_point_6`` (mm, frame 6), ``a67_start`` (fixed frame),
    ``mount`` (``6_BT``, 4x4) and ``mount_source`` ("centred", "pose" or the file)."""
    out = report.as_dict()
    if prepared.cell is not None:
        out["plant"] = prepared.header.get("plant", "kinestat")
        figures = getattr(report, "plant_figures", None) or {}
        out.update(figures)
        if "sim_time_s" in figures:
            out["time_to_goal_s"] = figures["sim_time_s"] if report.converged else None
        if prepared.follow is not None and figures.get("sim_time_s"):
            out["travel_speed_mm_s"] = None  # filled below from the travel
    model = prepared.config.model
    out["tool_point_6"] = model.tool_point_6.tolist()
    out["a67_start"] = prepared.config.start_a67.tolist()
    out["mount"] = model.mount.tolist()
    out["mount_source"] = prepared.header.get("mount_source", "centred")
    if prepared.follow is not None:
        out["task"] = "follow"
        out["completed"] = report.converged
        out.update(follow_summary(report.cycles, prepared.config.force_target,
                                  prepared.follow.travel))
        out["travel_dir"] = prepared.follow.travel_dir.tolist()  # the initial one (unit)
        if "travel_speed_mm_s" in out and out.get("travel") is not None:
            out["travel_speed_mm_s"] = out["travel"] / out["sim_time_s"]
    if prepared.arm is not None:
        out["arm"] = prepared.arm.header()
    return out


def plot_run(log_path: Path, plot_dir: Path) -> list[str]:
    """Write the wrench-vs-state plot of a run's log (Vibhute Fig. 5-2's states), and for a
    follow run the normal force against travel and the tool path."""
    from kinestat.viz.control_plots import write_plots  # lazy: matplotlib only when plotting
    from kinestat.viz.follow_plots import write_follow_plots  # lazy: as above

    records = read_log(log_path)
    paths = write_plots(records, plot_dir)
    if any(r.get("type") == "cycle" and r.get("task") for r in records):
        paths += write_follow_plots(records, plot_dir)
    return [str(p) for p in paths]
