"""``kinestat platform decompose``: split a twist into a twist of freedom and one of compliance.

Griffis & Duffy's kinestatic decomposition (Vibhute 2011 §2.1.3.3) with the platform's loaded
stiffness: ``T = T_f + T_c``, ``T_c = K⁻¹ W λ``, ``T_f`` reciprocal to every contact wrench
(:mod:`kinestat.parallel.kinestatic`). K is the stiffness that
``kinestat platform stiffness --pose P [--wrench W0] --twist-order axis`` reports.

This module adds the command to the ``platform`` group: call :func:`register` with the group's
Typer app (``register(platform_app)`` in :mod:`kinestat.cli.platform`).
"""

from __future__ import annotations

import numpy as np
import typer

from kinestat.cli._output import console, parse_floats, parse_pose, print_json, table
from kinestat.errors import InputError

POSE_HELP = "'home', a JSON/TOML file holding a 4x4 pose, or 16 comma-separated numbers."
WRENCH_HELP = ("External wrench W0 on the top fx,fy,fz,mx,my,mz (moment about O0, base frame); "
               "the legs carry j^-1 W0 instead of their spring forces at the pose.")
CONTACT_HELP = ("A wrench the contact can exert, fx,fy,fz,mx,my,mz (moment about O0, base "
                "frame); repeat for 1 to 5 independent wrenches.")
TWIST_HELP = "Twist wx,wy,wz,vx,vy,vz: [omega; v_O] (rad, length unit), base frame."


def _load(path: str | None):
    from kinestat.io.platform_toml import read_platform
    from kinestat.parallel.platform import prototype

    return prototype() if path is None else read_platform(path)


def _pose(text: str, platform) -> np.ndarray:
    from kinestat.parallel.legs import as_pose

    if text.strip().lower() == "home":
        return platform.home_pose.copy()
    return as_pose(parse_pose(text, "pose"), "--pose")


def decompose_command(
    twist: str = typer.Option(..., "--twist", help=TWIST_HELP),
    contact: list[str] = typer.Option(..., "--contact", help=CONTACT_HELP),
    pose: str = typer.Option("home", "--pose", help=POSE_HELP),
    wrench: str = typer.Option(None, "--wrench", help=WRENCH_HELP),
    platform: str = typer.Option(None, "--platform",
                                 help="TOML platform file (default: the embedded 2011 prototype)."),
    as_json: bool = typer.Option(False, "--json", help="Machine-readable JSON output."),
) -> None:
    """Twist of freedom and twist of compliance of a twist against contact wrenches.

    T = T_f + T_c, T_c = K^-1 W lambda, W^T Delta T_f = 0 (Griffis & Duffy; Vibhute 2.1.3.3).
    Twists in axis order [omega; v_O]. JSON: {"freedom" (6), "compliance" (6), "lambda" (m),
    "wrench_change" (6, = W lambda = K T_c), "twist_order": "axis"}.
    """
    from kinestat.parallel.kinestatic import decompose_twist, platform_stiffness_axis

    if not 1 <= len(contact) <= 5:
        raise InputError(f"--contact: give 1 to 5 contact wrenches, got {len(contact)}")
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
        print_json(out)
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


def register(platform_app: typer.Typer) -> None:
    """Add ``decompose`` to the ``kinestat platform`` group."""
    platform_app.command("decompose")(decompose_command)
