"""``kinestat dh-from-axes``: standard DH table from joint axes (lecture notes' algorithm).

The axes file format is described and read in :mod:`kinestat.io.axes_file`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import typer

from kinestat.cli._options import check_output_file, command_help, flag, json_option, path_value
from kinestat.cli._output import console, literal, print_json, table
from kinestat.errors import InputError, ParseError
from kinestat.io.axes_file import read_axes_file
from kinestat.io.model_toml import write_model as save_model
from kinestat.mechanism.dh_from_axes import dh_from_axes

__all__ = ["register"]


def register(app: typer.Typer) -> None:
    app.command("dh-from-axes", help=command_help(dh_from_axes_command))(dh_from_axes_command)


def dh_from_axes_command(
    file: Path = typer.Argument(..., parser=path_value,
                                help="Axes file (TOML, or JSON if it ends in .json)."),
    deg: bool = flag(True, "--deg/--rad", help="Angles θ, α in degrees (default) or "
                             "radians, in the table and the JSON keys (theta_deg or theta)."),
    write_model: Path = typer.Option(None, "--write-model", parser=path_value,
                                     help="Save the resulting model as a "
                                     "standard-DH TOML model file."),
    tol: float = typer.Option(None, "--tol", help="Tolerance for parallel/meeting axes "
                              "(overrides the file's tol; default 1e-9)."),
    as_json: bool = json_option(),
) -> None:
    """Standard DH table (θ, d, a, α) from the joint axes, by the lecture notes' frame assignment.

    JSON: {"name", "length_unit", "table": [{"joint", "type", "theta_deg", "d", "a",
    "alpha_deg", "relation"}, ...], "base", "tool", "frames", "model_file"} (theta/alpha in
    radians with --rad). "relation" is how z_{i-1} relates to z_i (the last row: to the tool).
    """
    check_output_file(write_model, "--write-model", what="model file")
    spec = read_axes_file(file)
    if tol is not None:
        if not (math.isfinite(tol) and tol >= 0):
            raise InputError(f"--tol must be a finite non-negative number, got {tol}")
        spec["tol"] = tol
    try:
        res = dh_from_axes(
            spec["axes"], spec["kinds"], pitches=spec["pitches"], names=spec["names"],
            base=spec.get("base"), tool=spec.get("tool"), tol=spec.get("tol", 1e-9),
            name=spec["name"], length_unit=spec["length_unit"],
            description=spec["description"],
        )
    except ParseError:
        raise
    except InputError as exc:  # a base off axis 1, a bad tool...: say which file
        raise ParseError(str(exc), file=str(file)) from exc
    if write_model is not None:
        save_model(res.model, write_model)
    ang = (lambda x: math.degrees(x) + 0.0) if deg else (lambda x: float(x) + 0.0)
    th_key, al_key = ("theta_deg", "alpha_deg") if deg else ("theta", "alpha")
    rows = []
    for i, ((th, d, a, al), rel) in enumerate(zip(res.table, res.relations, strict=True)):
        rows.append({"joint": spec["names"][i], "type": spec["kinds"][i], th_key: ang(th),
                     "d": float(d) + 0.0, "a": float(a) + 0.0, al_key: ang(al),
                     "relation": rel})
    if as_json:
        print_json({"name": res.model.name, "length_unit": res.model.length_unit,
                    "table": rows, "base": res.base, "tool": res.tool, "frames": res.frames,
                    "model_file": None if write_model is None else str(write_model)})
        return
    unit = "deg" if deg else "rad"
    console.print(f"[bold]{literal(res.model.name)}[/] ({res.n} joints, lengths in "
                  f"{literal(res.model.length_unit)}): H_i^(i-1) = Rz(θ) Tz(d) Tx(a) Rx(α)")
    console.print(table("Standard DH table", ["joint", "type", f"θ ({unit})", "d", "a",
                                              f"α ({unit})", "z(i-1) → z(i)"],
                        [[r["joint"], r["type"], r[th_key], r["d"], r["a"], r[al_key],
                          r["relation"]] for r in rows]))
    console.print(table("Base (frame 0 in the world)", ["", "x", "y", "z", "o"],
                        [[str(i + 1), *res.base[i]] for i in range(4)]))
    if not np.allclose(res.tool, np.eye(4), atol=1e-12):
        console.print(table("Tool (in frame n)", ["", "x", "y", "z", "o"],
                            [[str(i + 1), *res.tool[i]] for i in range(4)]))
    if write_model is not None:
        console.print(f"model written to {literal(write_model)}")
