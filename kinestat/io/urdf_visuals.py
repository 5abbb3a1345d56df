"""The visual meshes of a URDF file and where each one sits.

Each ``<link><visual>`` with a ``<mesh filename=…>`` (STL, DAE or OBJ) becomes a
:class:`Visual`: the link, its pose at the URDF's zero configuration (the product of the joint
origins from the root, metres by the format), the visual's own origin, the mesh scale and the
mesh file resolved on this machine. File names are resolved as ROS does:

- ``package://PKG/rest``: the directory ``PKG`` found first among the URDF file's ancestors
  (a package laid out as installed: ``…/share/PKG/…/robot.urdf``), then in every entry of
  ``ROS_PACKAGE_PATH`` (``entry/PKG`` or ``entry`` itself when its name is PKG) and
  ``AMENT_PREFIX_PATH`` (``entry/share/PKG``);
- ``file://ABS`` and absolute paths as they are;
- a relative path: relative to the URDF file's directory.

A file not found keeps ``path = None`` and a ``missing`` sentence naming the link and the name.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinestat.io.textfile import read_text_file
from kinestat.io.urdf import parse_robot_xml

__all__ = ["Visual", "MESH_FORMATS", "read_visuals", "resolve_mesh", "link_poses"]

#: mesh file suffixes the viewer draws, and the loader each one needs
MESH_FORMATS = {".stl": "stl", ".dae": "dae", ".obj": "obj"}


@dataclass(frozen=True)
class Visual:
    """One visual mesh of a link (lengths in metres, as the URDF)."""

    link: str
    origin: np.ndarray          # 4x4, the visual in its link's frame
    filename: str               # as written in the URDF
    path: Path | None           # resolved on this machine (None: not found)
    fmt: str | None             # "stl", "dae", "obj"; None: a format the viewer cannot draw
    scale: tuple[float, float, float]
    color: str | None           # "#rrggbb" of the visual's material, when given
    missing: str | None = None  # why it cannot be drawn


def _floats(text: str | None, default: tuple[float, ...]) -> np.ndarray:
    if text is None:
        return np.array(default, dtype=float)
    try:
        return np.array([float(x) for x in text.split()], dtype=float)
    except ValueError:
        return np.array(default, dtype=float)


def _rpy_pose(origin: ET.Element | None) -> np.ndarray:
    xyz = _floats(None if origin is None else origin.get("xyz"), (0.0, 0.0, 0.0))
    rpy = _floats(None if origin is None else origin.get("rpy"), (0.0, 0.0, 0.0))
    cr, sr, cp, sp = math.cos(rpy[0]), math.sin(rpy[0]), math.cos(rpy[1]), math.sin(rpy[1])
    cy, sy = math.cos(rpy[2]), math.sin(rpy[2])
    T = np.eye(4)
    T[:3, :3] = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                 [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                 [-sp, cp * sr, cp * cr]]
    T[:3, 3] = xyz
    return T


def _axis_motion(jtype: str, axis: np.ndarray, q: float) -> np.ndarray:
    """The motion of a joint by ``q`` about / along its unit ``axis`` (Rodrigues)."""
    T = np.eye(4)
    if jtype == "prismatic":
        T[:3, 3] = axis * q
    elif jtype in ("revolute", "continuous"):
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        T[:3, :3] = np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * (K @ K)
    return T


def link_poses(root: ET.Element, q: dict[str, float] | None = None) -> dict[str, np.ndarray]:
    """Every link's pose in the root link's frame (metres), the joints named in ``q`` moved
    by their values (the URDF's own kinematics: origin, then the motion about its axis)."""
    q = q or {}
    children: dict[str, list[ET.Element]] = {}
    has_parent = set()
    for j in root.findall("joint"):
        p, c = j.find("parent"), j.find("child")
        if p is None or c is None:
            continue
        children.setdefault(p.get("link"), []).append(j)
        has_parent.add(c.get("link"))
    poses: dict[str, np.ndarray] = {}
    stack = [(lk.get("name"), np.eye(4)) for lk in root.findall("link")
             if lk.get("name") not in has_parent]
    while stack:
        name, T = stack.pop()
        if name in poses:
            continue
        poses[name] = T
        for j in children.get(name, []):
            ax = _floats(None if j.find("axis") is None else j.find("axis").get("xyz"),
                         (1.0, 0.0, 0.0))
            n = float(np.linalg.norm(ax))
            M = _axis_motion(str(j.get("type")), ax / n if n > 0 else ax,
                             float(q.get(str(j.get("name")), 0.0)))
            stack.append((j.find("child").get("link"), T @ _rpy_pose(j.find("origin")) @ M))
    return poses


def _package_dir(pkg: str, urdf_dir: Path) -> Path | None:
    for d in (urdf_dir, *urdf_dir.parents):
        if d.name == pkg:
            return d
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry:
            e = Path(entry)
            for d in (e / pkg, e):
                if d.name == pkg and d.is_dir():
                    return d
    for entry in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if entry and (Path(entry) / "share" / pkg).is_dir():
            return Path(entry) / "share" / pkg
    return None


def resolve_mesh(filename: str, urdf_dir: Path) -> Path | None:
    """The file a URDF mesh name means on this machine, or None (see the module docstring)."""
    if filename.startswith("package://"):
        pkg, _, rest = filename[len("package://"):].partition("/")
        d = _package_dir(pkg, urdf_dir)
        p = None if d is None else d / rest
    elif filename.startswith("file://"):
        p = Path(filename[len("file://"):])
    else:
        p = Path(filename) if Path(filename).is_absolute() else urdf_dir / filename
    return p if p is not None and p.is_file() else None


def _color(visual: ET.Element, materials: dict[str, str]) -> str | None:
    mat = visual.find("material")
    if mat is None:
        return None
    c = mat.find("color")
    if c is None:
        return materials.get(str(mat.get("name")))
    rgba = _floats(c.get("rgba"), (0.5, 0.5, 0.5, 1.0))
    return "#" + "".join(f"{round(255 * min(max(x, 0.0), 1.0)):02x}" for x in rgba[:3])


def read_visuals(path: str | os.PathLike) -> tuple[list[Visual], ET.Element]:
    """The visual meshes of a URDF file (and its parsed XML root)."""
    p = Path(path)
    root = parse_robot_xml(read_text_file(p, "URDF file"), str(p))
    materials = {}
    for m in root.findall("material"):
        c = m.find("color")
        if c is not None:
            rgba = _floats(c.get("rgba"), (0.5, 0.5, 0.5, 1.0))
            materials[str(m.get("name"))] = "#" + "".join(
                f"{round(255 * min(max(x, 0.0), 1.0)):02x}" for x in rgba[:3])
    out = []
    for link in root.findall("link"):
        for vis in link.findall("visual"):
            mesh = vis.find("geometry/mesh")
            if mesh is None or not mesh.get("filename"):
                continue
            name = str(mesh.get("filename"))
            fmt = MESH_FORMATS.get(Path(name).suffix.lower())
            resolved = resolve_mesh(name, p.parent.resolve())
            s = _floats(mesh.get("scale"), (1.0, 1.0, 1.0))
            missing = None
            if fmt is None:
                missing = (f"link {link.get('name')!r}: mesh {name!r} is not STL, DAE or OBJ; "
                           "drawn as the stick figure")
            elif resolved is None:
                missing = (f"link {link.get('name')!r}: mesh {name!r} not found (package:// "
                           "is looked up above the URDF file, in ROS_PACKAGE_PATH and "
                           "AMENT_PREFIX_PATH); drawn as the stick figure")
            out.append(Visual(link=str(link.get("name")), origin=_rpy_pose(vis.find("origin")),
                              filename=name, path=resolved, fmt=fmt,
                              scale=tuple(float(x) for x in (s if s.size == 3 else [s[0]] * 3)),
                              color=_color(vis, materials), missing=missing))
    return out, root
