"""``kinestat fk``: forward kinematics (the theses' forward analysis) of a model at one
configuration, reported in the model's own words (its joint names; the PUMA 762's S6/a67 only
for the PUMA 762)."""

from __future__ import annotations

import numpy as np
import typer

from kinestat.cli._model import (
    MODEL_HELP,
    base_option,
    length_unit_option,
    load_model,
    scale_option,
    tip_option,
)
from kinestat.cli._options import (
    Q_METAVAR,
    XYZ_METAVAR,
    command_help,
    flag,
    json_option,
    name_value,
    units,
)
from kinestat.cli._output import console, literal, parse_floats, print_json, table
from kinestat.errors import InputError

#: the model whose end frame is described in the thesis's words (P_tool_F, S6_F, a67_F)
_PUMA762 = "puma762"


def register(app: typer.Typer) -> None:
    app.command("fk", help=command_help(fk_command))(fk_command)


def fk_command(
    model: str = typer.Argument(..., parser=name_value, help=MODEL_HELP),
    q: str = typer.Option(None, "--q", help="Joint values, comma-separated (radians / length).",
                          metavar=Q_METAVAR),
    q_deg: str = typer.Option(
        None, "--q-deg", help="Joint values with rotating joints in degrees (prismatic: length).",
        metavar=Q_METAVAR
    ),
    tool_offset: str = typer.Option(
        "0,0,0", "--tool-offset", "--tool-point-6", help="Tool point in the end frame (frame "
        "n), x,y,z; --tool-point-6 is the thesis's name (P_tool_6, the PUMA's frame 6).",
        metavar=XYZ_METAVAR
    ),
    euler: str = typer.Option(
        "ZYX", "--euler", help="Euler sequence for the orientation (SciPy style: ZYX intrinsic, "
        "zyx extrinsic).", metavar="SEQ"
    ),
    frames: bool = flag(False, "--frames", help="Also report every link frame."),
    tip: str = tip_option(),
    base: str = base_option(),
    scale: float = scale_option(),
    length_unit: str = length_unit_option(),
    as_json: bool = json_option(),
) -> None:
    """Pose of the end frame T_base_end and the tool point; for the PUMA 762 also P_tool_F,
    S6_F and a67_F in the thesis's words (Vibhute eq. 2-34).

    JSON: {"model", "q", "joint_names", "pose" (T_base_end), "tool_point" (p_base_tool),
    "z_base_end", "x_base_end" (the end frame's z and x axes), "euler_deg", "euler_seq",
    "gimbal_lock", "length_unit"}; for the puma762 model also "s6" and "a67" (the same axes in
    the thesis's words) (+ "frames" with --frames, "warning" outside the joint limits).
    """
    from kinestat.serial.fk import fk_frames  # lazy: as above
    from kinestat.spatial.euler import check_sequence, euler_from_matrix  # lazy: scipy

    try:
        check_sequence(euler)
    except InputError as exc:  # the library's message, with the option it came from
        raise InputError(f"--euler: {exc}") from None
    m = load_model(model, tip, base, scale, length_unit)
    if (q is None) == (q_deg is None):
        raise InputError("give the joint values with exactly one of --q or --q-deg")
    vals = parse_floats(q if q is not None else q_deg, m.n, "q" if q is not None else "q-deg")
    if q_deg is not None:
        vals = np.where(m.prismatic, vals, np.deg2rad(vals))
    p_end_tool = parse_floats(tool_offset, 3, "tool-offset")
    F = fk_frames(m, vals)
    T_base_end = F[-1]
    ang, lock = euler_from_matrix(T_base_end[:3, :3], euler, degrees=True,
                                  return_degenerate=True)
    puma = m.name == _PUMA762
    out = {
        "model": m.name,
        "q": vals,
        "joint_names": [j.name for j in m.joints],
        "pose": T_base_end,
        "tool_point": T_base_end[:3, :3] @ p_end_tool + T_base_end[:3, 3],
        "z_base_end": T_base_end[:3, 2],
        "x_base_end": T_base_end[:3, 0],
        "euler_seq": euler,
        "euler_deg": ang,
        "gimbal_lock": bool(lock),
        "length_unit": m.length_unit,
        "units": units(m.length_unit),
    }
    if puma:  # the thesis's names of the same axes (Vibhute eq. 2-34)
        out["s6"], out["a67"] = out["z_base_end"], out["x_base_end"]
    if not m.within_limits(vals):
        out["warning"] = "the configuration is outside the model's joint limits"
    if frames:
        out["frames"] = F
    if as_json:
        print_json(out)
        return
    _print_human(m, vals, out, F if frames else None, puma)


def _print_human(m, vals: np.ndarray, out: dict, F, puma: bool) -> None:
    """The tables of ``kinestat fk`` (without --json), in the model's own words."""
    T_base_end = out["pose"]
    console.print(f"[bold]{literal(m.name)}[/] ({m.n} joints, lengths in {literal(m.length_unit)})")
    console.print(table("Joints", ["joint", "kind", "value"], [
        [j.name or str(i + 1), j.kind,
         f"{vals[i]:.6g} {m.length_unit}" if j.kind == "prismatic"
         else f"{np.rad2deg(vals[i]):.6g} deg"]
        for i, j in enumerate(m.joints)
    ]))
    console.print(table("End pose T_base_end", ["", "x", "y", "z", "t"],
                        [[r] + list(T_base_end[i]) for i, r in enumerate(["1", "2", "3", "4"])]))
    if puma:
        rows = [["tool point P_tool_F", *out["tool_point"]], ["S6_F (z)", *out["s6"]],
                ["a67_F (x)", *out["a67"]]]
    else:
        rows = [["tool point", *out["tool_point"]], ["end z axis", *out["z_base_end"]],
                ["end x axis", *out["x_base_end"]]]
    console.print(table("Tool", ["", "x", "y", "z"], rows))
    ang = out["euler_deg"]
    console.print(f"Euler {out['euler_seq']} (deg): " + ", ".join(f"{a:.4f}" for a in ang)
                  + ("  \\[gimbal lock]" if out["gimbal_lock"] else ""))
    if "warning" in out:
        console.print(f"[yellow]warning:[/] {literal(out['warning'])}")
    if F is not None:
        console.print(table("Link frame origins", ["frame", "x", "y", "z"],
                            [[i, *F[i, :3, 3]] for i in range(len(F))]))
