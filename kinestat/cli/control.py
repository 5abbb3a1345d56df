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
from kinestat.cli import _control_options as opts
from kinestat.cli import _control_output as show
from kinestat.cli._model import (
    base_option,
    length_unit_option,
    scale_option,
    tip_option,
)
from kinestat.cli._options import check_seed, flag
from kinestat.cli._output import (
    err_console,
    literal,
    parse_floats,
    print_json,
)
from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.devices.ceilings import MAX_SAMPLES
from kinestat.errors import InputError, KinestatError


def register(app: typer.Typer) -> None:
    app.command("control")(control_command)


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
    with mujoco also sim_time_s, time_to_goal_s,
    sim_seconds_per_cycle, sim_move_s, sim_settle_s,
    moves_unsettled); with --task follow also task, travel_speed_mm_s (mujoco), completed,
    travel, normal_force_rms_error, normal_force_max_error, contact_lost (and the true errors,
    simulated); with --arm also arm (name, joints, base, placement, limits_deg).
    """
    opts.check_counts(samples, max_iterations)
    check_seed(seed)
    opts.check_plot_dir(plot, no_plot)
    opts.check_rate_and_log(rate, log)
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

    opts.check_task_options(task, travel=travel, travel_dir=travel_dir, travel_step=travel_step,
                        tilt_deg=tilt_deg, auto_tilt=auto_tilt, probe_span=probe_span)
    if not (math.isfinite(max_approach) and max_approach > 0):
        raise InputError(f"--max-approach must be a positive number of mm, got {max_approach}")
    arm_spec = opts.arm(arm, tip, base, scale, length_unit, arm_base, galil, serial)
    cell = opts.cell(galil, serial, serial_format, plane_point, plane_normal, ideal_sensor, noise,
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
                         **opts.tool_and_mount(tool_offset, a67, mount))
    cold = tuple(g for g in KERNELS if is_cold(g))
    if cold:  # compile before the run, so that its timing is the loop's own
        with compiling_notice(*cold):
            warm_kernels(cold)
    prepared = prepare_control(req)
    if serve and (not view or html is not None):
        raise InputError("--serve goes with --view (and not with --html)")
    run_dir = None  # claimed only now: a refused request leaves nothing behind
    if log is None or (plot is None and not no_plot):
        run_dir = opts.run_dir(Path("kinestat-runs"))
    log_path = log if log is not None else run_dir / "log.jsonl"
    plot_dir = None if no_plot else (plot if plot is not None else run_dir)

    err_console.print(f"[bold]kinestat control[/]: |F_req| = {force:g} N along "
                      f"({d[0]:.4f}, {d[1]:.4f}, {d[2]:.4f}), procedure {procedure}, method "
                      f"{method}, calibration {calibration}, "
                      + (("simulated cell" + (" (MuJoCo)" if sim == "mujoco" else ""))
                         if simulated
                         else literal(f"Galil {galil}, sensor {serial}"))
                      + ("" if prepared.arm is None else literal(show.arm_words(prepared.arm)))
                      + ("" if prepared.follow is None else
                         "; follow {:g} mm, first along ({:.4f}, {:.4f}, {:.4f})".format(
                             prepared.follow.travel, *prepared.follow.travel_dir)))
    live = show.start_live(log_path, platform) if serve else None
    # SIGTERM / SIGHUP stop the cell as Ctrl-C does: ST, a fault and an end record, status 2
    with stop_on_signals():
        try:
            report = run_control(prepared, log_path, progress=show.print_progress)
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
            show.print_report(out)
    if live is not None:
        show.serve_until_interrupted(live)
    elif view or html is not None:
        from kinestat.viz.show import show_log  # lazy: viewer only with --view

        show_log(log_path, html=html)
    if not report.converged:
        what = "the follow task did not complete" if task == "follow" else (
            "kinestatic control did not converge")
        raise KinestatError(f"{what}: {report.stop_reason}")


