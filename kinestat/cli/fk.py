"""``kinestat fk``: forward kinematics of a model at one configuration."""

from __future__ import annotations

import numpy as np
import typer

from kinestat.cli._output import console, literal, parse_floats, print_json, table
from kinestat.errors import InputError


def register(app: typer.Typer) -> None:
    app.command("fk")(fk_command)


def fk_command(
    model: str = typer.Argument(..., help="Embedded model name (e.g. puma762) or a TOML file."),
    q: str = typer.Option(None, "--q", help="Joint values, comma-separated (radians / length)."),
    q_deg: str = typer.Option(
        None, "--q-deg", help="Joint values with rotating joints in degrees (prismatic: length)."
    ),
    tool_point_6: str = typer.Option(
        "0,0,0", "--tool-point-6", help="Tool point in the end frame (frame n: the PUMA's "
        "frame 6), x,y,z."
    ),
    euler: str = typer.Option(
        "ZYX", "--euler", help="Euler sequence for the orientation (SciPy style: ZYX intrinsic, "
        "zyx extrinsic)."
    ),
    frames: bool = typer.Option(False, "--frames", help="Also report every link frame."),
    as_json: bool = typer.Option(False, "--json", help="Machine-readable JSON output."),
) -> None:
    """Pose of the end frame; for the PUMA 762 also P_tool_F, S6_F and a67_F (Vibhute eq. 2-34).

    JSON: {"pose", "tool_point", "s6" (z of the end frame), "a67" (x of the end frame),
    "euler_deg", "euler_seq", "gimbal_lock", "q"} (+ "frames" with --frames).
    """
    import kinestat
    from kinestat.serial.fk import fk_frames
    from kinestat.spatial.euler import euler_from_matrix

    m = kinestat.load(model)
    if (q is None) == (q_deg is None):
        raise InputError("give the joint values with exactly one of --q or --q-deg")
    vals = parse_floats(q if q is not None else q_deg, m.n, "q" if q is not None else "q-deg")
    if q_deg is not None:
        vals = np.where(m.prismatic, vals, np.deg2rad(vals))
    p6 = parse_floats(tool_point_6, 3, "tool-point-6")
    F = fk_frames(m, vals)
    T = F[-1]
    ang, lock = euler_from_matrix(T[:3, :3], euler, degrees=True, return_degenerate=True)
    out = {
        "model": m.name,
        "q": vals,
        "pose": T,
        "tool_point": T[:3, :3] @ p6 + T[:3, 3],
        "s6": T[:3, 2],
        "a67": T[:3, 0],
        "euler_seq": euler,
        "euler_deg": ang,
        "gimbal_lock": bool(lock),
        "length_unit": m.length_unit,
    }
    if not m.within_limits(vals):
        out["warning"] = "the configuration is outside the model's joint limits"
    if frames:
        out["frames"] = F
    if as_json:
        print_json(out)
        return
    console.print(f"[bold]{literal(m.name)}[/] ({m.n} joints, lengths in {literal(m.length_unit)})")
    console.print(table("End pose", ["", "x", "y", "z", "t"],
                        [[r] + list(T[i]) for i, r in enumerate(["1", "2", "3", "4"])]))
    console.print(table("Tool", ["", "x", "y", "z"], [
        ["tool point", *out["tool_point"]], ["s6 (z)", *out["s6"]], ["a67 (x)", *out["a67"]],
    ]))
    console.print(f"Euler {euler} (deg): " + ", ".join(f"{a:.4f}" for a in ang)
                  + ("  \\[gimbal lock]" if lock else ""))
    if "warning" in out:
        console.print(f"[yellow]warning:[/] {literal(out['warning'])}")
    if frames:
        console.print(table("Link frame origins", ["frame", "x", "y", "z"],
                            [[i, *F[i, :3, 3]] for i in range(len(F))]))
