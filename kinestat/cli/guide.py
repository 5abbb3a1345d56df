"""``kinestat guide``: Nadkarni's guidance analyses on any model (TOML file or embedded name).

Not an emulator of DISP: by default each stage ends with correction steps straight at its
target (``--no-settle`` turns them off); ``kinestat disp`` behaves as DISP did.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import typer

from kinestat.cli._compile import compiling_notice
from kinestat.cli._guidance import (
    SINGULAR_HELP,
    check_cond_limit,
    parse_steps,
    print_result,
    progress_reporter,
    singular_mode,
)
from kinestat.cli._model import (
    base_option,
    length_unit_option,
    load_model,
    scale_option,
    tip_option,
)
from kinestat.cli._options import (
    POINTS3_METAVAR,
    POSE_FILE_METAVAR,
    Q_METAVAR,
    STEPS_METAVAR,
    check_output_dir,
    check_output_file,
    command_help,
    flag,
    json_option,
    name_value,
    path_value,
    units,
)
from kinestat.cli._output import (
    console,
    literal,
    parse_floats,
    parse_pose,
    print_json,
    table,
    to_jsonable,
)
from kinestat.errors import InputError, ParseError
from kinestat.io.disp_deck import parse_operator_command
from kinestat.io.disp_deck.commands import parse_key_values, parse_number
from kinestat.io.textfile import read_text_file

if TYPE_CHECKING:
    from kinestat.io.disp_deck import OperatorCommand

__all__ = ["register", "parse_command", "parse_move", "read_commands"]

def _command_dict(c: OperatorCommand) -> dict:
    return {"frame": c.frame, "direction": np.array(c.direction), "distance": c.distance,
            "angle_deg": c.angle_deg}


def parse_command(text: str) -> dict:
    """``"frame=global,dir=0,0,1,d=4,angle=-30"`` → ``{frame, direction, distance, angle_deg}``
    (Nadkarni type IV, eqs. 4-21, 4-22; ``frame=hand`` for NTY = 1), parsed and validated by
    :func:`kinestat.io.disp_deck.parse_operator_command` (the SET THREE rules)."""
    return _command_dict(parse_operator_command(text, "--command"))


def parse_move(text: str) -> dict:
    """``"axis=0,0,1,angle=30,dir=1,0,0,d=5"``: type I Examples 1–3 — rotate by ``angle``
    (deg) about ``axis`` through the hand origin while it moves ``d`` along ``dir``."""
    kv = parse_key_values(text, "--move", {"axis": "axis", "angle": "angle", "dir": "dir",
                                   "direction": "dir", "d": "d", "distance": "d"})
    axis = parse_floats(kv.get("axis", "0,0,1"), 3, "move axis")
    direction = parse_floats(kv.get("dir", "1,0,0"), 3, "move dir")
    return {"axis": axis, "angle_deg": parse_number(kv.get("angle", "0"), "--move angle"),
            "direction": direction, "distance": parse_number(kv.get("d", "0"), "--move d")}


def read_commands(path: Path) -> list[dict]:
    """Commands from a file: one per line, either ``frame=…,dir=…,d=…,angle=…`` or the six
    numbers of a DISP SET THREE card ``NTY DCx DCy DCz DD THA``; ``#`` starts a comment."""
    try:
        text = read_text_file(path, "commands file")  # binary: a ParseError, not a crash
    except OSError as exc:
        raise InputError(f"cannot read commands file {str(path)!r}: {exc.strerror}") from exc
    out = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        try:
            out.append(_command_dict(parse_operator_command(line, "command")))
        except InputError as exc:
            raise ParseError(str(exc), file=str(path), line=lineno) from None
    if not out:
        raise ParseError("no commands in the file", file=str(path))
    return out


class _Cmd:
    """A parsed command dict seen as a :class:`~kinestat.serial.guidance.stages.Command`."""

    def __init__(self, c: dict) -> None:
        self.direction, self.distance = c["direction"], c["distance"]
        self.angle, self.frame = math.radians(c["angle_deg"]), c["frame"]


def _stages(model, q0, targets, kind, commands, moves):
    from kinestat.mechanism.nadkarni import hand_points  # lazy: start-up (`kinestat --help`)
    from kinestat.serial.fk import fk  # lazy: start-up (numba)
    from kinestat.serial.guidance.stages import (  # lazy: start-up (numba)
        command_stages,
        move_stages,
        target_stages,
    )

    given = sum(bool(x) for x in (targets, commands, moves))
    if given == 0:
        raise InputError("nothing to do: give --to targets, --command(s) or --move(s)")
    if given > 1:
        raise InputError("give targets (--to), commands (--command/--commands) or moves "
                         "(--move), not a mix: run them one after the other instead")
    if commands:
        return command_stages([_Cmd(c) for c in commands])
    if moves:
        return move_stages(moves)
    return target_stages(kind, hand_points(fk(model, q0)), targets)


def _pose_targets(poses: list[str]) -> list[np.ndarray]:
    """--to-pose values as the three hand points of each pose (origin, +z and +x points)."""
    from kinestat.mechanism.nadkarni import hand_points  # lazy: start-up (`kinestat --help`)
    from kinestat.spatial.validate import as_pose  # lazy: start-up

    return [hand_points(as_pose(parse_pose(t, "to-pose"), "--to-pose")) for t in poses]


def _rates(result, speed: float) -> tuple[np.ndarray, list[int]]:
    """Joint rates per path step (rad or length per second, eqs. 5-1..5-4) moving along the
    path at ``speed`` (deg/s of hand rotation; length/s for a purely translating step), and the
    step numbers (correction steps at the end of a stage are left out)."""
    from kinestat.serial.guidance.planners import twist_between  # lazy: start-up (numba)
    from kinestat.serial.guidance.velocity import joint_rates  # lazy: start-up (numba)

    m = result.model
    settle = result.settle_rows()
    out, steps = [], []
    for j in range(1, result.q.shape[0]):
        if j in settle:
            continue
        tw = twist_between(result.poses[j - 1], result.poses[j])
        steps.append(j)
        if not np.any(np.abs(tw) > 1e-15):
            out.append(np.zeros(m.n))
            continue
        rot = np.linalg.norm(tw[:3]) > 1e-12 * max(np.linalg.norm(tw[3:]), 1e-300)
        s = math.radians(speed) if rot else speed
        out.append(joint_rates(m, result.q[j - 1], tw, s))
    return np.array(out).reshape(-1, m.n), steps


def guide(
    model: str = typer.Argument(..., parser=name_value,
                                help="A TOML model file, a URDF file or an embedded "
                                "model name (nadkarni-config1, nadkarni-config2, puma762, …)."),
    to_pose: list[str] = typer.Option(None, "--to-pose", metavar=POSE_FILE_METAVAR,
                                      help="Target hand pose T_base_hand: a pose file or 16 "
                                      "comma-separated numbers (row by row); repeatable. "
                                      "Instead of --to."),
    to: list[str] = typer.Option(None, "--to", help="Target hand position by three points "
                                 "x,y,z,x,y,z,x,y,z (origin, a point on +z, a point on the +x "
                                 "side); repeat for several targets.", metavar=POINTS3_METAVAR),
    kind: str = typer.Option("screw", "--type", help="Path to the targets: screw (type II), "
                             "line (type III: the hand points move on straight lines) or "
                             "general (type I, Example 4)."),
    command: list[str] = typer.Option(None, "--command", help="Operator command (type IV), "
                                      "e.g. 'frame=global,dir=0,0,1,d=4,angle=-30'; "
                                      "repeatable, run in order."),
    commands: Path = typer.Option(None, "--commands", parser=path_value,
                                  help="File of commands, one per line "
                                  "(key=value or DISP's 'NTY DCx DCy DCz DD THA').",
                                  metavar="FILE"),
    move: list[str] = typer.Option(None, "--move", help="Type I Examples 1-3: "
                                   "'axis=0,0,1,angle=30,dir=1,0,0,d=5' rotates about axis "
                                   "through the hand origin while it moves d along dir."),
    q0_deg: str = typer.Option(None, "--q0-deg", help="Initial joint values (degrees for "
                               "revolute joints, length units for prismatic); default: the "
                               "model's home.", metavar=Q_METAVAR),
    steps: str = typer.Option(None, "--steps", help="Step count for every stage, or one per "
                              "stage N1,N2,…; 0 or omitted = automatic.", metavar=STEPS_METAVAR),
    closed_loop: bool = flag(False, "--closed-loop", help="Newton-correct every step "
                                     "onto the ideal path."),
    second_order: bool = flag(False, "--second-order", help="Second-order terms of "
                                      "Nadkarni eq. 5-5."),
    singular: str = typer.Option("perturb", "--singular", help=SINGULAR_HELP),
    damped: bool = flag(False, "--damped", help="Short for --singular damped."),
    no_settle: bool = flag(False, "--no-settle", help="No correction steps at the end "
                                   "of a stage (kinestat's default adds them; DISP did not)."),
    cond_limit: float = typer.Option(1e3, "--cond-limit", help="Dimensionless condition number "
                                     "above which a configuration counts as singular."),
    speed: float = typer.Option(None, "--speed", help="Hand speed for the joint rates "
                                "(Nadkarni suggestion 1): deg/s of rotation, or length/s for a "
                                "pure translation."),
    view: bool = flag(False, "--view", help="Also open a 3D view in the browser."),
    html: Path = typer.Option(None, "--html", parser=path_value,
                              metavar="FILE", help="With --view: write the "
                              "3D page to FILE (self-contained) instead of opening a browser."),
    tip: str = tip_option(),
    base: str = base_option(),
    scale: float = scale_option(),
    length_unit: str = length_unit_option(),
    as_json: bool = json_option(),
    plot: Path = typer.Option(None, "--plot", parser=path_value,
                              help="Write joints.png and hand-path.png here.",
                              metavar="DIR"),
) -> None:
    """Guide a manipulator's hand to targets, along commands or moves (Nadkarni ch. IV).

    kinestat's defaults, not an emulator of DISP: each stage ends with correction steps
    straight at its target (--no-settle: off). `kinestat disp` runs decks as DISP did.

    Exit status 2 when the run stops early (joint limit, singularity, unreachable target); the
    table up to that point is printed first.
    """
    check_output_file(html, "--html")
    check_output_dir(plot, "--plot")
    check_cond_limit(cond_limit)
    from kinestat.disp import result_record  # lazy: start-up (numba)
    from kinestat.serial.guidance.rules import GuidanceOptions  # lazy: start-up (numba)
    from kinestat.serial.guidance.run import run_guidance  # lazy: start-up (numba)
    from kinestat.serial.guidance.stages import PATH_TYPES  # lazy: start-up (numba)

    if kind not in PATH_TYPES:
        raise InputError(f"--type must be one of {', '.join(PATH_TYPES)}, got {kind!r}")
    m = load_model(model, tip, base, scale, length_unit)
    if q0_deg is None:
        q0 = np.array(m.q_home, dtype=float)
    else:
        vals = parse_floats(q0_deg, m.n, "q0-deg")
        q0 = np.where(m.prismatic, vals, np.radians(vals))
    targets = [parse_floats(t, 9, "to").reshape(3, 3) for t in (to or [])]
    if to_pose:
        if targets:
            raise InputError("give the targets as --to points or as --to-pose poses, not both")
        targets = _pose_targets(to_pose)
    cmds = [parse_command(c) for c in (command or [])]
    if commands is not None:
        cmds += read_commands(commands)
    moves = [parse_move(s) for s in (move or [])]
    stages = _stages(m, q0, targets, kind, cmds, moves)
    mode = singular_mode(singular, damped, "perturb")
    opts = GuidanceOptions(step_rule="second_order" if second_order else "first_order",
                           closed_loop=closed_loop, singular=mode,
                           settle=not no_settle, cond_limit=cond_limit)
    with compiling_notice("serial"), progress_reporter(not as_json) as prog:
        result = run_guidance(m, q0, stages, steps=parse_steps(steps), options=opts,
                              progress=prog)
    rates = None
    if speed is not None:
        if not (math.isfinite(speed) and speed > 0):
            raise InputError(f"--speed must be positive, got {speed}")
        rates, rate_steps = _rates(result, speed)
    written = []
    if plot is not None:
        from kinestat.viz.guidance_plots import write_guidance_plots  # lazy: matplotlib

        written = write_guidance_plots(result, plot, title=f"kinestat guide {m.name}")
    if as_json:
        rec = {"model": m.name, "type": ("command" if cmds else "general" if moves else kind)}
        rec.update(result_record(result))
        if rates is not None:
            disp_rates = np.where(m.prismatic, rates, np.degrees(rates))
            rec["joint_rates"] = disp_rates
            rec["joint_rate_steps"] = rate_steps
            rec["joint_rate_units"] = [f"{m.length_unit}/s" if p else "deg/s"
                                       for p in m.prismatic]
        rec["notes"] = list(result.notes)
        rec["units"] = units(m.length_unit)
        if written:
            rec["plots"] = [str(p) for p in written]
        print_json(to_jsonable(rec))
    else:
        print_result(result, result.notes, title=f"Joint variables, {m.name}")
        if rates is not None and rates.size:
            peak = np.max(np.abs(rates), axis=0)
            peak = np.where(m.prismatic, peak, np.degrees(peak))
            rate_units = [f"{m.length_unit}/s" if p else "deg/s" for p in m.prismatic]
            console.print(table("Peak joint rates (Nadkarni eqs. 5-1..5-4)", ["joint", "rate"],
                                [[str(i + 1), f"{peak[i]:.4g} {rate_units[i]}"]
                                 for i in range(m.n)]))
        for p in written:
            console.print(f"wrote {literal(p)}")
    if view or html is not None:
        from kinestat.viz.show import show_guidance  # lazy: viewer only with --view

        show_guidance(result, f"kinestat guide {m.name}", html=html)
    result.raise_if_stopped()


def register(app: typer.Typer) -> None:
    """Add the ``guide`` command to the ``kinestat`` app."""
    app.command("guide", help=command_help(guide))(guide)
