"""Composition root of ``kinestat control``: a :class:`~kinestat.control.runspec.RunSpec` in,
the prepared run out — the cell, the controller's settings and the task.

The CLI (:mod:`kinestat.cli.control`) and :func:`kinestat.app.run` describe a run as one
:class:`RunSpec` (``ControlRequest`` is its older name); :func:`prepare_control` builds what it
needs — the thesis's experiment as a simulated cell (Vibhute 2011 §5.1: the special 6-6
platform centred on the flange, the tool at ``P_tool_6``, a tilted plane ahead of the start
tool point) or the real cell's model, with another arm when ``RunSpec.arm`` names one
(:mod:`kinestat.app.arm_cell`) — and :func:`run_control` opens the cell
(:mod:`kinestat.app.cell_factory`) and runs the task on it (:func:`kinestat.control.loop.run`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from kinestat.app.arm_cell import (
    ArmSpec,
    PlacedArm,
    arm_control_model,
    arm_start_counts,
    place_arm,
)
from kinestat.app.calibrations import (
    NamedCalibration,
    calibrated_model,
    ideal_counts,
    resolve_calibration,
    resolve_mount,
    resolve_platform,
)
from kinestat.app.cell_factory import NotReady, open_cell
from kinestat.app.control_defaults import (
    DEFAULT_DIRECTION,
    DEFAULT_PLANE_DISTANCE,
    DEFAULT_PLANE_TILT_DEG,
    DEFAULT_START,
)
from kinestat.app.sim_cell import start_counts
from kinestat.control.controller import MAX_ITERATIONS, ControllerConfig
from kinestat.control.envelope import Envelope
from kinestat.control.follow import FollowConfig, default_travel_dir
from kinestat.control.follow_task import FollowTask
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import RunReport, refuse, run
from kinestat.control.model import ControlModel
from kinestat.control.payload import Payload
from kinestat.control.runspec import (
    TASKS,
    CylinderSpec,
    RealDevices,
    RunSpec,
    SimulatedCell,
)
from kinestat.control.task import Task, as_task
from kinestat.devices.cell_io import MAX_SAMPLES
from kinestat.devices.motion import MOVE_RULES
from kinestat.errors import InputError
from kinestat.parallel.platform import Platform
from kinestat.robots.puma762.axes import THESIS_TOOL_POINT_6
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


ControlRequest = RunSpec
"""The older name of :class:`~kinestat.control.runspec.RunSpec` (one run of ``kinestat
control``)."""


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


def _config(req: RunSpec, model: ControlModel) -> ControllerConfig:
    if req.top_mass is not None:
        model = replace(model, top_mass=req.top_mass)
    return ControllerConfig(
        model=model, force=req.force, start_tool_point=req.start_tool_point,
        force_tol=req.force_tol, align_tol_deg=req.align_tol_deg, method=req.method,
        step=req.step, approach_step=req.approach_step, estimator=req.estimator,
        max_iterations=req.max_iterations, max_approach=req.max_approach, envelope=Envelope(),
        procedure=req.procedure, start_a67=req.a67)


@dataclass(frozen=True, eq=False)
class PreparedRun:
    """A run assembled but not started: its spec, the controller's settings, the simulated
    cell and its sensor (None with real devices), the follow task's settings, the placed arm,
    the MuJoCo plant and the log header describing the cell; :attr:`task` is what the loop
    runs."""

    request: RunSpec
    config: ControllerConfig
    header: dict
    cell: Cell | None = None
    sensor: Sensor | None = None
    follow: FollowConfig | None = None
    arm: PlacedArm | None = None
    plant: object | None = None  # the MuJoCo plant (--sim mujoco), built and at rest

    @property
    def spec(self) -> RunSpec:
        return self.request

    @property
    def task(self) -> Task:
        """The task the loop runs (:mod:`kinestat.control.task`)."""
        if self.follow is not None:
            return FollowTask(self.follow)
        return as_task(self.config)


def prepare_control(req: RunSpec) -> PreparedRun:
    """Assemble the cell, the controller and the task of ``req`` (nothing starts).

    The settings were checked when ``req`` was made (:class:`RunSpec`); what needs the cell
    is checked here: the workpiece ahead of the tool, the platform files, the arm's start
    pose, the follow task's force inside the envelope
    (:class:`~kinestat.control.follow.FollowConfig`) — before anything moves."""
    prepared = _prepare_cell(req)
    if req.task != "follow":
        return prepared
    travel_dir = (default_travel_dir(prepared.config.start_s6) if req.travel_dir is None
                  else req.travel_dir)
    follow = FollowConfig(base=prepared.config, travel=req.travel, travel_dir=travel_dir,
                          travel_step=req.travel_step, tilt_deg=req.tilt_deg,
                          auto_tilt=req.auto_tilt, probe_span=req.probe_span)
    header = dict(prepared.header, task="follow", travel=req.travel,
                  travel_dir=follow.travel_dir, tilt_deg=req.tilt_deg, auto_tilt=req.auto_tilt,
                  probe_span=follow.probe_span)
    return replace(prepared, follow=follow, header=header)


def _prepare_cell(req: RunSpec) -> PreparedRun:
    """The press task's assembly (the follow task adds its settings on top)."""
    if not (isinstance(req.samples, int) and 1 <= req.samples <= MAX_SAMPLES):
        raise InputError(f"--samples must be in 1..{MAX_SAMPLES} (packets averaged per "
                         f"measurement), got {req.samples!r}")
    if req.move_rule not in MOVE_RULES:
        raise InputError(f"--move-rule must be one of {', '.join(MOVE_RULES)}, got "
                         f"{req.move_rule!r}")
    platform = resolve_platform(req.platform)
    cal = resolve_calibration(req.calibration, platform)
    mount, mount_source = resolve_mount(req.mount, platform, req.platform)
    tool6 = THESIS_TOOL_POINT_6 if req.tool_point_6 is None else req.tool_point_6
    header: dict = {"simulated": isinstance(req.cell, SimulatedCell),
                    "move_rule": req.move_rule, "calibration": cal.name,
                    "platform": req.platform or "prototype", "mount_source": mount_source}
    if isinstance(req.cell, RealDevices):
        d = req.cell
        header.update({"galil": f"{d.host}:{d.port}", "serial": d.serial,
                       "serial_format": d.serial_format})
        model = calibrated_model(platform, cal, tool_point_6=tool6, mount=mount)
        return PreparedRun(req, _config(req, model), header)
    s = req.cell
    header["plant"] = s.plant
    truth = resolve_calibration(s.sim_legs, platform, option="--sim-legs")
    if s.ideal_sensor:  # the controller reads the same fine counts
        _, fine = ideal_counts(truth.calibration, cal.calibration)
        cal = NamedCalibration(cal.name, fine)
    cell, sensor = simulated_cell(s, req.start_tool_point, req.direction, platform, truth,
                                  mount=mount, tool_point_6=tool6)
    config = _config(req, calibrated_model(platform, cal, tool_point_6=tool6, mount=mount))
    placed_arm = None
    if req.arm is not None:
        config, placed_arm = _with_arm(req.arm, config)
        header["arm"] = placed_arm.header()
    _check_ahead(cell.workpiece, req.start_tool_point, req.direction, config.max_approach)
    header.update(_workpiece_header(cell.workpiece, s))
    header["sim_legs"] = truth.name
    prepared = PreparedRun(req, config, header, cell, sensor, arm=placed_arm)
    if s.plant == "mujoco":  # the scene is built now: a model MuJoCo refuses stops here
        prepared = _with_plant(prepared, _mujoco_plant(prepared))
    return prepared


def _workpiece_header(wp, s: SimulatedCell) -> dict:
    """The log header's description of the simulated workpiece and sensor."""
    out = ({"plane_point": wp.point, "plane_normal": wp.normal} if s.cylinder is None
           else {"workpiece": {"kind": "cylinder", "radius": wp.radius, "axis": wp.axis,
                               "point": wp.point}})
    out.update({"friction": s.friction, "workpiece_stiffness": s.workpiece_stiffness,
                "ideal_sensor": s.ideal_sensor, "noise": s.noise, "rate_hz": s.rate_hz})
    return out


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
    """Open the prepared run's cell (:func:`kinestat.app.cell_factory.open_cell`: the built-in
    simulator, MuJoCo or the real devices) and run its task on it
    (:func:`kinestat.control.loop.run`), logging every cycle to ``log_path``.

    The devices are started and connected BEFORE the log is created: a refused connection or
    a missing serial device leaves no (empty) log behind. Every final command (axis 5
    compensated) goes through the envelope
    (:func:`~kinestat.control.envelope.sent_command_guard`).
    """
    with open_cell(prepared) as io, CycleLog(log_path) as cycle_log:
        if isinstance(io, NotReady):
            return refuse(prepared.config, cycle_log, io.reason, extra_header=prepared.header)
        report = run(prepared.task, io, cycle_log, progress=progress,
                     extra_header=prepared.header)
        figures = getattr(io, "figures", None)
        if figures is not None:  # MuJoCo: the simulated time
            report.plant_figures = _plant_figures(figures(), report)
    return report


def _plant_figures(figures: dict, report: RunReport) -> dict:
    if report.iterations:
        figures["sim_seconds_per_cycle"] = figures["sim_time_s"] / report.iterations
    return figures


def _with_plant(prepared: PreparedRun, plant) -> PreparedRun:
    """The prepared run on ``plant``, its controller told the top's and the tool's mass, their
    weight and the radius of the tool's ball tip (the scene's, as a user declares a tool's
    mass, centre of mass and tip)."""
    mass, com, gravity = plant.scene.top_load()
    config = prepared.config
    model = replace(config.model, tip_radius=plant.scene.tip_radius_mm,
                    top_mass=plant.scene.params.top_mass)
    if mass > 0.0:
        model = replace(model, payload=Payload(mass, com, gravity))
    config = replace(config, model=model)
    header = dict(prepared.header, payload={"mass_kg": mass, "com_top_mm": com.tolist()},
                  tip_radius_mm=model.tip_radius, top_mass_kg=model.top_mass)
    return replace(prepared, plant=plant, config=config, header=header)


def _scene_params(req: RunSpec):
    """The MuJoCo scene's settings from the request (``--top-weight``, ``--top-mass``)."""
    from kinestat.sim.mujoco_scene import SceneParams  # lazy: mujoco only for --sim mujoco

    kw = {} if req.top_mass is None else {"top_mass": req.top_mass}
    return SceneParams(top_weight=req.cell.top_weight, **kw)


def _mujoco_plant(prepared: PreparedRun):
    """The MuJoCo plant of a prepared simulated cell at its start pose (at rest)."""
    from kinestat.app.mujoco_cell import mujoco_plant  # lazy: mujoco only for --sim mujoco

    config = prepared.config
    counts = (arm_start_counts(prepared.arm) if prepared.arm is not None
              else start_counts(config))
    return mujoco_plant(prepared.cell, config.model, counts,
                        params=_scene_params(prepared.request))


def report_dict(prepared: PreparedRun, report: RunReport) -> dict:
    """The run's JSON report: :meth:`RunReport.as_dict`, the task's own figures
    (:meth:`~kinestat.control.task.Task.report`): for the follow task ``task``, ``completed``,
    ``travel`` (mm along the surface), ``normal_force_rms_error``/``normal_force_max_error``
    (N, over the travel cycles), ``contact_lost`` (and the true errors when simulated),
    ``travel_dir`` (the initial travel direction, unit: given, or the default); always the
    run's tool and mount: ``tool_point_6`` (mm, frame 6; generic name ``tool_offset``),
    ``a67_start`` (fixed frame; generic name ``x_base_end_start``),
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
    # the same in generic names (any arm): the tool in the end frame, the end frame's x axis
    out["tool_offset"], out["x_base_end_start"] = out["tool_point_6"], out["a67_start"]
    out["mount"] = model.mount.tolist()
    out["mount_source"] = prepared.header.get("mount_source", "centred")
    task_figures = prepared.task.report(report.cycles)  # the task's own (follow's)
    if task_figures:
        out["task"] = task_figures.pop("task")
        out["completed"] = report.converged
        out.update(task_figures)
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
