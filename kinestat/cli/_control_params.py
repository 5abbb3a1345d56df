"""The options of ``kinestat control`` (:mod:`kinestat.cli.control`): their names, types,
defaults (:data:`~kinestat.control.defaults.RUN_DEFAULTS`) and help, as the command's
signature (:data:`PARAMETERS`), and the command's help (:data:`HELP`)."""

from __future__ import annotations

import inspect
from pathlib import Path

import typer

from kinestat.cli._model import (
    base_option,
    length_unit_option,
    scale_option,
    tip_option,
)
from kinestat.cli._options import flag, name_value, path_value
from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.control.defaults import RUN_DEFAULTS as D
from kinestat.control.defaults import TASKS
from kinestat.devices.ceilings import MAX_SAMPLES

__all__ = ["PARAMETERS", "HELP"]


def _p(name: str, annotation, option) -> inspect.Parameter:
    return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=option,
                             annotation=annotation)


PARAMETERS = [
    _p("force", float, typer.Option(D.force, "--force",
                                    help="Target force magnitude |F_req| (N).")),
    _p("direction", str, typer.Option(
        D.direction, "--direction",
        help="Direction of F_req x,y,z (fixed frame): the approach direction and the start "
        "pose's tool axis. Default the thesis's 0.9713 i + 0 j - 0.2375 k.")),
    _p("force_tol", float, typer.Option(D.force_tol, "--force-tol", help="Tolerance on |F| (N).")),
    _p("align_tol_deg", float, typer.Option(
        D.align_tol_deg, "--align-tol-deg",
        help="Tolerance on the angle between S6 and the force (deg).")),
    _p("start", str, typer.Option(D.start, "--start",
                              help="Start tool point P_tool_F x,y,z (mm, fixed frame).")),
    _p("plane_point", str, typer.Option(
        None, "--plane-point",
        help=f"A point of the workpiece plane x,y,z (mm). Default: {D.plane_distance} mm "
        "ahead of the start tool point along F_req (simulation only).")),
    _p("plane_normal", str, typer.Option(
        None, "--plane-normal",
        help=f"Workpiece normal x,y,z, pointing out of the material towards the tool. Default: "
        f"-F_req tilted by {D.plane_tilt_deg} deg (simulation only).")),
    _p("method", str, typer.Option(
        "stiffness", "--method",
        help="Step along S6: 'stiffness' (Newton step from the platform stiffness) or 'fixed' "
        "(the thesis's constant step).")),
    _p("step", float, typer.Option(
        D.step, "--step", help="Fixed step, and the largest stiffness step (mm).")),
    _p("approach_step", float, typer.Option(
        None, "--approach-step", help="Step along S6 while no contact is measured (mm; default "
        "1 for press, 0.25 for follow).")),
    _p("estimator", str, typer.Option(
        "point", "--estimator",
        help="Force the controller acts on: 'point' (point-contact fit) or 'wrench' (the "
        "equivalent wrench's force, as the thesis).")),
    _p("ideal_sensor", bool, flag(
        False, "--ideal-sensor", help="Simulated leg encoders without quantisation (1 nm).")),
    _p("noise", float, typer.Option(
        0.0, "--noise", help="Simulated leg-length noise, standard deviation (mm).")),
    _p("friction", float, typer.Option(
        0.0, "--friction", help="Coulomb friction coefficient of the simulated workpiece.")),
    _p("galil", str, typer.Option(None, "--galil", help="Real Galil controller HOST:PORT.")),
    _p("serial", str, typer.Option(None, "--serial",
                               help="Real encoder stream: serial device or pyserial URL.")),
    _p("serial_format", str, typer.Option(
        "ks", "--serial-format", help="Encoder packet format: 'ks' or 'legacy' (thesis).")),
    _p("samples", int, typer.Option(
        1, "--samples", help=f"Sensor packets averaged per measurement (1..{MAX_SAMPLES}).")),
    _p("rate", float, typer.Option(D.rate_hz, "--rate",
                                   help="Simulated encoder packet rate (Hz).")),
    _p("seed", int, typer.Option(0, "--seed", help="Seed of the simulated sensor noise.")),
    _p("max_approach", float, typer.Option(
        D.max_approach, "--max-approach", metavar="MM",
        help="Farthest an approach without contact may "
        "carry the tool point from the start (mm); beyond it the run stops (a simulated "
        "workpiece the approach would not meet within it is refused before any motion).")),
    _p("max_iterations", int, typer.Option(
        None, "--max-iterations",
        help=f"Measurement cycles before giving up (1..{MAX_ITERATIONS}; default 60 for press, "
        f"{MAX_ITERATIONS} for follow).")),
    _p("plot", Path, typer.Option(
        None, "--plot", parser=path_value,
        help="Directory for the wrench-vs-state plot (default: the run "
        "directory).")),
    _p("no_plot", bool, flag(False, "--no-plot", help="Do not write the plot.")),
    _p("log", Path, typer.Option(
        None, "--log", parser=path_value, help="Cycle log file, JSON lines (default: "
        "./kinestat-runs/<timestamp>/log.jsonl).")),
    _p("view", bool, flag(False, "--view", help="Also open a 3D replay in the browser.")),
    _p("html", Path, typer.Option(None, "--html", parser=path_value,
                                  metavar="FILE", help="With --view: write the "
                              "3D replay to FILE (self-contained) instead of opening a browser.")),
    _p("serve", bool, flag(False, "--serve", help="With --view: a live view on loopback while the "
                       "run goes (each cycle streamed to the page as it is logged); its address "
                       "goes to stderr, and after the run it serves until Ctrl-C.")),
    _p("calibration", str, typer.Option(
        "thesis", "--calibration", parser=name_value,
        help="Leg calibration the controller uses (counts -> leg length and force): 'thesis' "
        "(the 2011 prototype's maps), 'nominal' (the design springs) or a TOML file "
        "(docs/control.md).", metavar="thesis|nominal|FILE")),
    _p("platform", str, typer.Option(
        None, "--platform", parser=name_value,
        help="Platform TOML file (default the 2011 prototype); its "
        "\\[mount] table, if any, is the default --mount.", metavar="FILE")),
    _p("tool_offset", str, typer.Option(
        None, "--tool-offset", "--tool-point-6", metavar="X,Y,Z",
        help="The tool point fixed on the top plate, given where it sits in frame 6 (the "
        "flange) when the platform is unloaded: the thesis's P_tool_6 (mm; default 0,0,235). "
        "The simulated cell carries the same tool.")),
    _p("a67", str, typer.Option(
        None, "--a67", "--a67-f", metavar="X,Y,Z",
        help="The start pose's a67_F (fixed frame), perpendicular to --direction (default: "
        "the fixed z axis made perpendicular to it).")),
    _p("mount", str, typer.Option(
        None, "--mount", metavar="centred|FILE|POSE",
        help="The platform's base frame on the flange, 6_BT: 'centred' (the base triangle's "
        "centroid on S6, base x along a67; the default), a platform TOML file's \\[mount] "
        "table, or a pose (a pose file, or 16 numbers row by row, mm). The simulated cell is "
        "built with the same mount.")),
    _p("sim", str, typer.Option(
        "kinestat", "--sim",
        help="The simulated cell's physics: 'kinestat' (the built-in contact simulator behind "
        "the simulated Galil and encoder box) or 'mujoco' (MuJoCo's rigid-body dynamics and "
        "contact, in process; docs/mujoco.md).", metavar="kinestat|mujoco")),
    _p("sim_legs", str, typer.Option(
        "thesis", "--sim-legs", parser=name_value,
        help="The simulated legs' TRUE law: 'thesis', 'nominal' or a calibration TOML file "
        "(simulation only).", metavar="thesis|nominal|FILE")),
    _p("procedure", str, typer.Option(
        "kinestat", "--procedure",
        help="'kinestat' (the improved loop) or 'thesis' (ForceCorrection.m as written: one "
        "reorientation about the tool point, then fixed --step translations along S6).",
        metavar="kinestat|thesis")),
    _p("move_rule", str, typer.Option(
        "coordinated", "--move-rule",
        help="Per-axis speeds of each move: 'coordinated' (the axes start and finish together), "
        "'thesis' (galil_control.m's |delta|/4 counts/s) or 'max'.",
        metavar="coordinated|thesis|max")),
    _p("assume_homed", bool, flag(
        False, "--assume-homed",
        help="With --galil: move even if the controller does not report this session homed "
        "(`kinestat home`).")),
    _p("task", str, typer.Option(
        "press", "--task", help=f"{' or '.join(TASKS)}: press the tool on the workpiece "
        "(default), or slide it along the workpiece holding the normal force at --force.")),
    _p("travel", float, typer.Option(None, "--travel", metavar="MM",
                                 help="follow: distance to travel along the surface (mm; "
                                 "default 50).")),
    _p("travel_dir", str, typer.Option(
        None, "--travel-dir", help="follow: initial direction of travel x,y,z (fixed frame), "
        "projected onto the tangent plane as the surface is discovered (default: +y made "
        "perpendicular to F_req; +x when F_req is within 30° of ±y).")),
    _p("travel_step", float, typer.Option(None, "--travel-step", metavar="MM",
                                      help="follow: largest travel per cycle (mm; default 1).")),
    _p("tilt_deg", float, typer.Option(
        None, "--tilt-deg", help="follow: tool axis tilted from the measured normal towards "
        "the travel direction (degrees; default 0).")),
    _p("auto_tilt", bool | None, typer.Option(
        None, "--auto-tilt/--no-auto-tilt", metavar="", help="follow: tilt the tool axis onto "
        "the friction cone's edge (estimated), more while the tip sticks: --auto-tilt from "
        "the start, --no-auto-tilt never; default: it switches itself on when the tip sticks "
        "under the travel steps (friction), unless --tilt-deg is given (docs/control.md).")),
    _p("probe_span", float, typer.Option(
        None, "--probe-span", metavar="MM", help="follow: before raising the force, touch the "
        "surface MM either side of the first contact (across and along the travel) and fit "
        "its normal to the touches (default 3; 0: take the first contact force's direction, "
        "which friction can tilt by up to atan(mu)).")),
    _p("workpiece", str, typer.Option(
        None, "--workpiece", help="Simulated workpiece: 'plane' (default, --plane-point/"
        "--plane-normal) or 'cylinder:radius=R,axis=x,y,z[,point=x,y,z]' (without point: its "
        f"surface {D.plane_distance} mm ahead of the start tool point along F_req).")),
    _p("workpiece_stiffness", float, typer.Option(
        None, "--workpiece-stiffness", metavar="N/MM", help="Normal stiffness of the simulated "
        "workpiece (N/mm): the tip sinks f_n/k into it (e.g. wood, docs/control.md). Default: "
        "rigid.")),
    _p("top_weight", bool, flag(
        False, "--top-weight", help="--sim mujoco: gravity on the top plate + tool (0.35 kg); "
        "the controller is given their weight and centre of mass and subtracts them from "
        "every measurement (docs/mujoco.md). Default: weightless, as the built-in simulator.")),
    _p("top_mass", float, typer.Option(
        None, "--top-mass", metavar="KG", help="The top plate + tool's moving mass (kg): the "
        "follow task keeps its moves' accelerations low enough that this inertia cannot run a "
        "sliding tip past what its slip test resolves (docs/mujoco.md). Default: 0, the "
        "thesis's massless model (moves not limited); with --sim mujoco the scene's 0.35 kg, "
        "which this also sets.")),
    _p("arm", str, typer.Option(
        None, "--arm", parser=name_value,
        metavar="MODEL", help="The robot: an embedded model name (e.g. "
        "puma560), a TOML model or a URDF file, any 6-joint arm with an analytic solver; "
        "default the thesis's PUMA 762. Another arm runs on the in-process simulated cell: its "
        "joints are set directly within its limits, its base at --arm-base (docs/control.md).")),
    _p("tip", str, tip_option()),
    _p("base", str, base_option()),
    _p("scale", float, scale_option()),
    _p("length_unit", str, length_unit_option()),
    _p("arm_base", str, typer.Option(
        None, "--arm-base", metavar="X,Y,Z", help="--arm: where its base frame is (mm, fixed "
        "frame, axes parallel). Default: placed automatically so that the start pose is "
        "reached with the best-conditioned Jacobian and joint-limit margin, the arm's "
        "shoulder behind the workpiece's plane (reported as arm.base).")),
    _p("as_json", bool, flag(False, "--json", help="Print the final report as JSON.")),
]
"""The signature of ``kinestat control`` (typer reads it from ``__signature__``)."""

HELP = """Kinestatic control: press the tool on the workpiece with |F_req| along the force.

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
