"""TOML platform files: read, write, round trip.

Two forms. Units are explicit and required: ``length_unit`` (mm, cm, m, in) and ``force_unit``
(N, kN, lbf); spring constants are in force_unit per length_unit; angles in degrees (named so).

Design form — a special 6-6 (Griffis–Duffy) platform from its design parameters
(:func:`kinestat.parallel.platform.special_6_6`); the geometry, home pose and free lengths are
derived::

    name = "vibhute-2011-prototype"
    description = "..."                 # optional
    length_unit = "mm"
    force_unit = "N"
    leg_names = ["O", "P", "Q", "R", "S", "T"]   # optional (this is the default)

    [design]
    kind = "special-6-6"
    base_side = 120.0          # |O0P0| = |P0Q0| = |Q0O0|; or three numbers
    top_side = 60.0            # |R1S1|, |S1T1|, |T1R1|; a number or three
    base_offset = 28.0         # |O0S0|, |P0T0|, |Q0R0|; a number or three
    top_offset = 14.0          # |R1O1|, |S1P1|, |T1Q1|; a number or three
    home_height = 60.0         # top plane above the base plane at home
    home_twist_deg = -60.0     # top frame turned about the base z axis at home
    stiffness = 2.627          # a number or six (legs in leg_names order)
    free_lengths = [...]       # optional, six; default: the leg lengths at home

Explicit form — any six-leg platform::

    name = "my-platform"
    length_unit = "mm"
    force_unit = "N"
    home_pose = [[1, 0, 0, 30], [0, 1, 0, 51.96], [0, 0, 1, 60], [0, 0, 0, 1]]

    [[legs]]                   # six of these
    name = "O"
    base = [0.0, 0.0, 0.0]     # base frame
    top = [14.0, 0.0, 0.0]     # top frame
    stiffness = 2.627
    free_length = 80.969       # optional; default: the leg length at home_pose

A file holds exactly one of ``[design]`` and ``[[legs]]``.

Either form may say how the platform is bolted on the robot's flange (frame 6), an optional
``[mount]`` table (:func:`read_platform_mount`; ``kinestat control --platform``/``--mount``)::

    [mount]
    offset = 12.5              # the base plane along S6 from the flange face (length_unit)
    turn_deg = 30.0            # the base x axis turned from a67 about S6

with the base triangle's centroid on S6 (the centred mount), or the whole ``6_BT``::

    [mount]
    pose = [[1, 0, 0, -60], [0, 1, 0, -34.64], [0, 0, 1, 0], [0, 0, 0, 1]]
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import tomli_w

from kinestat.errors import InputError, ModelError, ParseError
from kinestat.io._fields import matrix, number, numbers, refuse_unknown, string, unit
from kinestat.io.textfile import parse_toml, read_text_file, write_text_atomic
from kinestat.parallel.platform import LEG_NAMES, Platform, special_6_6
from kinestat.parallel.singularity import check_design
from kinestat.spatial.transforms import apply

__all__ = ["LENGTH_UNITS", "FORCE_UNITS", "PlatformMount", "loads_platform", "read_platform",
           "read_platform_mount", "read_mount_file", "dumps_platform", "write_platform"]

LENGTH_UNITS = ("mm", "cm", "m", "in")
FORCE_UNITS = ("N", "kN", "lbf")

_TOP_KEYS = {"name", "description", "source", "length_unit", "force_unit", "leg_names",
             "design", "legs", "home_pose", "mount"}
_MOUNT_KEYS = {"offset", "turn_deg", "pose"}
_DESIGN_KEYS = {"kind", "base_side", "top_side", "base_offset", "top_offset", "home_height",
                "home_twist_deg", "stiffness", "free_lengths"}
_LEG_KEYS = {"name", "base", "top", "stiffness", "free_length"}


def _unit(doc: dict, key: str, allowed: tuple[str, ...], source: str) -> str:
    return unit(doc, key, source, f"{key} = {allowed[0]!r} (one of {list(allowed)})", allowed)


def loads_platform(text: str, source: str = "<string>") -> Platform:
    """Parse a TOML platform from text (``source`` names it in error messages)."""
    return _from_doc(parse_toml(text, source), source)


def read_platform(path: str | os.PathLike) -> Platform:
    """Read a TOML platform file."""
    return loads_platform(read_text_file(path, "platform file"), source=str(Path(path)))


@dataclass(frozen=True, eq=False)
class PlatformMount:
    """A platform file's ``[mount]``: the whole ``6_BT`` (``pose``, 4x4) or, when ``pose`` is
    None, the centred mount shifted by ``offset`` along S6 and turned by ``turn_deg`` about it
    (:func:`kinestat.sim.contact.centred_mount`)."""

    pose: np.ndarray | None = None
    offset: float = 0.0
    turn_deg: float = 0.0


def read_platform_mount(path: str | os.PathLike) -> tuple[Platform, PlatformMount | None]:
    """The platform of a TOML platform file and its ``[mount]`` table (None when it has none)."""
    source = str(Path(path))
    doc = parse_toml(read_text_file(path, "platform file"), source)
    return _from_doc(doc, source), _mount(doc.get("mount"), source)


def read_mount_file(path: str | os.PathLike) -> tuple[Platform | None, PlatformMount]:
    """A mount from a TOML file: a platform file's ``[mount]`` table (with its platform), or a
    pose file's ``pose = [[…] ×4]`` (``6_BT``; no platform)."""
    source = str(Path(path))
    doc = parse_toml(read_text_file(path, "mount file"), source)
    if "pose" in doc and not {"design", "legs"} & set(doc):
        return None, PlatformMount(pose=matrix(doc["pose"], source, "pose", (4, 4)))
    plat, mount = _from_doc(doc, source), _mount(doc.get("mount"), source)
    if mount is None:
        raise ParseError("the platform file has no [mount] table (offset, turn_deg or pose) "
                         "to take the mount from", file=source)
    return plat, mount


def _mount(table, source: str) -> PlatformMount | None:
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ParseError("[mount] must be a table", file=source, card="mount")
    refuse_unknown(table, _MOUNT_KEYS, source, "keys in [mount]", card="mount")
    if "pose" in table:
        if {"offset", "turn_deg"} & set(table):
            raise ParseError("give either pose or offset/turn_deg, not both", file=source,
                             card="mount")
        return PlatformMount(pose=matrix(table["pose"], source, "mount.pose", (4, 4)))
    return PlatformMount(offset=number(table.get("offset", 0.0), source, "mount.offset"),
                         turn_deg=number(table.get("turn_deg", 0.0), source, "mount.turn_deg"))


def _from_doc(doc: dict, source: str) -> Platform:
    refuse_unknown(doc, _TOP_KEYS, source, "top-level keys")
    _mount(doc.get("mount"), source)  # checked with the file, wherever it is read
    name = string(doc.get("name", Path(source).stem), source, "name")
    lu = _unit(doc, "length_unit", LENGTH_UNITS, source)
    fu = _unit(doc, "force_unit", FORCE_UNITS, source)
    has_design, has_legs = "design" in doc, "legs" in doc
    if has_design == has_legs:
        raise ParseError("a platform file needs exactly one of a [design] table and six "
                         "[[legs]] tables", file=source)
    try:
        if has_design:
            return _design(doc, source, name, lu, fu)
        return _explicit(doc, source, name, lu, fu)
    except ParseError:
        raise
    except (InputError, ModelError) as exc:
        raise ParseError(str(exc), file=source) from exc


def _design(doc: dict, source: str, name: str, lu: str, fu: str) -> Platform:
    d = doc["design"]
    if not isinstance(d, dict):
        raise ParseError("[design] must be a table", file=source, card="design")
    refuse_unknown(d, _DESIGN_KEYS, source, "keys in [design]", card="design")
    kind = d.get("kind", "special-6-6")
    if kind != "special-6-6":
        raise ParseError(f"unknown design kind {kind!r}; only 'special-6-6' is known",
                         file=source, card="design", field="kind")
    required = ("base_side", "top_side", "base_offset", "top_offset", "home_height",
                "stiffness")
    for key in required:
        if key not in d:
            raise ParseError(f"missing {key!r}", file=source, card="design", field=key)

    def f(key, n):
        return numbers(d[key], n, source, f"design.{key}")

    names = doc.get("leg_names", list(LEG_NAMES))
    if (not isinstance(names, list) or len(names) != 6
            or not all(isinstance(x, str) for x in names)):
        raise ParseError(f"leg_names must be six strings, got {names!r}", file=source,
                         field="leg_names")
    free = None
    if "free_lengths" in d:
        free = numbers(d["free_lengths"], 6, source, "design.free_lengths", scalar_ok=False)
    twist = number(d.get("home_twist_deg", -60.0), source, "design.home_twist_deg")
    return special_6_6(
        base_side=f("base_side", 3), top_side=f("top_side", 3),
        base_offset=f("base_offset", 3), top_offset=f("top_offset", 3),
        height=number(d["home_height"], source, "design.home_height"),
        twist=math.radians(twist), stiffness=f("stiffness", 6), free_lengths=free,
        name=name, length_unit=lu, force_unit=fu, leg_names=tuple(names))


def _explicit(doc: dict, source: str, name: str, lu: str, fu: str) -> Platform:
    legs = doc["legs"]
    if not isinstance(legs, list) or len(legs) != 6:
        raise ParseError(f"need exactly six [[legs]] tables, got "
                         f"{len(legs) if isinstance(legs, list) else legs!r}", file=source,
                         card="legs")
    if "home_pose" not in doc:
        raise ParseError("missing 'home_pose' (4x4) for an explicit platform", file=source,
                         field="home_pose")
    home = matrix(doc["home_pose"], source, "home_pose", (4, 4))
    names, base, top, k, l0 = [], [], [], [], []
    for i, leg in enumerate(legs):
        card = f"legs[{i}]"
        if not isinstance(leg, dict):
            raise ParseError("each [[legs]] entry must be a table", file=source, card=card)
        refuse_unknown(leg, _LEG_KEYS, source, card=card)
        for key in ("name", "base", "top", "stiffness"):
            if key not in leg:
                raise ParseError(f"missing {key!r}", file=source, card=card, field=key)
        names.append(string(leg["name"], source, f"{card}.name"))
        base.append(numbers(leg["base"], 3, source, f"{card}.base", scalar_ok=False))
        top.append(numbers(leg["top"], 3, source, f"{card}.top", scalar_ok=False))
        k.append(number(leg["stiffness"], source, f"{card}.stiffness"))
        l0.append(number(leg["free_length"], source, f"{card}.free_length")
                  if "free_length" in leg else None)
    base_a, top_a = np.array(base), np.array(top)
    home_l = np.linalg.norm(apply(home, top_a) - base_a, axis=-1)
    free = np.array([h if x is None else x for x, h in zip(l0, home_l, strict=True)])
    plat = Platform(base_points=base_a, top_points=top_a, stiffness=np.array(k),
                    free_lengths=free, home_pose=home, leg_names=tuple(names), name=name,
                    length_unit=lu, force_unit=fu)
    check_design(plat)
    return plat


def dumps_platform(platform: Platform, description: str | None = None) -> str:
    """TOML text of a platform: the design form if it has design parameters, else explicit."""
    doc: dict = {"name": platform.name}
    if description:
        doc["description"] = description
    doc["length_unit"] = platform.length_unit
    doc["force_unit"] = platform.force_unit
    d = platform.design
    if d is not None:
        if platform.leg_names != LEG_NAMES:
            doc["leg_names"] = list(platform.leg_names)

        def one(v):
            v = list(v)
            return v[0] if all(x == v[0] for x in v) else v

        design = {
            "kind": "special-6-6",
            "base_side": one(d.base_side),
            "top_side": one(d.top_side),
            "base_offset": one(d.base_offset),
            "top_offset": one(d.top_offset),
            "home_height": d.height,
            "home_twist_deg": round(math.degrees(d.twist), 12),
            "stiffness": one(d.stiffness),
        }
        if d.free_lengths is not None:
            design["free_lengths"] = list(d.free_lengths)
        doc["design"] = design
    else:
        doc["home_pose"] = platform.home_pose.tolist()
        doc["legs"] = [
            {"name": n, "base": b.tolist(), "top": t.tolist(), "stiffness": float(k),
             "free_length": float(l0)}
            for n, b, t, k, l0 in zip(platform.leg_names, platform.base_points,
                                      platform.top_points, platform.stiffness,
                                      platform.free_lengths, strict=True)
        ]
    return tomli_w.dumps(doc)


def write_platform(platform: Platform, path: str | os.PathLike,
                   description: str | None = None) -> None:
    """Write a platform to a TOML file (atomically: a temporary file renamed into place)."""
    write_text_atomic(path, dumps_platform(platform, description), "platform file")
