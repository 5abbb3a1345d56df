"""Axes files: the joint axes of an arm in the world frame, input of ``dh-from-axes``.

The file (TOML, or JSON with the same structure) lists the joint axes in one configuration of
the arm::

    name = "my-arm"              # optional (default: the file name)
    length_unit = "mm"           # required
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

import os
from pathlib import Path

import numpy as np

from kinestat.errors import ParseError
from kinestat.io._fields import joint_type_and_pitch, matrix, number, numbers, refuse_unknown, unit
from kinestat.io.textfile import parse_json, parse_toml, read_text_file

__all__ = ["loads_axes", "read_axes_file"]

_TOP_KEYS = {"name", "length_unit", "description", "tol", "tool", "base", "axes"}
_AXIS_KEYS = {"name", "type", "point", "direction", "plucker", "pitch"}


def _plucker_line(ax: dict, source: str, where: str) -> list[float]:
    """The six Plücker coordinates [S; S0] of an axis given as ``plucker``, checked."""
    if "point" in ax or "direction" in ax:
        raise ParseError("give either plucker or point and direction, not both", file=source,
                         field=where)
    pl = numbers(ax["plucker"], 6, source, f"{where}.plucker", scalar_ok=False)
    S, S0 = np.array(pl[:3]), np.array(pl[3:])
    nS = float(np.linalg.norm(S))
    if nS == 0.0:
        raise ParseError("the direction S (first three numbers) is the zero vector; give the "
                         "axis direction", file=source, field=f"{where}.plucker")
    # the same test as kinestat.mechanism.dh_from_axes applies
    if abs(float(S @ S0)) > 1e-6 * nS * max(float(np.linalg.norm(S0)), nS):
        raise ParseError("not a line: Plücker coordinates [S; S0] need S . S0 = 0 (S0 = r x S "
                         "for a point r on the line)", file=source, field=f"{where}.plucker")
    return pl


def _point_direction(ax: dict, source: str, where: str) -> list[list[float]]:
    """[point, direction] of an axis given by a point and a direction, checked."""
    for k in ("point", "direction"):
        if k not in ax:
            raise ParseError(f"missing '{k}' (or give 'plucker')", file=source,
                             field=f"{where}.{k}")
    p = numbers(ax["point"], 3, source, f"{where}.point", scalar_ok=False)
    s = numbers(ax["direction"], 3, source, f"{where}.direction", scalar_ok=False)
    if not any(s):
        raise ParseError("the direction is the zero vector; give the axis direction",
                         file=source, field=f"{where}.direction")
    return [p, s]


def loads_axes(doc: dict, source: str = "<string>") -> dict:
    """Check a parsed axes document; returns keyword arguments for
    :func:`kinestat.mechanism.dh_from_axes.dh_from_axes` plus the joint ``kinds`` and ``axes``
    (``(n, 2, 3)`` point and direction, or ``(n, 6)`` Plücker coordinates).

    >>> spec = loads_axes({"length_unit": "mm",
    ...                    "axes": [{"point": [0, 0, 0], "direction": [0, 0, 1]},
    ...                             {"point": [0, 0, 0], "direction": [1, 0, 0]}]})
    >>> spec["axes"].shape, spec["kinds"], spec["names"]
    ((2, 2, 3), ['revolute', 'revolute'], ['1', '2'])
    """
    if not isinstance(doc, dict):
        raise ParseError("expected a table/object at the top level", file=source)
    refuse_unknown(doc, _TOP_KEYS, source, "top-level keys")
    axes = doc.get("axes")
    if not isinstance(axes, list) or not axes:
        raise ParseError("expected at least one [[axes]] entry (a point and a direction each)",
                         file=source, field="axes")
    lines, kinds, pitches, names, forms = [], [], [], [], set()
    for i, ax in enumerate(axes, start=1):
        where = f"axes[{i}]"
        if not isinstance(ax, dict):
            raise ParseError("each axis must be a table", file=source, field=where)
        refuse_unknown(ax, _AXIS_KEYS, source, field=where)
        kind, pitch = joint_type_and_pitch(ax, source, where)
        if "plucker" in ax:
            lines.append(_plucker_line(ax, source, where))
            forms.add("plucker")
        else:
            lines.append(_point_direction(ax, source, where))
            forms.add("point")
        kinds.append(kind)
        pitches.append(pitch)
        names.append(str(ax.get("name", i)))
    if len(forms) > 1:  # mixed forms: write every axis in Plücker coordinates [s; p x s]
        lines = [ln if len(ln) == 6 else [*ln[1], *np.cross(ln[0], ln[1])] for ln in lines]
    out: dict = {"axes": np.array(lines, dtype=float), "kinds": kinds, "pitches": pitches,
                 "names": names, "name": str(doc.get("name", Path(source).stem)),
                 "length_unit": unit(doc, "length_unit", source,
                                    'length_unit = "mm" (the unit of the points)'),
                 "description": str(doc.get("description", ""))}
    for k in ("tool", "base"):
        if k in doc:
            out[k] = matrix(doc[k], source, k, (4, 4))
    if "tol" in doc:
        tol = number(doc["tol"], source, "tol")
        if tol < 0:
            raise ParseError(f"tol must be a finite non-negative number, got {tol!r}",
                             file=source, field="tol")
        out["tol"] = tol
    return out


def read_axes_file(path: str | os.PathLike) -> dict:
    """Read an axes file (``.json`` as JSON, anything else as TOML); see the module docstring."""
    p = Path(path)
    text = read_text_file(p, "axes file")
    parse = parse_json if p.suffix.lower() == ".json" else parse_toml
    doc = parse(text, str(p))
    return loads_axes(doc, source=str(p))
