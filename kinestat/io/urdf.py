"""URDF import and export for serial chains.

Export writes the chain ``C0 · Z(q1) · C1 · … · Z(qn) · Cn`` as links ``base`` → ``link1`` … →
``link<n>`` → ``tool``: joint i has origin ``C_{i-1}`` and axis +z; a fixed joint carries ``Cn``.
Import follows the chain from the root link to a tip link; a joint whose axis is not +z is
rotated onto z (``A`` with ``A·z = axis``) so that the model stays in kinestat's canonical form.
Units: URDF lengths are metres and angles radians, by the format. Export converts the model's
lengths to metres from its ``length_unit`` (mm, cm, m, in, ft; another unit is refused unless
``scale`` is given). Import gives metres, or the ``length_unit`` asked for (converted); ``scale``
multiplies the file's numbers instead (a file written in millimetres: ``scale=1e-3``). A file
whose joint offsets look like millimetres (one longer than 10 m) raises a
:class:`~kinestat.errors.KinestatWarning` when no ``scale`` is given.
A moving joint with a ``<mimic>`` on the chain is refused (kinestat has no coupled joints; on a
fixed joint a ``<mimic>`` couples nothing and is ignored, as Pinocchio does); so are floating
and planar joints (no single axis). Screw joints have no URDF form and are refused on export.
"""

from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from kinestat.errors import InputError, KinestatWarning, ModelError, ParseError
from kinestat.io.textfile import read_text_file
from kinestat.mechanism.chain import ChainModel
from kinestat.mechanism.joints import Joint

__all__ = ["to_urdf", "from_urdf", "read_urdf", "parse_robot_xml", "METRES_PER_UNIT",
           "metres_per_unit"]

#: metres in one unit of each length unit a model may use
METRES_PER_UNIT = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "in": 0.0254, "ft": 0.3048}

#: a joint offset longer than this (file numbers, metres by the format) looks like millimetres
_MM_SUSPECT = 10.0


def metres_per_unit(unit: str, what: str = "length unit") -> float:
    """Metres in one ``unit`` (mm, cm, m, in, ft); another unit is an InputError.

    >>> metres_per_unit("mm"), metres_per_unit("in")
    (0.001, 0.0254)
    """
    try:
        return METRES_PER_UNIT[unit]
    except KeyError:
        raise InputError(f"{what} {unit!r} cannot be converted to metres: kinestat knows "
                         f"{', '.join(METRES_PER_UNIT)}; give scale= (--scale) "
                         "explicitly") from None


def _origin(T: np.ndarray, scale: float) -> str:
    from scipy.spatial.transform import Rotation  # lazy: start-up (scipy.spatial ~0.5 s)

    xyz = " ".join(f"{v * scale:.17g}" for v in T[:3, 3])
    with warnings.catch_warnings():  # gimbal lock is harmless: any valid rpy reproduces R
        warnings.simplefilter("ignore", UserWarning)
        rpy_v = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")
    rpy = " ".join(f"{v:.17g}" for v in rpy_v)
    return f'<origin xyz="{xyz}" rpy="{rpy}"/>'


def to_urdf(model: ChainModel, *, scale: float | None = None, name: str | None = None) -> str:
    """URDF text of a serial chain, lengths in metres: converted from ``model.length_unit``
    (mm, cm, m, in, ft), or multiplied by ``scale`` when it is given (for any other unit).

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> arm = from_standard_dh([[0.0, 0.0, 650.0, 0.0]], length_unit="mm")
    >>> import re
    >>> tool = re.search(r'"tool_fixed".*?xyz="([^"]+)"', to_urdf(arm)).group(1)
    >>> [round(float(v), 12) for v in tool.split()]
    [0.65, 0.0, 0.0]
    """
    if any(j.kind == "screw" for j in model.joints):
        raise ModelError(f"model {model.name!r} has a screw joint, which URDF cannot express")
    if scale is None:
        scale = metres_per_unit(model.length_unit, f"model {model.name!r}: length unit")
    lines = [f'<robot name="{name or model.name}">', '  <link name="base"/>']
    C = model.constants
    for i, j in enumerate(model.joints, start=1):
        lines.append(f'  <link name="link{i}"/>')
        lo, hi = j.lower, j.upper
        if j.kind == "revolute" and not (math.isfinite(lo) and math.isfinite(hi)):
            jtype, limit = "continuous", ""
        else:
            s = scale if j.kind == "prismatic" else 1.0
            lo = lo * s if math.isfinite(lo) else -1e9
            hi = hi * s if math.isfinite(hi) else 1e9
            jtype = j.kind
            limit = f'<limit lower="{lo:.17g}" upper="{hi:.17g}" effort="0" velocity="0"/>'
        parent = "base" if i == 1 else f"link{i - 1}"
        lines.append(
            f'  <joint name="{j.name or i}" type="{jtype}"><parent link="{parent}"/>'
            f'<child link="link{i}"/>{_origin(C[i - 1], scale)}<axis xyz="0 0 1"/>{limit}</joint>'
        )
    lines.append('  <link name="tool"/>')
    lines.append(
        f'  <joint name="tool_fixed" type="fixed"><parent link="link{model.n}"/>'
        f'<child link="tool"/>{_origin(C[model.n], scale)}</joint>'
    )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def _floats(text: str | None, n: int, where: str, source: str) -> np.ndarray:
    if text is None:
        return np.zeros(n)
    try:
        v = np.array([float(x) for x in text.split()])
    except ValueError as exc:
        raise ParseError(f"cannot read numbers from {text!r}", file=source, field=where) from exc
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise ParseError(f"expected {n} finite numbers, got {text!r}", file=source, field=where)
    return v


def _limit(text: str | None, default: float, where: str, source: str) -> float:
    """A joint limit attribute (absent: ``default``); not a number is a ParseError."""
    if text is None:
        return default
    try:
        v = float(text)
    except ValueError:
        raise ParseError(f"cannot read a number from {text[:40]!r}", file=source,
                         field=where) from None
    if math.isnan(v):
        raise ParseError("a limit cannot be NaN", file=source, field=where)
    return v


def _check_joint(j: ET.Element, where: str, source: str) -> None:
    """A joint kinestat can put on a serial chain, or a ParseError naming it and why not."""
    jtype = j.get("type")
    if jtype in ("floating", "planar"):
        dof = "6 degrees of freedom" if jtype == "floating" else "3 degrees of freedom"
        raise ParseError(f"{where} is {jtype} ({dof}, no single axis): a serial chain has "
                         "revolute, continuous, prismatic and fixed joints only; start the "
                         "chain below it (base=, --base)", file=source)
    if jtype not in ("revolute", "continuous", "prismatic", "fixed"):
        raise ParseError(f"{where}: joint type {jtype!r} is not supported in a serial chain",
                         file=source)
    mimic = j.find("mimic")
    if mimic is not None and jtype != "fixed":  # a fixed joint has no value to couple
        raise ParseError(f"{where} mimics joint {mimic.get('joint')!r} (<mimic>): kinestat "
                         "models independent joints only, so coupled joints are refused; end "
                         "the chain before it (tip=, --tip)", file=source)


def parse_robot_xml(text: str, source: str) -> ET.Element:
    """The ``<robot>`` element of ``text``, its tags without XML namespaces: a file that
    declares a default namespace (``<robot xmlns="...">``) names its elements ``{ns}joint``, and
    URDF readers go by the local names."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ParseError(f"not valid XML: {exc}", file=source) from exc
    for el in root.iter():
        if isinstance(el.tag, str) and el.tag.startswith("{"):
            el.tag = el.tag.rsplit("}", 1)[1]
    if root.tag != "robot":
        raise ParseError(f"the root element must be <robot>, not <{root.tag}>", file=source)
    return root


def _declared_links(root: ET.Element, source: str) -> set[str]:
    """The names of the ``<link>`` elements; a link without a name or declared twice is a
    ParseError naming it (the tree would be ambiguous)."""
    links: set[str] = set()
    for lk in root.findall("link"):
        name = lk.get("name")
        if name is None:
            raise ParseError("a <link> has no name attribute", file=source)
        if name in links:
            raise ParseError(f"link {name!r} is declared twice (<link name={name!r}>); link "
                             "names must be unique", file=source)
        links.add(name)
    return links


def _leaves_below(start: str, children: dict[str, list[str]]) -> list[str]:
    """Leaf links below ``start`` (itself if it has no child), depth first, linear time."""
    leaves, stack, seen = [], [start], set()
    while stack:
        link = stack.pop()
        if link in seen:
            continue
        seen.add(link)
        kids = children.get(link, [])
        if not kids:
            leaves.append(link)
        stack.extend(reversed(kids))
    return leaves


def _path_to_tip(root: ET.Element, tip: str | None, source: str,
                 base: str | None = None) -> list[ET.Element]:
    """The joints from ``base`` (default: the root link) to ``tip`` (default: the only leaf
    below ``base`` that a moving joint leads to), base first.

    Linear in the number of joints. A link that is the child of two joints, or a cycle of
    joints, is a ParseError naming the joint.
    """
    joint_to: dict[str, ET.Element] = {}  # child link -> the joint leading to it
    parents_of: dict[str, str | None] = {}  # child link -> its parent link
    link_set = _declared_links(root, source)
    names: set[str | None] = set()
    for j in root.findall("joint"):
        parent, child = j.find("parent"), j.find("child")
        if j.get("name") is None:
            raise ParseError("a <joint> has no name attribute", file=source)
        if parent is None or child is None:
            raise ParseError(f"joint {j.get('name')!r} lacks a parent or child", file=source)
        if j.get("name") in names:
            raise ParseError(f"joint {j.get('name')!r} is declared twice; joint names must be "
                             "unique", file=source)
        names.add(j.get("name"))
        for role, el in (("parent", parent), ("child", child)):
            if el.get("link") not in link_set:
                raise ParseError(f"joint {j.get('name')!r}: its {role} link "
                                 f"{el.get('link')!r} is not declared (no <link "
                                 f"name={el.get('link')!r}>)", file=source)
        c = child.get("link")
        if c in joint_to:
            raise ParseError(f"joint {j.get('name')!r}: link {c!r} is already the child of "
                             f"joint {joint_to[c].get('name')!r} (a serial chain is a tree)",
                             file=source)
        joint_to[c] = j
        parents_of[c] = parent.get("link")
    links = [lk.get("name") for lk in root.findall("link")]
    if base is None:
        roots = [lk for lk in links if lk not in joint_to]
        if len(roots) != 1:
            raise ParseError(f"expected one root link, found {roots[:10]}", file=source)
        base = roots[0]
    elif base not in link_set:
        raise ParseError(f"no link named {base!r} (base)", file=source)
    if tip is None:
        tip = _only_leaf(base, joint_to, parents_of, source)
    if tip not in link_set:
        raise ParseError(f"no link named {tip!r} (tip)", file=source)
    path: list[ET.Element] = []
    seen: set[str] = set()
    link = tip
    while link != base:
        if link not in joint_to:
            raise ParseError(f"link {tip!r} (tip) is not below link {base!r} (base)",
                             file=source)
        if link in seen:
            raise ParseError(f"joint {joint_to[link].get('name')!r} closes a cycle of joints "
                             f"through link {link!r}; a serial chain has none", file=source)
        seen.add(link)
        path.append(joint_to[link])
        link = parents_of[link]
    path.reverse()
    return path


def _only_leaf(base: str, joint_to: dict, parents_of: dict, source: str) -> str:
    """The one leaf link below ``base`` reached through at least one moving joint; several
    (or none) is a ParseError listing them."""
    children: dict[str, list[str]] = {}
    for child, parent in parents_of.items():
        children.setdefault(parent, []).append(child)
    leaves = _leaves_below(base, children)

    def moves(leaf: str) -> bool:
        link = leaf
        while link != base and link in joint_to:
            if joint_to[link].get("type") != "fixed":
                return True
            link = parents_of[link]
        return False

    chains = [lk for lk in leaves if moves(lk)]
    if len(chains) != 1:
        raise ParseError(f"{len(chains)} chains below link {base!r}, ending at "
                         f"{chains[:10] or leaves[:10]}: choose the end link with tip= (--tip)",
                         file=source)
    return chains[0]


def _pose(xyz: np.ndarray, rpy: np.ndarray) -> np.ndarray:
    """The URDF origin ``xyz``/``rpy`` as a 4x4 pose: R = Rz(yaw) Ry(pitch) Rx(roll).

    Written out (not scipy's Rotation): it runs once per joint, and a chain may have thousands.
    """
    cr, sr = math.cos(rpy[0]), math.sin(rpy[0])
    cp, sp = math.cos(rpy[1]), math.sin(rpy[1])
    cy, sy = math.cos(rpy[2]), math.sin(rpy[2])
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr, xyz[0]],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr, xyz[1]],
        [-sp, cp * sr, cp * cr, xyz[2]],
        [0.0, 0.0, 0.0, 1.0],
    ])


def _align_z(axis: np.ndarray) -> np.ndarray:
    """A rotation (4x4) taking +z onto ``axis`` (unit): about z x axis by the angle between
    them (Rodrigues: R = I + [v] + [v]^2 (1 - c)/s^2, v = z x axis, s = |v|, c = z . axis)."""
    T = np.eye(4)
    vx, vy, c = -float(axis[1]), float(axis[0]), float(axis[2])
    s2 = vx * vx + vy * vy
    if s2 < 1e-30:
        if c < 0:
            T[:3, :3] = np.diag([1.0, -1.0, -1.0])
        return T
    k = (1.0 - c) / s2
    # [v] = [[0, 0, vy], [0, 0, -vx], [-vy, vx, 0]] for v = (vx, vy, 0)
    T[:3, :3] = [[1.0 - k * vy * vy, k * vx * vy, vy],
                 [k * vx * vy, 1.0 - k * vx * vx, -vx],
                 [-vy, vx, 1.0 - k * s2]]
    return T


def from_urdf(
    text: str,
    *,
    tip: str | None = None,
    base: str | None = None,
    scale: float | None = None,
    name: str | None = None,
    length_unit: str | None = None,
    source: str = "<urdf>",
) -> ChainModel:
    """Serial chain from URDF text, from link ``base`` (default: the root link) to link ``tip``
    (default: the only leaf below ``base`` reached through a moving joint).

    Units: the model's lengths are in ``length_unit`` (default ``"m"``, URDF's own unit),
    converted from metres; or the file's numbers times ``scale`` when it is given (a file
    written in millimetres: ``scale=1e-3``; the model's unit is then ``length_unit`` or "m").
    Without ``scale``, a joint offset longer than 10 (file numbers) warns that the file looks
    like millimetres. Angles are radians. A moving joint with a ``<mimic>``, a floating or a
    planar joint on the chain is a ParseError naming it; ``scale`` must be finite and > 0.
    """
    explicit_scale = scale is not None
    if explicit_scale and not (isinstance(scale, (int, float)) and not isinstance(scale, bool)
                               and math.isfinite(scale) and scale > 0):
        raise InputError(f"scale (--scale) must be a finite number > 0, got {scale!r}: zero "
                         "collapses every length and a negative one mirrors the arm")
    if scale is None:
        scale = 1.0 / metres_per_unit(length_unit or "m")
    length_unit = length_unit or "m"
    root = parse_robot_xml(text, source)
    path = _path_to_tip(root, tip, source, base)
    consts = [np.eye(4)]
    kinds: list[Joint] = []
    longest = (0.0, "")
    for j in path:
        where = f"joint {j.get('name')!r}"
        _check_joint(j, where, source)
        o = j.find("origin")
        xyz = _floats(o.get("xyz") if o is not None else None, 3, where + " origin xyz", source)
        rpy = _floats(o.get("rpy") if o is not None else None, 3, where + " origin rpy", source)
        if float(np.abs(xyz).max()) > longest[0]:
            longest = (float(np.abs(xyz).max()), str(j.get("name")))
        with np.errstate(over="ignore", invalid="ignore"):
            xyz = xyz * scale
        if not np.all(np.isfinite(xyz)):
            raise ParseError(f"origin xyz times scale {scale:g} is not finite", file=source,
                             field=where + " origin xyz")
        Tj = _pose(xyz, rpy)
        jtype = j.get("type")
        if jtype == "fixed":
            consts[-1] = consts[-1] @ Tj
            continue
        ax = j.find("axis")
        axis = _floats(ax.get("xyz") if ax is not None else "1 0 0", 3, where + " axis", source)
        nrm = np.linalg.norm(axis)
        if nrm < 1e-12:  # an <axis> without xyz is zero too (urdfdom's reading)
            said = f"xyz={ax.get('xyz')!r}" if ax.get("xyz") else "<axis> without xyz"
            raise ParseError(f"{where}: the joint axis is zero ({said}); give "
                             "<axis xyz=\"...\"/> a direction, or drop <axis> for URDF's "
                             "default 1 0 0", file=source)
        A = _align_z(axis / nrm)
        consts[-1] = consts[-1] @ Tj @ A
        consts.append(A.T.copy())  # the inverse of a rotation
        lim = j.find("limit")
        lo, hi = -math.inf, math.inf
        if lim is not None and jtype != "continuous":
            s = scale if jtype == "prismatic" else 1.0
            lo = _limit(lim.get("lower"), -math.inf, where + " limit lower", source) * s
            hi = _limit(lim.get("upper"), math.inf, where + " limit upper", source) * s
        try:
            kinds.append(Joint(kind="prismatic" if jtype == "prismatic" else "revolute",
                               lower=lo, upper=hi, name=str(j.get("name"))))
        except InputError as exc:  # limits that are not an interval
            raise ParseError(str(exc), file=source, field=where + " limit") from exc
    if not kinds:
        raise ModelError(f"{source}: no moving joint between {base or 'the root'!r} and {tip!r}")
    if not explicit_scale and longest[0] > _MM_SUSPECT:
        warnings.warn(f"{source}: lengths look like millimetres (joint {longest[1]!r} is "
                      f"{longest[0]:g} from its parent link, URDF lengths are metres); if the "
                      "file is in millimetres load it with scale=0.001 (--scale 0.001)",
                      KinestatWarning, stacklevel=2)
    try:
        return ChainModel(name=name or str(root.get("name", "urdf")), joints=tuple(kinds),
                          constants=np.array(consts), length_unit=length_unit)
    except InputError as exc:  # e.g. limits that are not an interval
        raise ParseError(str(exc), file=source) from exc


def read_urdf(path: str | os.PathLike, **kwargs) -> ChainModel:
    """Read a URDF file (see :func:`from_urdf`)."""
    p = Path(path)
    text = read_text_file(p, "URDF file")
    return from_urdf(text, source=str(p), **kwargs)
