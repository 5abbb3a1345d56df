"""``kinestat dh-from-axes``: standard DH table from joint axes (lecture notes' algorithm).

The axes file (TOML, or JSON with the same structure) lists the joint axes in the world frame,
in one configuration of the arm::

    name = "my-arm"              # optional (default: the file name)
    length_unit = "mm"           # optional
    description = "..."          # optional
    tol = 1e-9                   # optional (see kinestat.mechanism.dh_from_axes)
    tool = [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]   # optional: tool pose, world frame
    base = [[...]]               # optional: frame 0 (z on axis 1, along it)

    [[axes]]
    name = "1"                   # optional
    type = "revolute"            # revolute | prismatic | screw (default revolute)
    point = [0, 0, 0]            # a point on the axis
    direction = [0, 0, 1]        # the positive sense of the joint
    # or instead of point and direction: plucker = [Sx, Sy, Sz, S0x, S0y, S0z]
    pitch = 0.0                  # screw joints only: length per radian
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import typer

from kinestat.cli._output import console, print_json, table
from kinestat.errors import InputError, ParseError
from kinestat.io.textfile import read_text_file

__all__ = ["register", "read_axes_file", "loads_axes"]

_TOP_KEYS = {"name", "length_unit", "description", "tol", "tool", "base", "axes"}
_AXIS_KEYS = {"name", "type", "point", "direction", "plucker", "pitch"}


def register(app: typer.Typer) -> None:
    app.command("dh-from-axes")(dh_from_axes_command)


def _vector(v, size: int, source: str, field: str) -> list[float]:
    if not isinstance(v, list) or len(v) != size:
        raise ParseError(f"expected a list of {size} numbers, got {v!r}", file=source, field=field)
    out = []
    for x in v:
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
            raise ParseError(f"expected finite numbers, got {x!r}", file=source, field=field)
        out.append(float(x))
    return out


def _pose(v, source: str, field: str) -> np.ndarray:
    if not isinstance(v, list) or len(v) != 4:
        raise ParseError("expected a 4x4 array (four rows of four numbers)", file=source,
                         field=field)
    return np.array([_vector(r, 4, source, f"{field}[{i + 1}]") for i, r in enumerate(v)])


def loads_axes(doc: dict, source: str = "<string>") -> dict:
    """Check a parsed axes document; returns keyword arguments for ``dh_from_axes`` plus the
    joint ``kinds`` and ``axes`` (``(n, 2, 3)`` or ``(n, 6)``)."""
    if not isinstance(doc, dict):
        raise ParseError("expected a table/object at the top level", file=source)
    unknown = set(doc) - _TOP_KEYS
    if unknown:
        raise ParseError(f"unknown top-level keys {sorted(unknown)}; expected some of "
                         f"{sorted(_TOP_KEYS)}", file=source)
    axes = doc.get("axes")
    if not isinstance(axes, list) or not axes:
        raise ParseError("expected at least one [[axes]] entry (a point and a direction each)",
                         file=source, field="axes")
    lines, kinds, pitches, names, forms = [], [], [], [], set()
    for i, ax in enumerate(axes, start=1):
        where = f"axes[{i}]"
        if not isinstance(ax, dict):
            raise ParseError("each axis must be a table", file=source, field=where)
        extra = set(ax) - _AXIS_KEYS
        if extra:
            raise ParseError(f"unknown keys {sorted(extra)}; expected some of "
                             f"{sorted(_AXIS_KEYS)}", file=source, field=where)
        kind = ax.get("type", "revolute")
        if kind not in ("revolute", "prismatic", "screw"):
            raise ParseError(f"unknown joint type {kind!r}; expected revolute, prismatic or "
                             "screw", file=source, field=f"{where}.type")
        if "plucker" in ax:
            if "point" in ax or "direction" in ax:
                raise ParseError("give either plucker or point and direction, not both",
                                 file=source, field=where)
            pl = _vector(ax["plucker"], 6, source, f"{where}.plucker")
            S, S0 = np.array(pl[:3]), np.array(pl[3:])
            nS = float(np.linalg.norm(S))
            if nS == 0.0:
                raise ParseError("the direction S (first three numbers) is the zero vector; "
                                 "give the axis direction", file=source,
                                 field=f"{where}.plucker")
            # the same test as kinestat.mechanism.dh_from_axes applies
            if abs(float(S @ S0)) > 1e-6 * nS * max(float(np.linalg.norm(S0)), nS):
                raise ParseError("not a line: Plücker coordinates [S; S0] need S . S0 = 0 "
                                 "(S0 = r x S for a point r on the line)", file=source,
                                 field=f"{where}.plucker")
            lines.append(pl)
            forms.add("plucker")
        else:
            for k in ("point", "direction"):
                if k not in ax:
                    raise ParseError(f"missing '{k}' (or give 'plucker')", file=source,
                                     field=f"{where}.{k}")
            p = _vector(ax["point"], 3, source, f"{where}.point")
            s = _vector(ax["direction"], 3, source, f"{where}.direction")
            if not any(s):
                raise ParseError("the direction is the zero vector; give the axis direction",
                                 file=source, field=f"{where}.direction")
            lines.append([p, s])
            forms.add("point")
        pitch = ax.get("pitch", 0.0)
        if isinstance(pitch, bool) or not isinstance(pitch, (int, float)) \
                or not math.isfinite(pitch):
            raise ParseError(f"pitch must be a finite number, got {pitch!r}", file=source,
                             field=f"{where}.pitch")
        if kind == "screw" and pitch == 0.0:
            raise ParseError("a screw joint needs a non-zero pitch", file=source,
                             field=f"{where}.pitch")
        if kind != "screw" and pitch != 0.0:
            raise ParseError(f"pitch is only for screw joints, not {kind}", file=source,
                             field=f"{where}.pitch")
        kinds.append(kind)
        pitches.append(float(pitch))
        names.append(str(ax.get("name", i)))
    if len(forms) > 1:  # mixed forms: write every axis in Plücker coordinates [s; p x s]
        lines = [ln if len(ln) == 6 else [*ln[1], *np.cross(ln[0], ln[1])] for ln in lines]
    out: dict = {"axes": np.array(lines, dtype=float), "kinds": kinds, "pitches": pitches,
                 "names": names, "name": str(doc.get("name", Path(source).stem)),
                 "length_unit": str(doc.get("length_unit", "mm")),
                 "description": str(doc.get("description", ""))}
    for k in ("tool", "base"):
        if k in doc:
            out[k] = _pose(doc[k], source, k)
    if "tol" in doc:
        tol = doc["tol"]
        if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not (
                math.isfinite(tol) and tol >= 0):
            raise ParseError(f"tol must be a finite non-negative number, got {tol!r}",
                             file=source, field="tol")
        out["tol"] = float(tol)
    return out


def read_axes_file(path: str | Path) -> dict:
    """Read an axes file (``.json`` as JSON, anything else as TOML); see the module docstring."""
    p = Path(path)
    text = read_text_file(p, "axes file")
    if p.suffix.lower() == ".json":
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ParseError(f"not valid JSON: {exc.msg}", file=str(p), line=exc.lineno) from exc
    else:
        try:
            doc = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ParseError(f"not valid TOML: {exc}", file=str(p)) from exc
    return loads_axes(doc, source=str(p))


def dh_from_axes_command(
    file: Path = typer.Argument(..., help="Axes file (TOML, or JSON if it ends in .json)."),
    deg: bool = typer.Option(True, "--deg/--rad", help="Angles θ, α in degrees (default) or "
                             "radians, in the table and the JSON keys (theta_deg or theta)."),
    write_model: Path = typer.Option(None, "--write-model", help="Save the resulting model as a "
                                     "standard-DH TOML model file."),
    tol: float = typer.Option(None, "--tol", help="Tolerance for parallel/meeting axes "
                              "(overrides the file's tol; default 1e-9)."),
    as_json: bool = typer.Option(False, "--json", help="Machine-readable JSON output."),
) -> None:
    """Standard DH table (θ, d, a, α) from the joint axes, by the lecture notes' frame assignment.

    JSON: {"name", "length_unit", "table": [{"joint", "type", "theta_deg", "d", "a",
    "alpha_deg", "relation"}, ...], "base", "tool", "frames", "model_file"} (theta/alpha in
    radians with --rad). "relation" is how z_{i-1} relates to z_i (the last row: to the tool).
    """
    from kinestat.io.model_toml import write_model as save_model
    from kinestat.mechanism.dh_from_axes import dh_from_axes

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
    console.print(f"[bold]{res.model.name}[/] ({res.n} joints, lengths in "
                  f"{res.model.length_unit}): H_i^(i-1) = Rz(θ) Tz(d) Tx(a) Rx(α)")
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
        console.print(f"model written to {write_model}")
