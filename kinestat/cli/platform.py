"""``kinestat platform``: the compliant 6-6 platform — geometry, FK, IK, statics, stiffness.

Every command takes ``--platform FILE`` (a TOML platform file; default the embedded 2011
prototype) and ``--json``. Poses (``--pose``) are ``home``, a file (JSON: a 4x4 list or an
object with a ``"pose"`` key; TOML: a ``pose`` key) or 16 comma-separated numbers, row-major.
Wrenches are ``fx,fy,fz,mx,my,mz``: the external wrench on the top, moment about the base
origin O0, base frame (see docs/platform.md for the sign conventions).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer

from kinestat.cli._compile import compiling_notice
from kinestat.cli._options import (
    LEGS_METAVAR,
    POSE_METAVAR,
    TWIST_METAVAR,
    WRENCH_METAVAR,
    check_output_file,
    command_help,
    flag,
    help_text,
    json_option,
    name_value,
    path_value,
    units,
)
from kinestat.cli._output import console, literal, parse_floats, parse_pose, print_json, table
from kinestat.errors import InputError, UnreachableError

# Domain modules are imported inside the commands (`# lazy: start-up`): registering the
# commands for `kinestat --help` must not load Numba or SciPy.

PLATFORM_HELP = "TOML platform file (default: the embedded 2011 prototype)."
POSE_HELP = "'home', a JSON/TOML file holding a 4x4 pose, or 16 comma-separated numbers."
WRENCH_HELP = "External wrench on the top fx,fy,fz,mx,my,mz (moment about O0, base frame)."

platform_app = typer.Typer(
    name="platform",
    help="The compliant special 6-6 platform: info, fk, ik, statics, stiffness.",
    no_args_is_help=True,
)


def register(app: typer.Typer) -> None:
    for cmd in platform_app.registered_commands:
        cmd.help = cmd.help or command_help(cmd.callback)
    app.add_typer(platform_app, name="platform")


def _load(path: str | None):
    from kinestat.io.library import prototype  # lazy: start-up
    from kinestat.io.platform_toml import read_platform  # lazy: start-up

    return prototype() if path is None else read_platform(path)


def _pose(text: str, platform) -> np.ndarray:
    if text.strip().lower() == "home":
        return platform.home_pose.copy()
    from kinestat.parallel.legs import as_pose  # lazy: start-up

    T = parse_pose(text, "pose")
    return as_pose(T, "--pose")


def _pose_rows(T: np.ndarray) -> list[list]:
    return [[str(i + 1), *T[i]] for i in range(4)]


@platform_app.command("info")
def info_command(
    platform: str = typer.Option(None, "--platform", parser=name_value,
                                 help=PLATFORM_HELP, metavar="FILE"),
    as_json: bool = json_option(),
) -> None:
    """Geometry, springs, free lengths and home pose of the platform.

    JSON: {"name", "length_unit", "force_unit", "leg_names", "base_points", "top_points",
    "stiffness", "free_lengths", "home_pose", "special", "edge_fractions", "jacobian_det_home",
    "singularity_measure_home", "design", "mobility"}; "mobility" is the Grübler–Kutzbach
    count (Vibhute eq. 1-1) per leg chain: {"structure", "space", "links", "joints", "formula",
    "chains": {"UPS"|"SPS": {"joint_counts", "mobility", "idle", "top"}}, "chain",
    "mobility"}.
    """
    from kinestat.parallel.mobility import platform_mobility  # lazy: start-up
    from kinestat.parallel.singularity import singularity_measure  # lazy: start-up
    from kinestat.parallel.statics import jacobian_det  # lazy: start-up (numba)

    p = _load(platform)
    d = p.design
    out = {
        "name": p.name,
        "length_unit": p.length_unit,
        "force_unit": p.force_unit,
        "leg_names": list(p.leg_names),
        "base_points": p.base_points,
        "top_points": p.top_points,
        "stiffness": p.stiffness,
        "free_lengths": p.free_lengths,
        "home_pose": p.home_pose,
        "special": p.layout is not None,
        "edge_fractions": None if p.layout is None else dict(
            zip(("O", "P", "Q", "R", "S", "T"), p.layout.t, strict=True)),
        "jacobian_det_home": float(jacobian_det(p, p.home_pose)),
        "singularity_measure_home": float(singularity_measure(p, p.home_pose)),
        "design": None if d is None else {
            "base_side": d.base_side, "top_side": d.top_side, "base_offset": d.base_offset,
            "top_offset": d.top_offset, "home_height": d.height,
            "home_twist_deg": float(np.degrees(d.twist)), "stiffness": d.stiffness},
        "mobility": platform_mobility(p),
    }
    if as_json:
        print_json({**out, "units": units(p.length_unit, p.force_unit)})
        return
    console.print(f"[bold]{literal(p.name)}[/] (lengths in {p.length_unit}, forces in "
                  f"{p.force_unit}; "
                  f"{'special 6-6' if p.layout is not None else 'general 6-6'})")
    console.print(table("Legs", ["leg", "base x", "base y", "base z", "top x", "top y", "top z",
                                 "k", "free length"],
                        [[n, *b, *t, k, l0] for n, b, t, k, l0 in zip(
                            p.leg_names, p.base_points, p.top_points, p.stiffness,
                            p.free_lengths, strict=True)]))
    console.print(table("Home pose (top frame in base frame)", ["", "x", "y", "z", "t"],
                        _pose_rows(p.home_pose)))
    console.print(f"det j at home = {out['jacobian_det_home']:.6g}, singularity measure = "
                  f"{out['singularity_measure_home']:.4f}")
    mob = out["mobility"]
    console.print(f"mobility ({mob['structure']}; Grübler–Kutzbach {mob['formula']}, λ = "
                  f"{mob['space']}, n = {mob['links']}, j = {mob['joints']}): "
                  + "; ".join(f"{c} legs M = {v['mobility']}"
                              + (f" ({v['idle']} idle leg spins, the top {v['top']})"
                                 if v["idle"] else "")
                              for c, v in mob["chains"].items()))


@platform_app.command("fk")
def fk_command(
    legs: str = typer.Option(..., "--legs", help="Six leg lengths in leg order (O,P,Q,R,S,T).",
                             metavar=LEGS_METAVAR),
    platform: str = typer.Option(None, "--platform", parser=name_value,
                                 help=PLATFORM_HELP, metavar="FILE"),
    all_poses: bool = flag(False, "--all-poses", help="Also print every mode's 4x4 pose."),
    view: bool = flag(False, "--view", help="Also open a 3D view in the browser."),
    html: Path = typer.Option(None, "--html", parser=path_value,
                              metavar="FILE", help="With --view: write the "
                              "3D page to FILE (self-contained) instead of opening a browser."),
    as_json: bool = json_option(),
) -> None:
    """Every real assembly mode for six leg lengths, each verified by reverse kinematics; the
    physical one (the top above the base, nearest the home pose) is marked.

    JSON: {"count", "method", "solutions": [{"pose", "top_points", "above_base",
    "max_leg_error", "home_distance", "physical"}], "physical_mode" (1-based, as printed)};
    top_points are O1..T1 (leg order) in base coordinates; home_distance is |p - p_home| +
    r_top * (rotation angle from home), r_top the top's mean radius.
    """
    check_output_file(html, "--html")
    from kinestat.parallel.fk import fk_list, fk_numeric  # lazy: start-up (numba)
    from kinestat.parallel.legs import leg_lengths, top_points_in_base  # lazy: start-up

    p = _load(platform)
    L = parse_floats(legs, 6, "legs")
    for name, x in zip(p.leg_names, L, strict=True):
        if x <= 0:
            raise InputError(f"--legs: leg {name} has length {x:g}; leg lengths must be positive "
                             f"(order {', '.join(p.leg_names)})")
    if p.layout is not None:
        with compiling_notice("platform"):
            poses = fk_list(p, L)
        method = "special 6-6 -> 3-3 closed form, all modes"
    else:
        try:
            poses, method = [fk_numeric(p, L)], "numerical (Newton from home), one mode"
        except UnreachableError as exc:
            raise UnreachableError(
                f"no assembly of {p.name!r} found near its home pose: it is a general 6-6 "
                "platform, which platform fk solves by Newton from home only (one mode); check "
                f"the leg lengths (order {', '.join(p.leg_names)}; at home "
                f"{', '.join(f'{x:.4g}' for x in leg_lengths(p, p.home_pose))})") from exc
    sols = [{"pose": T, "top_points": top_points_in_base(p, T),
             "above_base": bool(T[2, 3] >= 0),
             "max_leg_error": float(np.max(np.abs(leg_lengths(p, T) - L))),
             "home_distance": _home_distance(p, T)} for T in poses]
    physical = _physical_mode(sols)
    for i, s in enumerate(sols):
        s["physical"] = i == physical
    out = {"count": len(sols), "method": method, "leg_names": list(p.leg_names),
           "leg_lengths": L, "solutions": sols,
           "physical_mode": None if physical is None else physical + 1}
    if view or html is not None:
        from kinestat.viz.show import show_platform_modes  # lazy: viewer only with --view

        show_platform_modes(p, poses, L, html=html,
                            physical=0 if physical is None else physical)
    if as_json:
        print_json({**out, "units": units(p.length_unit, p.force_unit)})
        return
    _print_modes(p, sols, method, physical, all_poses)


def _home_distance(p, T: np.ndarray) -> float:
    """|p - p_home| + r_top * angle(R_home^T R): how far a mode is from the home pose."""
    H = p.home_pose
    cos = np.clip((np.trace(H[:3, :3].T @ T[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)
    r_top = float(np.mean(np.linalg.norm(np.asarray(p.top_points), axis=1)))
    return float(np.linalg.norm(T[:3, 3] - H[:3, 3]) + r_top * np.arccos(cos))


def _physical_mode(sols: list[dict]) -> int | None:
    """The physical assembly: above the base and nearest the home pose (None if none above)."""
    above = [i for i, s in enumerate(sols) if s["above_base"]]
    return min(above, key=lambda i: sols[i]["home_distance"]) if above else None


def _print_modes(p, sols: list[dict], method: str, physical: int | None, all_poses: bool) -> None:
    """One table of the modes (position, yaw, above the base, leg error), the physical one
    marked, and its pose (every pose with --all-poses)."""
    console.print(f"[bold]{len(sols)}[/] assembly mode(s) of {literal(p.name)} ({method})")
    rows = []
    for i, s in enumerate(sols):
        T = s["pose"]
        yaw = float(np.degrees(np.arctan2(T[1, 0], T[0, 0])))
        rows.append([f"{i + 1}", "physical" if i == physical else "", *T[:3, 3], yaw,
                     "yes" if s["above_base"] else "no", f"{s['max_leg_error']:.1e}",
                     s["home_distance"]])
    u = p.length_unit
    console.print(table("Assembly modes (top frame in the base frame)",
                        ["mode", "", f"x ({u})", f"y ({u})", f"z ({u})", "yaw (deg)",
                         "above base", f"leg error ({u})", "from home"], rows, fmt="{:.4g}"))
    if physical is None:
        console.print("no mode has the top above the base: none is marked physical")
    for i, s in enumerate(sols):
        if all_poses or i == physical:
            what = "the physical mode" if i == physical else "pose"
            console.print(table(f"Mode {i + 1}: {what} (max leg error "
                                f"{s['max_leg_error']:.2e} {u})", ["", "x", "y", "z", "t"],
                                _pose_rows(s["pose"])))


@platform_app.command("ik")
def ik_command(
    pose: str = typer.Option(..., "--pose", help=POSE_HELP, metavar=POSE_METAVAR),
    platform: str = typer.Option(None, "--platform", parser=name_value,
                                 help=PLATFORM_HELP, metavar="FILE"),
    as_json: bool = json_option(),
) -> None:
    """Leg lengths at a pose (reverse kinematics). JSON: {"leg_lengths", "leg_names"}."""
    from kinestat.parallel.legs import leg_lengths  # lazy: start-up

    p = _load(platform)
    T = _pose(pose, p)
    L = leg_lengths(p, T)
    out = {"leg_names": list(p.leg_names), "leg_lengths": L,
           "extension": L - p.free_lengths}
    if as_json:
        print_json({**out, "units": units(p.length_unit, p.force_unit)})
        return
    console.print(table(f"Leg lengths ({p.length_unit})", ["leg", "length", "l - l0"],
                        [[n, x, e] for n, x, e in zip(p.leg_names, L, out["extension"],
                                                      strict=True)]))


@platform_app.command("statics")
def statics_command(
    pose: str = typer.Option(..., "--pose", help=POSE_HELP, metavar=POSE_METAVAR),
    wrench: str = typer.Option(..., "--wrench", help=WRENCH_HELP, metavar=WRENCH_METAVAR),
    platform: str = typer.Option(None, "--platform", parser=name_value,
                                 help=PLATFORM_HELP, metavar="FILE"),
    as_json: bool = json_option(),
) -> None:
    """Leg forces balancing an external wrench at a pose, f = j^-1 w (Vibhute eq. 2-8).

    Forces are tensions (positive: the leg pulls). JSON: {"leg_forces", "jacobian_det",
    "singularity_measure", "leg_names"}.
    """
    from kinestat.parallel.singularity import singularity_measure  # lazy: start-up
    from kinestat.parallel.statics import forces_from_wrench, jacobian_det  # lazy: numba

    p = _load(platform)
    T = _pose(pose, p)
    w = parse_floats(wrench, 6, "wrench")
    f = forces_from_wrench(p, T, w)
    out = {"leg_names": list(p.leg_names), "leg_forces": f,
           "jacobian_det": float(jacobian_det(p, T)),
           "singularity_measure": float(singularity_measure(p, T)),
           "convention": "leg force > 0 is tension; wrench = external wrench on the top, "
                         "moment about O0, base frame"}
    if as_json:
        print_json({**out, "units": units(p.length_unit, p.force_unit)})
        return
    console.print(table(f"Leg tensions ({p.force_unit})", ["leg", "force"],
                        [[n, x] for n, x in zip(p.leg_names, f, strict=True)]))
    console.print(f"det j = {out['jacobian_det']:.6g}, singularity measure = "
                  f"{out['singularity_measure']:.4f}")


@platform_app.command("stiffness")
def stiffness_command(
    pose: str = typer.Option("home", "--pose", help=POSE_HELP, metavar=POSE_METAVAR),
    wrench: str = typer.Option(None, "--wrench", help=WRENCH_HELP + " The legs carry "
                               "j^-1 w instead of their spring forces at the pose.",
                               metavar=WRENCH_METAVAR),
    twist_order: str = typer.Option("ray", "--twist-order",
                                    help=help_text("'ray': dD = [dx; dphi] (default); "
                                                   "'axis': [dphi; dx].")),
    platform: str = typer.Option(None, "--platform", parser=name_value,
                                 help=PLATFORM_HELP, metavar="FILE"),
    as_json: bool = json_option(),
) -> None:
    """Spatial stiffness K (dw = K dD, Vibhute eq. 2-17) at a pose, loaded by the springs or w.

    JSON: {"stiffness" (6x6), "twist_order", "leg_forces", "asymmetry" (max |K - K^T|)}.
    """
    from kinestat.parallel.legs import leg_lengths  # lazy: start-up
    from kinestat.parallel.statics import forces_from_wrench  # lazy: start-up (numba)
    from kinestat.parallel.stiffness import TWIST_ORDERS, stiffness  # lazy: start-up (numba)

    if twist_order not in TWIST_ORDERS:
        raise InputError(f"--twist-order must be one of {list(TWIST_ORDERS)}, got "
                         f"{twist_order!r}")
    p = _load(platform)
    T = _pose(pose, p)
    forces = None
    if wrench is not None:
        forces = forces_from_wrench(p, T, parse_floats(wrench, 6, "wrench"))
    K = stiffness(p, T, forces, twist_order=twist_order)
    if forces is None:

        forces = p.stiffness * (leg_lengths(p, T) - p.free_lengths)
    Kr = stiffness(p, T, forces)
    out = {"stiffness": K, "twist_order": twist_order, "leg_forces": forces,
           "asymmetry": float(np.max(np.abs(Kr - Kr.T)))}
    if as_json:
        print_json({**out, "units": units(p.length_unit, p.force_unit)})
        return
    cols = ["dx", "dy", "dz", "dphi_x", "dphi_y", "dphi_z"]
    if twist_order == "axis":
        cols = cols[3:] + cols[:3]
    rows = [[r, *K[i]] for i, r in enumerate(["fx", "fy", "fz", "mx", "my", "mz"])]
    console.print(table(f"Stiffness ({p.force_unit}, {p.length_unit}; dw = K dD)", ["", *cols],
                        rows, fmt="{:.4g}"))
    console.print(f"max |K - K^T| = {out['asymmetry']:.4g} (zero when unloaded)")


CONTACT_HELP = ("A wrench the contact can exert, fx,fy,fz,mx,my,mz (moment about O0, base "
                "frame); repeat for 1 to 6 independent wrenches.")
DECOMPOSE_TWIST_HELP = help_text("Twist wx,wy,wz,vx,vy,vz: [omega; v_O] (rad, length unit), "
                                 "base frame.")


@platform_app.command("decompose")
def decompose_command(
    twist: str = typer.Option(..., "--twist", help=DECOMPOSE_TWIST_HELP, metavar=TWIST_METAVAR),
    contact: list[str] = typer.Option(..., "--contact", help=CONTACT_HELP, metavar=WRENCH_METAVAR),
    pose: str = typer.Option("home", "--pose", help=POSE_HELP, metavar=POSE_METAVAR),
    wrench: str = typer.Option(None, "--wrench", help=WRENCH_HELP, metavar=WRENCH_METAVAR),
    platform: str = typer.Option(None, "--platform", parser=name_value,
                                 help="TOML platform file (default: the embedded 2011 prototype).",
                                 metavar="FILE"),
    as_json: bool = json_option(),
) -> None:
    """Twist of freedom and twist of compliance of a twist against contact wrenches.

    T = T_f + T_c, T_c = K^-1 W lambda, W^T Delta T_f = 0 (Griffis & Duffy; Vibhute 2.1.3.3).
    Twists in axis order [omega; v_O]. JSON: {"freedom" (6), "compliance" (6), "lambda" (m),
    "wrench_change" (6, = W lambda = K T_c), "twist_order": "axis"}.
    """
    from kinestat.parallel.kinestatic import (  # lazy: start-up (numba)
        decompose_twist,
        platform_stiffness_axis,
    )

    if not 1 <= len(contact) <= 6:
        raise InputError(f"--contact: give 1 to 6 contact wrenches, got {len(contact)}")
    W = np.stack([parse_floats(c, 6, "contact") for c in contact], axis=1)
    T_axis = parse_floats(twist, 6, "twist")
    p = _load(platform)
    T_base_top = _pose(pose, p)
    w0 = None if wrench is None else parse_floats(wrench, 6, "wrench")
    K = platform_stiffness_axis(p, T_base_top, w0)
    s = decompose_twist(K, W, T_axis)
    out = {"freedom": s.freedom, "compliance": s.compliance, "lambda": s.lam,
           "wrench_change": W @ s.lam, "twist_order": "axis"}
    if as_json:
        print_json({**out, "units": units(p.length_unit, p.force_unit)})
        return
    u = p.length_unit
    cols = ["wx (rad)", "wy (rad)", "wz (rad)", f"vx ({u})", f"vy ({u})", f"vz ({u})"]
    title = "Kinestatic decomposition T = T_f + T_c (axis order \\[w; v_O], base frame)"
    console.print(table(title, ["", *cols], [["twist T", *T_axis], ["freedom T_f", *s.freedom],
                                      ["compliance T_c", *s.compliance]], fmt="{:.6g}"))
    console.print(table(f"Wrench change W lambda ({p.force_unit}, {p.force_unit}·{u})",
                        ["", "fx", "fy", "fz", "mx", "my", "mz"],
                        [["dw", *out["wrench_change"]]], fmt="{:.6g}"))
    console.print("lambda = " + ", ".join(f"{x:.6g}" for x in s.lam))
