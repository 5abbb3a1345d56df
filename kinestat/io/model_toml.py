"""TOML model files: read, write, round trip.

Schema (both units required: angles in the file's ``angle_unit``, lengths in ``length_unit``;
a file without them is refused, naming the key to add)::

    name = "puma762"
    notation = "modified_dh"      # standard_dh | modified_dh | nadkarni
    length_unit = "mm"
    angle_unit = "deg"            # deg | rad
    description = "..."
    base = [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]   # optional (not for nadkarni)
    tool = [[...]]                                      # optional (not for nadkarni)
    q_home = [0, 0, 0, 0, 0, 0]                         # optional, file units

    # nadkarni only: SET FIVE and the seventh (hand) joint
    frame_points = [[0,0,0],[0,0,1],[1,0,0]]
    [hand]
    r = 0.0
    alpha = 0.0
    a = 1.0
    theta = 0.0

    [[joints]]
    name = "1"
    type = "revolute"             # revolute | prismatic | screw
    # standard_dh: theta d a alpha | modified_dh: alpha a theta d | nadkarni: r alpha a theta
    alpha = 90.0
    a = 0.0
    theta = 0.0
    d = 0.0
    pitch = 0.0                   # screw joints: length per radian
    limits = [-160.0, 160.0]      # angle_unit for rotating joints, length_unit for prismatic

For ``standard_dh`` and ``modified_dh`` the joint's θ (or d, prismatic) is an offset added to
the joint value; for ``nadkarni`` the values are the initial configuration (as in DISP).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import tomli_w

from kinestat.errors import InputError, ModelError, ParseError
from kinestat.io._fields import (
    choice,
    joint_type_and_pitch,
    matrix,
    number,
    refuse_unknown,
    short_repr,
    unit,
)
from kinestat.io.textfile import parse_toml, read_text_file, write_text_atomic
from kinestat.mechanism.chain import (
    ChainModel,
    from_modified_dh,
    from_nadkarni,
    from_standard_dh,
)
from kinestat.mechanism.joints import PRISMATIC_PITCH_THRESHOLD

__all__ = ["read_model", "loads_model", "write_model", "dumps_model"]

_FIELDS = {
    "standard_dh": ("theta", "d", "a", "alpha"),
    "modified_dh": ("alpha", "a", "theta", "d"),
    "nadkarni": ("r", "alpha", "a", "theta"),
}
_ANGLES = {"theta", "alpha"}
_TOP_KEYS = {"name", "notation", "length_unit", "angle_unit", "description", "base", "tool",
             "q_home", "frame_points", "hand", "joints", "source"}


def _err(msg: str, source: str, field: str | None = None) -> ParseError:
    return ParseError(msg, file=source, field=field)


def loads_model(text: str, source: str = "<string>") -> ChainModel:
    """Parse a TOML model from text."""
    return _from_doc(parse_toml(text, source), source)


def read_model(path: str | os.PathLike) -> ChainModel:
    """Read a TOML model file."""
    return loads_model(read_text_file(path, "model file"), source=str(Path(path)))


def _limit(x) -> float:
    """A limit as a float (±inf allowed); NaN for anything that is not a number of float size."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return math.nan
    try:
        return float(x)
    except OverflowError:
        return math.nan


def _joint_tables(joints: list, fields: tuple[str, ...], to_rad: float, source: str):
    """Rows (radians), kinds, pitches, limits (radians or length) and names of [[joints]]."""
    rows, kinds, pitches, limits, names = [], [], [], [], []
    for i, j in enumerate(joints, start=1):
        where = f"joints[{i}]"
        if not isinstance(j, dict):
            raise _err("each joint must be a table", source, where)
        refuse_unknown(j, {*fields, "name", "type", "pitch", "limits"}, source, field=where)
        kind, pitch = joint_type_and_pitch(j, source, where)
        row = []
        for f in fields:
            v = number(j.get(f, 0.0), source, f"{where}.{f}")
            row.append(v * to_rad if f in _ANGLES else v)
        rows.append(row)
        kinds.append(kind)
        pitches.append(pitch)
        lim = j.get("limits", [-math.inf, math.inf])
        if not isinstance(lim, list) or len(lim) != 2:
            raise _err("limits must be [lower, upper]", source, f"{where}.limits")
        lo, hi = (_limit(x) for x in lim)
        if math.isnan(lo) or math.isnan(hi) or lo > hi:
            raise _err(f"limits {short_repr(lim)} are not an interval", source, f"{where}.limits")
        scale = 1.0 if kind == "prismatic" else to_rad
        limits.append((lo * scale, hi * scale))
        names.append(str(j.get("name", i)))
    return rows, kinds, pitches, limits, names


def _from_doc(doc: dict, source: str) -> ChainModel:
    refuse_unknown(doc, _TOP_KEYS, source, "top-level keys")
    notation = choice(doc.get("notation"), _FIELDS, source, "notation")
    angle_unit = unit(doc, "angle_unit", source, 'angle_unit = "deg" (or "rad")',
                      ("deg", "rad"))
    to_rad = math.pi / 180.0 if angle_unit == "deg" else 1.0
    # keys of the other notations: refused rather than silently ignored
    unused = ["q_home"] if notation == "nadkarni" else ["frame_points", "hand"]
    for k in unused:
        if k in doc:
            hint = ("the joint values of a nadkarni file are the initial configuration"
                    if k == "q_home" else "it belongs to the nadkarni notation")
            raise _err(f"'{k}' is not used with the {notation} notation ({hint})", source, k)
    name = str(doc.get("name", Path(source).stem))
    length_unit = unit(doc, "length_unit", source, 'length_unit = "mm" (the unit of every length)')
    joints = doc.get("joints")
    if not isinstance(joints, list) or not joints:
        raise _err("expected at least one [[joints]] table", source, "joints")
    fields = _FIELDS[notation]
    rows, kinds, pitches, limits, names = _joint_tables(joints, fields, to_rad, source)
    description = str(doc.get("description", ""))
    try:
        if notation == "nadkarni":
            for k in ("base", "tool"):
                if k in doc:
                    raise _err(f"'{k}' is not used with the nadkarni notation "
                               "(use frame_points and [hand])", source, k)
            fp = matrix(doc.get("frame_points"), source, "frame_points", (3, 3))
            full = []
            for row, kind, pitch in zip(rows, kinds, pitches, strict=True):
                ph = {"prismatic": 2 * PRISMATIC_PITCH_THRESHOLD, "revolute": 0.0}.get(kind, pitch)
                full.append(row + [ph])
            n_active: int | None = None
            if "hand" in doc:
                h = doc["hand"]
                if not isinstance(h, dict):
                    raise _err("[hand] must be a table of r, alpha, a, theta", source, "hand")
                hr = [number(h.get(f, 0.0), source, f"hand.{f}") * (to_rad if f in _ANGLES else 1)
                      for f in fields]
                full.append(hr + [0.0])
                n_active = len(rows)
            model = from_nadkarni(full, fp, n_active=n_active, limits=limits, name=name,
                                  length_unit=length_unit, description=description)
            object.__setattr__(model, "joints", tuple(
                type(jt)(kind=jt.kind, pitch=jt.pitch, lower=jt.lower, upper=jt.upper, name=nm)
                for jt, nm in zip(model.joints, names, strict=True)))
        else:
            base = matrix(doc["base"], source, "base", (4, 4)) if "base" in doc else None
            tool = matrix(doc["tool"], source, "tool", (4, 4)) if "tool" in doc else None
            build = from_standard_dh if notation == "standard_dh" else from_modified_dh
            q_home = None
            if "q_home" in doc:
                if not isinstance(doc["q_home"], list):
                    raise _err(f"q_home must be a list of {len(rows)} numbers, got "
                               f"{doc['q_home']!r}", source, "q_home")
                qh = np.array([number(v, source, "q_home") for v in doc["q_home"]])
                if qh.shape != (len(rows),):
                    raise _err(f"q_home must have {len(rows)} values", source, "q_home")
                q_home = np.where(np.array(kinds) == "prismatic", qh, qh * to_rad)
            model = build(rows, kinds, pitches=pitches, limits=limits, names=names, base=base,
                          tool=tool, name=name, length_unit=length_unit, q_home=q_home,
                          description=description)
    except ParseError:
        raise
    except InputError as exc:  # ModelError, and InputError from the frame points
        raise _err(str(exc), source) from exc
    return model


def _clean(x: float) -> float:
    """Round-trip-safe float for TOML (drop -0.0 and tiny float noise is NOT done: exact)."""
    return 0.0 if x == 0.0 else float(x)


def dumps_model(model: ChainModel, angle_unit: str = "deg") -> str:
    """Serialise a model to TOML in its own notation (``chain`` models cannot be written)."""
    if model.notation not in _FIELDS:
        raise ModelError(f"model {model.name!r} in notation {model.notation!r} has no TOML form; "
                         "build it from a DH table or Nadkarni's notation")
    to_file = 180.0 / math.pi if angle_unit == "deg" else 1.0
    fields = _FIELDS[model.notation]
    doc: dict = {"name": model.name, "notation": model.notation,
                 "length_unit": model.length_unit, "angle_unit": angle_unit}
    if model.description:
        doc["description"] = model.description
    joints = []
    if model.notation == "nadkarni":
        ex = model.extra_dict()
        rows = np.asarray(ex["rows"])
        n_active = int(ex["n_active"])
        doc["frame_points"] = [[_clean(v) for v in p] for p in np.asarray(ex["frame_points"])]
        params = rows[:, :4]
        if n_active < rows.shape[0]:
            h = rows[n_active]
            doc["hand"] = {f: _clean(h[k] * (to_file if f in _ANGLES else 1.0))
                           for k, f in enumerate(fields)}
        params = params[:n_active]
    else:
        params = np.asarray(model.parameters)
        if not np.array_equal(model.base, np.eye(4)):
            doc["base"] = [[_clean(v) for v in r] for r in model.base]
        if not np.array_equal(model.tool, np.eye(4)):
            doc["tool"] = [[_clean(v) for v in r] for r in model.tool]
        if np.any(model.q_home != 0):
            doc["q_home"] = [_clean(v if j.kind == "prismatic" else v * to_file)
                             for v, j in zip(model.q_home, model.joints, strict=True)]
    for jt, row in zip(model.joints, params, strict=True):
        entry: dict = {"name": jt.name, "type": jt.kind}
        for k, f in enumerate(fields):
            entry[f] = _clean(row[k] * (to_file if f in _ANGLES else 1.0))
        if jt.kind == "screw":
            entry["pitch"] = _clean(jt.pitch)
        if math.isfinite(jt.lower) or math.isfinite(jt.upper):
            s = 1.0 if jt.kind == "prismatic" else to_file
            entry["limits"] = [jt.lower * s, jt.upper * s]  # TOML has inf
        joints.append(entry)
    doc["joints"] = joints
    return tomli_w.dumps(doc)


def write_model(model: ChainModel, path: str | os.PathLike, angle_unit: str = "deg") -> None:
    """Write a model as TOML, atomically (a temporary file renamed into place)."""
    write_text_atomic(path, dumps_model(model, angle_unit=angle_unit), "model file")
