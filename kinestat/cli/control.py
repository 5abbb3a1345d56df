"""``kinestat control``: kinestatic force control of the PUMA 762 + compliant platform cell.

With no device arguments the command starts the Galil simulator and the encoder emitter
itself (loopback TCP and a pty), builds the simulated cell (the thesis's experiment by
default: Vibhute 2011 §5.1) and drives it through the real client and reader. With
``--galil HOST:PORT --serial DEVICE`` it drives real hardware. With ``--arm MODEL`` another
6-joint arm with an analytic solver carries the platform in the in-process simulated cell
(:mod:`kinestat.app.arm_cell`). This module only parses and prints; the assembly is
:mod:`kinestat.app.control_run`.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import typer

from kinestat.app.control_defaults import (
    DEFAULT_DIRECTION,
    DEFAULT_PLANE_DISTANCE,
    DEFAULT_PLANE_TILT_DEG,
    DEFAULT_START,
    TASKS,
)
from kinestat.app.signals import stop_on_signals
from kinestat.cli._model import (
    base_option,
    length_unit_option,
    load_model,
    scale_option,
    tip_option,
)
from kinestat.cli._options import check_seed, flag
from kinestat.cli._output import console as out_console
from kinestat.cli._output import (
    err_console,
    literal,
    parse_floats,
    parse_pose,
    print_json,
    table,
)
from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.devices.ceilings import MAX_SAMPLES
from kinestat.errors import InputError, KinestatError


def register(app: typer.Typer) -> None:
    app.command("control")(control_command)


def _host_port(text: str) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep or not host:
        raise InputError(f"--galil: expected HOST:PORT, got {text!r}")
    try:
        p = int(port)
    except ValueError as exc:
        raise InputError(f"--galil: port {port!r} is not a number") from exc
    if not 0 < p < 65536:
        raise InputError(f"--galil: port {p} outside 1..65535")
    return host, p


def _run_dir(base: Path) -> Path:
    """A new run directory ``base/<timestamp>[-k]``, created here: two runs started in the
    same second each get their own (mkdir is atomic; checking for it first was not, and two
    runs wrote one interleaved log)."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    base.mkdir(parents=True, exist_ok=True)
    k = 1
    while True:
        d = base / (stamp if k == 1 else f"{stamp}-{k}")
        try:
            d.mkdir()
            return d
        except FileExistsError:
            k += 1


def _workpiece(text: str | None):
    """``--workpiece``: "plane" (None) or "cylinder:radius=R,axis=x,y,z[,point=x,y,z]" (a
    :class:`~kinestat.app.control_run.CylinderSpec`)."""
    from kinestat.app.control_run import CylinderSpec  # lazy: start-up (numba)

    if text is None or text.strip() == "plane":
        return None
    kind, sep, rest = text.partition(":")
    if kind.strip() != "cylinder" or not sep:
        raise InputError(f"--workpiece: expected 'plane' or 'cylinder:radius=R,axis=x,y,z"
                         f"[,point=x,y,z]', got {text!r}")
    fields: dict[str, list[str]] = {}
    key = None
    for tok in rest.split(","):
        name, eq, val = tok.partition("=")
        if eq:
            key = name.strip()
            if key not in ("radius", "axis", "point") or key in fields:
                raise InputError(f"--workpiece: unknown or repeated field {key!r} in {text!r}")
            fields[key] = [val]
        elif key is None:
            raise InputError(f"--workpiece: expected name=value after 'cylinder:', got {text!r}")
        else:
            fields[key].append(tok)
    if "radius" not in fields or "axis" not in fields:
        raise InputError(f"--workpiece: a cylinder needs radius= and axis=, got {text!r}")
    radius = parse_floats(",".join(fields["radius"]), 1, "workpiece radius")[0]
    axis = parse_floats(",".join(fields["axis"]), 3, "workpiece axis")
    point = (parse_floats(",".join(fields["point"]), 3, "workpiece point")
             if "point" in fields else None)
    return CylinderSpec(radius=float(radius), axis=axis, point=point)


def _cell(galil, serial, serial_format, plane_point, plane_normal, ideal_sensor, noise, friction,
          rate, seed, sim_legs="thesis", workpiece=None, sim="kinestat",
          workpiece_stiffness=None):
    """The cell the options describe: simulated (no device options) or the real devices."""
    from kinestat.app.control_run import (  # lazy: start-up (numba)
        PLANTS,
        RealDevices,
        SimulatedCell,
    )

    if sim not in PLANTS:
        raise InputError(f"--sim must be one of {', '.join(PLANTS)}, got {sim!r}")
    if galil is not None and sim != "kinestat":
        raise InputError("--sim chooses the simulated cell's physics; with real devices "
                         "(--galil/--serial) run `kinestat sim galil --plant mujoco` and give "
                         "its addresses instead")

    if (galil is None) != (serial is None):
        raise InputError("give both --galil HOST:PORT and --serial DEVICE for real devices, or "
                         "neither to run the simulated cell")
    if galil is not None and (plane_point or plane_normal or ideal_sensor or noise or friction
                              or sim_legs != "thesis" or workpiece is not None
                              or workpiece_stiffness is not None):
        raise InputError("--plane-point/--plane-normal/--ideal-sensor/--noise/--friction/"
                         "--sim-legs/--workpiece/--workpiece-stiffness describe the simulated "
                         "cell; they cannot be used "
                         "with real devices")
    cylinder = _workpiece(workpiece)
    if cylinder is not None and (plane_point or plane_normal):
        raise InputError("--plane-point/--plane-normal describe a plane workpiece; with "
                         "--workpiece cylinder:... give the cylinder's point= instead")
    if serial_format not in ("ks", "legacy"):
        raise InputError(f"--serial-format must be 'ks' or 'legacy', got {serial_format!r}")
    if ideal_sensor and noise:
        raise InputError("--ideal-sensor and --noise exclude each other")
    if not (math.isfinite(noise) and noise >= 0):
        raise InputError(f"--noise must be >= 0 mm, got {noise}")
    if workpiece_stiffness is not None and not (math.isfinite(workpiece_stiffness)
                                                and workpiece_stiffness > 0):
        raise InputError(f"--workpiece-stiffness must be a finite number of N/mm > 0, got "
                         f"{workpiece_stiffness}")

    if galil is None:
        return SimulatedCell(
            plane_point=parse_floats(plane_point, 3, "plane-point") if plane_point else None,
            plane_normal=parse_floats(plane_normal, 3, "plane-normal") if plane_normal else None,
            friction=friction, ideal_sensor=ideal_sensor, noise=noise, rate_hz=rate, seed=seed,
            sim_legs=sim_legs, cylinder=cylinder, plant=sim,
            workpiece_stiffness=workpiece_stiffness)
    host, port = _host_port(galil)
    return RealDevices(host=host, port=port, serial=serial, serial_format=serial_format)


THESIS_ARM_NAME = "puma762"
"""``--arm`` naming the thesis's PUMA 762 (the default): today's cell, Galil and encoders."""


def _arm(arm, tip, base, scale, length_unit, arm_base, galil, serial):
    """The ``--arm`` of the run (an :class:`~kinestat.app.arm_cell.ArmSpec`), or None for the
    thesis's PUMA 762; every refusal before anything is loaded or moves."""
    urdf = [o for o, v in (("--tip", tip), ("--base", base), ("--scale", scale),
                           ("--length-unit", length_unit)) if v is not None]
    if arm is None:
        if urdf or arm_base is not None:
            raise InputError(f"{'/'.join(urdf + (['--arm-base'] if arm_base else []))}: "
                             "options of --arm MODEL; give --arm")
        return None
    if arm == THESIS_ARM_NAME and not urdf:
        if arm_base is not None:
            raise InputError("--arm-base: the thesis's PUMA 762 is the cell's fixed frame; "
                             "--arm-base places another arm")
        return None
    if galil is not None or serial is not None:
        raise InputError(f"--arm {arm}: another arm runs on the in-process simulated cell "
                         "only; the Galil and encoder protocols are the PUMA 762's hardware "
                         "(drop --galil/--serial)")
    from kinestat.app.arm_cell import ArmSpec  # lazy: start-up (numba)

    b = None if arm_base is None else parse_floats(arm_base, 3, "arm-base")
    return ArmSpec(model=load_model(arm, tip, base, scale, length_unit), base=b, name=arm)


def _print_progress(rec: dict) -> None:
    """One line per cycle on stderr."""
    m = rec["measured"]
    c = rec["commanded"]
    what = rec["decision"] if c is None else c["action"]
    extra = ""
    if c is not None and c["step"]:
        extra += f" step {c['step']:+.4f} mm"
    if c is not None and c["rotation_deg"]:
        extra += f" turn {c['rotation_deg']:.3f}°"
    fmag = float(np.linalg.norm(m["estimate"]))
    task = rec.get("task")
    if task:
        extra += f"  F_n {task['normal_force']:7.4f} N  travel {task['travel']:7.3f} mm"
    err_console.print(f"cycle {rec['cycle']:3d}  state {rec['state']}  |F| {fmag:7.4f} N"
                      f"  -> {what}{extra}")


def control_command(
    force: float = typer.Option(4.0, "--force", help="Target force magnitude |F_req| (N)."),
    direction: str = typer.Option(
        DEFAULT_DIRECTION, "--direction",
        help="Direction of F_req x,y,z (fixed frame): the approach direction and the start "
        "pose's tool axis. Default the thesis's 0.9713 i + 0 j - 0.2375 k."),
    force_tol: float = typer.Option(0.5, "--force-tol", help="Tolerance on |F| (N)."),
    align_tol_deg: float = typer.Option(
        0.5, "--align-tol-deg", help="Tolerance on the angle between S6 and the force (deg)."),
    start: str = typer.Option(DEFAULT_START, "--start",
                              help="Start tool point P_tool_F x,y,z (mm, fixed frame)."),
    plane_point: str = typer.Option(
        None, "--plane-point",
        help=f"A point of the workpiece plane x,y,z (mm). Default: {DEFAULT_PLANE_DISTANCE} mm "
        "ahead of the start tool point along F_req (simulation only)."),
    plane_normal: str = typer.Option(
        None, "--plane-normal",
        help=f"Workpiece normal x,y,z, pointing out of the material towards the tool. Default: "
        f"-F_req tilted by {DEFAULT_PLANE_TILT_DEG} deg (simulation only)."),
    method: str = typer.Option(
        "stiffness", "--method",
        help="Step along S6: 'stiffness' (Newton step from the platform stiffness) or 'fixed' "
        "(the thesis's constant step)."),
    step: float = typer.Option(
        1.0, "--step", help="Fixed step, and the largest stiffness step (mm)."),
    approach_step: float = typer.Option(
        None, "--approach-step", help="Step along S6 while no contact is measured (mm; default "
        "1 for press, 0.25 for follow)."),
    estimator: str = typer.Option(
        "point", "--estimator",
        help="Force the controller acts on: 'point' (point-contact fit) or 'wrench' (the "
        "equivalent wrench's force, as the thesis)."),
    ideal_sensor: bool = flag(
        False, "--ideal-sensor", help="Simulated leg encoders without quantisation (1 nm)."),
    noise: float = typer.Option(
        0.0, "--noise", help="Simulated leg-length noise, standard deviation (mm)."),
    friction: float = typer.Option(
        0.0, "--friction", help="Coulomb friction coefficient of the simulated workpiece."),
    galil: str = typer.Option(None, "--galil", help="Real Galil controller HOST:PORT."),
    serial: str = typer.Option(None, "--serial",
                               help="Real encoder stream: serial device or pyserial URL."),
    serial_format: str = typer.Option(
        "ks", "--serial-format", help="Encoder packet format: 'ks' or 'legacy' (thesis)."),
    samples: int = typer.Option(
        1, "--samples", help=f"Sensor packets averaged per measurement (1..{MAX_SAMPLES})."),
    rate: float = typer.Option(200.0, "--rate", help="Simulated encoder packet rate (Hz)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the simulated sensor noise."),
    max_approach: float = typer.Option(
        50.0, "--max-approach", metavar="MM", help="Farthest an approach without contact may "
        "carry the tool point from the start (mm); beyond it the run stops (a simulated "
        "workpiece the approach would not meet within it is refused before any motion)."),
    max_iterations: int = typer.Option(
        None, "--max-iterations",
        help=f"Measurement cycles before giving up (1..{MAX_ITERATIONS}; default 60 for press, "
        f"{MAX_ITERATIONS} for follow)."),
    plot: Path = typer.Option(
        None, "--plot", help="Directory for the wrench-vs-state plot (default: the run "
        "directory)."),
    no_plot: bool = flag(False, "--no-plot", help="Do not write the plot."),
    log: Path = typer.Option(
        None, "--log", help="Cycle log file, JSON lines (default: "
        "./kinestat-runs/<timestamp>/log.jsonl)."),
    view: bool = flag(False, "--view", help="Also open a 3D replay in the browser."),
    html: Path = typer.Option(None, "--html", metavar="FILE", help="With --view: write the "
                              "3D replay to FILE (self-contained) instead of opening a browser."),
    serve: bool = flag(False, "--serve", help="With --view: a live view on loopback while the "
                       "run goes (each cycle streamed to the page as it is logged); its address "
                       "goes to stderr, and after the run it serves until Ctrl-C."),
    calibration: str = typer.Option(
        "thesis", "--calibration",
        help="Leg calibration the controller uses (counts -> leg length and force): 'thesis' "
        "(the 2011 prototype's maps), 'nominal' (the design springs) or a TOML file "
        "(docs/control.md).", metavar="thesis|nominal|FILE"),
    platform: str = typer.Option(
        None, "--platform", help="Platform TOML file (default the 2011 prototype); its "
        "\\[mount] table, if any, is the default --mount.", metavar="FILE"),
    tool_offset: str = typer.Option(
        None, "--tool-offset", "--tool-point-6", metavar="X,Y,Z",
        help="The tool point fixed on the top plate, given where it sits in frame 6 (the "
        "flange) when the platform is unloaded: the thesis's P_tool_6 (mm; default 0,0,235). "
        "The simulated cell carries the same tool."),
    a67: str = typer.Option(
        None, "--a67", "--a67-f", metavar="X,Y,Z",
        help="The start pose's a67_F (fixed frame), perpendicular to --direction (default: "
        "the fixed z axis made perpendicular to it)."),
    mount: str = typer.Option(
        None, "--mount", metavar="centred|FILE|POSE",
        help="The platform's base frame on the flange, 6_BT: 'centred' (the base triangle's "
        "centroid on S6, base x along a67; the default), a platform TOML file's \\[mount] "
        "table, or a pose (a pose file, or 16 numbers row by row, mm). The simulated cell is "
        "built with the same mount."),
    sim: str = typer.Option(
        "kinestat", "--sim",
        help="The simulated cell's physics: 'kinestat' (the built-in contact simulator behind "
        "the simulated Galil and encoder box) or 'mujoco' (MuJoCo's rigid-body dynamics and "
        "contact, in process; docs/mujoco.md).", metavar="kinestat|mujoco"),
    sim_legs: str = typer.Option(
        "thesis", "--sim-legs",
        help="The simulated legs' TRUE law: 'thesis', 'nominal' or a calibration TOML file "
        "(simulation only).", metavar="thesis|nominal|FILE"),
    procedure: str = typer.Option(
        "kinestat", "--procedure",
        help="'kinestat' (the improved loop) or 'thesis' (ForceCorrection.m as written: one "
        "reorientation about the tool point, then fixed --step translations along S6).",
        metavar="kinestat|thesis"),
    move_rule: str = typer.Option(
        "coordinated", "--move-rule",
        help="Per-axis speeds of each move: 'coordinated' (the axes start and finish together), "
        "'thesis' (galil_control.m's |delta|/4 counts/s) or 'max'.",
        metavar="coordinated|thesis|max"),
    assume_homed: bool = flag(
        False, "--assume-homed",
        help="With --galil: move even if the controller does not report this session homed "
        "(`kinestat home`)."),
    task: str = typer.Option(
        "press", "--task", help=f"{' or '.join(TASKS)}: press the tool on the workpiece "
        "(default), or slide it along the workpiece holding the normal force at --force."),
    travel: float = typer.Option(None, "--travel", metavar="MM",
                                 help="follow: distance to travel along the surface (mm; "
                                 "default 50)."),
    travel_dir: str = typer.Option(
        None, "--travel-dir", help="follow: initial direction of travel x,y,z (fixed frame), "
        "projected onto the tangent plane as the surface is discovered (default: +y made "
        "perpendicular to F_req; +x when F_req is within 30° of ±y)."),
    travel_step: float = typer.Option(None, "--travel-step", metavar="MM",
                                      help="follow: largest travel per cycle (mm; default 1)."),
    tilt_deg: float = typer.Option(
        None, "--tilt-deg", help="follow: tool axis tilted from the measured normal towards "
        "the travel direction (degrees; default 0)."),
    auto_tilt: bool | None = typer.Option(
        None, "--auto-tilt/--no-auto-tilt", metavar="", help="follow: tilt the tool axis onto "
        "the friction cone's edge (estimated), more while the tip sticks: --auto-tilt from "
        "the start, --no-auto-tilt never; default: it switches itself on when the tip sticks "
        "under the travel steps (friction), unless --tilt-deg is given (docs/control.md)."),
    probe_span: float = typer.Option(
        None, "--probe-span", metavar="MM", help="follow: before raising the force, touch the "
        "surface MM either side of the first contact (across and along the travel) and fit "
        "its normal to the touches (default 3; 0: take the first contact force's direction, "
        "which friction can tilt by up to atan(mu))."),
    workpiece: str = typer.Option(
        None, "--workpiece", help="Simulated workpiece: 'plane' (default, --plane-point/"
        "--plane-normal) or 'cylinder:radius=R,axis=x,y,z[,point=x,y,z]' (without point: its "
        f"surface {DEFAULT_PLANE_DISTANCE} mm ahead of the start tool point along F_req)."),
    workpiece_stiffness: float = typer.Option(
        None, "--workpiece-stiffness", metavar="N/MM", help="Normal stiffness of the simulated "
        "workpiece (N/mm): the tip sinks f_n/k into it (e.g. wood, docs/control.md). Default: "
        "rigid."),
    arm: str = typer.Option(
        None, "--arm", metavar="MODEL", help="The robot: an embedded model name (e.g. "
        "puma560), a TOML model or a URDF file, any 6-joint arm with an analytic solver; "
        "default the thesis's PUMA 762. Another arm runs on the in-process simulated cell: its "
        "joints are set directly within its limits, its base at --arm-base (docs/control.md)."),
    tip: str = tip_option(),
    base: str = base_option(),
    scale: float = scale_option(),
    length_unit: str = length_unit_option(),
    arm_base: str = typer.Option(
        None, "--arm-base", metavar="X,Y,Z", help="--arm: where its base frame is (mm, fixed "
        "frame, axes parallel). Default: placed automatically so that the start pose is "
        "reached with the best-conditioned Jacobian and joint-limit margin, the arm's "
        "shoulder behind the workpiece's plane (reported as arm.base)."),
    as_json: bool = flag(False, "--json", help="Print the final report as JSON."),
) -> None:
    """Kinestatic control: press the tool on the workpiece with |F_req| along the force.

    Vibhute 2011 ch. 4-5: move to the start pose, measure the wrench through the compliant
    platform, turn S6 onto the force about the tool point, then step along S6 until the force
    is within tolerance. Without --galil/--serial it runs the simulated cell. Every cycle is
    logged; faults end in a safe stop (ST). Exit status 0 when converged, 2 otherwise.

    JSON keys: converged, iterations, force, torque, force_magnitude, true_force, tool_axis,
    tool_point (the commanded, unloaded tool point P_tool_F), tip (the measured, deflected
    tip), final_joints_deg, final_leg_lengths, log, states, stop_reason, method, plots,
    torque_about_tip, torque_about_tool, torque_about_base (N·mm, fixed frame: about the tip,
    the tool point and the robot base), equivalent_force (the equivalent wrench's force, N:
    base − tool torque = tool_point × it), procedure, calibration, cycles, tool_point_6 (mm,
    frame 6), a67_start, mount (6_BT), mount_source, plant (simulated: kinestat or mujoco;
    with mujoco also sim_time_s, sim_seconds_per_cycle, sim_move_s, sim_settle_s,
    moves_unsettled); with --task follow also task, travel_speed_mm_s (mujoco), completed,
    travel, normal_force_rms_error, normal_force_max_error, contact_lost (and the true errors,
    simulated); with --arm also arm (name, joints, base, placement, limits_deg).
    """
    _check_counts(samples, max_iterations)
    check_seed(seed)
    _check_plot_dir(plot, no_plot)
    d = parse_floats(direction, 3, "direction")
    if np.linalg.norm(d) == 0:
        raise InputError("--direction must not be the zero vector")
    d = d / np.linalg.norm(d)
    if not (math.isfinite(force) and force > 0):
        raise InputError(f"--force must be a positive number of newtons, got {force}")
    p0 = parse_floats(start, 3, "start")

    # lazy: start-up (the cell loads numba and scipy; `kinestat --help` should not)
    from kinestat.app.control_run import (
        ControlRequest,
        SimulatedCell,
        plot_run,
        prepare_control,
        report_dict,
        run_control,
    )
    from kinestat.cli._compile import KERNELS, compiling_notice, is_cold, warm_kernels

    _check_task_options(task, travel=travel, travel_dir=travel_dir, travel_step=travel_step,
                        tilt_deg=tilt_deg, auto_tilt=auto_tilt, probe_span=probe_span)
    if not (math.isfinite(max_approach) and max_approach > 0):
        raise InputError(f"--max-approach must be a positive number of mm, got {max_approach}")
    arm_spec = _arm(arm, tip, base, scale, length_unit, arm_base, galil, serial)
    cell = _cell(galil, serial, serial_format, plane_point, plane_normal, ideal_sensor, noise,
                 friction, rate, seed, sim_legs, workpiece, sim, workpiece_stiffness)
    simulated = isinstance(cell, SimulatedCell)
    req = ControlRequest(force=force * d, start_tool_point=p0, cell=cell, force_tol=force_tol,
                         align_tol_deg=align_tol_deg, method=method, step=step,
                         approach_step=approach_step, estimator=estimator, samples=samples,
                         max_iterations=max_iterations, calibration=calibration,
                         platform=platform, procedure=procedure, move_rule=move_rule,
                         assume_homed=assume_homed, task=task,
                         travel=50.0 if travel is None else travel,
                         travel_dir=(None if travel_dir is None
                                     else parse_floats(travel_dir, 3, "travel-dir")),
                         travel_step=1.0 if travel_step is None else travel_step,
                         tilt_deg=0.0 if tilt_deg is None else tilt_deg, auto_tilt=auto_tilt,
                         arm=arm_spec, probe_span=probe_span, max_approach=max_approach,
                         **_tool_and_mount(tool_offset, a67, mount))
    cold = tuple(g for g in KERNELS if is_cold(g))
    if cold:  # compile before the run, so that its timing is the loop's own
        with compiling_notice(*cold):
            warm_kernels(cold)
    prepared = prepare_control(req)
    if serve and (not view or html is not None):
        raise InputError("--serve goes with --view (and not with --html)")
    run_dir = None  # claimed only now: a refused request leaves nothing behind
    if log is None or (plot is None and not no_plot):
        run_dir = _run_dir(Path("kinestat-runs"))
    log_path = log if log is not None else run_dir / "log.jsonl"
    plot_dir = None if no_plot else (plot if plot is not None else run_dir)

    err_console.print(f"[bold]kinestat control[/]: |F_req| = {force:g} N along "
                      f"({d[0]:.4f}, {d[1]:.4f}, {d[2]:.4f}), procedure {procedure}, method "
                      f"{method}, calibration {calibration}, "
                      + (f"simulated cell ({sim})" if simulated
                         else literal(f"Galil {galil}, sensor {serial}"))
                      + ("" if prepared.arm is None else literal(_arm_words(prepared.arm)))
                      + ("" if prepared.follow is None else
                         "; follow {:g} mm, first along ({:.4f}, {:.4f}, {:.4f})".format(
                             prepared.follow.travel, *prepared.follow.travel_dir)))
    live = _start_live(log_path, platform) if serve else None
    # SIGTERM / SIGHUP stop the cell as Ctrl-C does: ST, a fault and an end record, status 2
    with stop_on_signals():
        try:
            report = run_control(prepared, log_path, progress=_print_progress)
        except KeyboardInterrupt as exc:  # before or after the loop: nothing was moving
            raise KinestatError(f"kinestat control: {exc or 'interrupted'} before the run "
                                "started or after it ended") from exc
        out = report_dict(prepared, report)
        plots: list[str] = []
        if plot_dir is not None:
            try:
                plots = plot_run(log_path, plot_dir)
            except InputError as exc:
                err_console.print(f"[yellow]no plot:[/] {literal(exc)}")
        out["plots"] = plots
        if as_json:
            print_json(out)
        else:
            _print_report(out)
    if live is not None:
        _serve_until_interrupted(live)
    elif view or html is not None:
        from kinestat.viz.show import show_log  # lazy: viewer only with --view

        show_log(log_path, html=html)
    if not report.converged:
        what = "the follow task did not complete" if task == "follow" else (
            "kinestatic control did not converge")
        raise KinestatError(f"{what}: {report.stop_reason}")


def _tool_and_mount(tool_offset: str | None, a67: str | None, mount: str | None) -> dict:
    """``--tool-offset``, ``--a67`` and ``--mount`` as :class:`ControlRequest` fields."""
    out: dict = {}
    if tool_offset is not None:
        out["tool_point_6"] = parse_floats(tool_offset, 3, "tool-offset")
    if a67 is not None:
        out["a67"] = parse_floats(a67, 3, "a67")
    if mount is not None:
        text = mount.strip()
        if text in ("centred", "centered") or (Path(text).suffix.lower() == ".toml"
                                              and Path(text).is_file()):
            out["mount"] = text
        else:
            out["mount"] = parse_pose(text, "mount")
    return out


def _start_live(log_path: Path, platform: str | None):
    """The live view of the run (``--view --serve``), opened in the browser."""
    import webbrowser  # lazy: the browser only with --serve

    from kinestat.viz.live import start_live  # lazy: the server only with --serve

    p = None
    if platform is not None:
        from kinestat.io.platform_toml import read_platform  # lazy: only with --platform

        p = read_platform(platform)
    live = start_live(log_path, platform=p)
    err_console.print(f"kinestat control: live view at {live.url}")
    err_console.file.flush()
    webbrowser.open(live.url)
    return live


def _serve_until_interrupted(live) -> None:
    err_console.print(f"kinestat control: the run has ended; the live view stays at {live.url} "
                      "until Ctrl-C")
    err_console.file.flush()
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        live.close()


def _arm_words(placed) -> str:
    """The banner's words on another arm: its name and where its base was put."""
    b = ", ".join(f"{v:g}" for v in placed.base)
    how = "placed automatically" if placed.placement == "auto" else "--arm-base"
    return f", arm {placed.source_name} (base at {b} mm, {how})"


def _check_task_options(task: str, **given) -> None:
    """The follow task's options given to another task: one clear error naming them (they
    would be ignored)."""
    if task != "press":  # follow, or an unknown task (refused with its own error)
        return
    named = [f"--{k.replace('_', '-')}" for k, v in given.items() if v is not None]
    if named:
        raise InputError(f"{', '.join(named)} only apply to --task follow (this run is "
                         f"--task {task})")


def _check_counts(samples: int, max_iterations: int | None) -> None:
    """The documented ceilings of --samples and --max-iterations, before anything starts."""
    if not 1 <= samples <= MAX_SAMPLES:
        raise InputError(f"--samples must be in 1..{MAX_SAMPLES} (packets averaged per "
                         f"measurement), got {samples}")
    if max_iterations is not None and not 1 <= max_iterations <= MAX_ITERATIONS:
        raise InputError(f"--max-iterations must be in 1..{MAX_ITERATIONS}, got "
                         f"{max_iterations}")


def _check_plot_dir(plot: Path | None, no_plot: bool) -> None:
    """--plot names a directory: refuse an existing file before running (as ``disp --plot``)."""
    if plot is not None and not no_plot and plot.exists() and not plot.is_dir():
        raise InputError(f"--plot {str(plot)!r} exists and is not a directory; give a "
                         "directory for the wrench-vs-state plot")


def _print_report(out: dict) -> None:
    ok = "[green]converged[/]" if out["converged"] else "[red]not converged[/]"
    out_console.print(f"Kinestatic control {ok} after {out['iterations']} cycles "
                      f"({out['moves']} moves, {out['elapsed_s']:.1f} s); states "
                      + (" → ".join(out["states"]) if out["states"]
                         else "none (stopped before the first cycle)"))
    if out["converged"]:  # a failed run's reason is the one error line on stderr
        out_console.print(f"  {literal(out['stop_reason'])}")
    if out.get("task") == "follow":
        rms, mx = out.get("normal_force_rms_error"), out.get("normal_force_max_error")
        out_console.print(f"  travel {out['travel']:.3f} mm along the surface; normal force error "
                          + ("n/a" if rms is None else f"RMS {rms:.4f} N, max {mx:.4f} N")
                          + f"; contact lost {out['contact_lost']} cycles")
    rows = []
    # the equivalent wrench's force beside its torques: base − tool = tool_point × that force,
    # base − tip = tip × that force
    for key, label in (("force", f"force, {out.get('estimator', 'point')} estimate (N)"),
                       ("equivalent_force", "equivalent wrench: force (N)"),
                       ("torque_about_tip", "  torque about measured tip (N·mm)"),
                       ("torque_about_tool", "  torque about tool point P_tool_F (N·mm)"),
                       ("torque_about_base", "  torque about robot base (N·mm)"),
                       ("true_force", "true force (N)"), ("tool_axis", "tool axis S6"),
                       ("tip", "tip, measured (mm)"),
                       ("tool_point", "tool point (mm), commanded")):
        if out.get(key) is not None:
            rows.append([label, *out[key]])
    if rows:
        out_console.print(table("Final state (fixed frame)", ["", "x", "y", "z"], rows))
    if out.get("force_magnitude") is not None:
        line = f"|F| = {out['force_magnitude']:.4f} N (target {out['target_force']:g} N)"
        if out.get("true_force_magnitude") is not None:
            line += f", true |F| = {out['true_force_magnitude']:.4f} N"
        if out.get("axis_error_deg") is not None:
            line += f", true force vs tool axis {out['axis_error_deg']:.3f}°"
        out_console.print(line)
    if out.get("final_axis_deg") is not None:
        out_console.print("robot axes (deg): " + ", ".join(f"{v:.4f}"
                                                           for v in out["final_axis_deg"]))
    if out.get("tool_point_6") is not None:
        out_console.print("tool P_tool_6 (" + ", ".join(f"{v:g}" for v in out["tool_point_6"])
                          + ") mm, mount " + literal(str(out.get("mount_source", "centred"))))
    if out.get("arm") is not None:
        arm = out["arm"]
        out_console.print(literal(f"arm {arm['name']}: base at ("
                                  + ", ".join(f"{v:g}" for v in arm["base"]) + ") mm, "
                                  + ("placed automatically" if arm["placement"] == "auto"
                                     else "--arm-base")))
    out_console.print(f"log: {literal(out['log'])}")
    for p in out.get("plots", []):
        out_console.print(f"plot: {literal(p)}")
