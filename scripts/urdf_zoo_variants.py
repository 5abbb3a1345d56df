"""Synthetic variants of real arms' URDF files for scripts/urdf_zoo_campaign.py.

Each variant is valid URDF (or, where named, a chain kinestat must refuse with one error) and
is compared with Pinocchio built from the same text; the variants that keep the geometry
(reframed axes, split fixed joints) keep the arm's all-solution IK class.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
from scipy.spatial.transform import Rotation

#: (file name in the zoo, tip link) of the arms the variants start from
BASES = (
    ("erd:ur_description/urdf/ur5_robot.urdf", "tool0"),
    ("erd:z1_description/urdf/z1.urdf", "link06"),
    ("rtb:xacro/kuka_description/kuka_kr16/urdf/kr16_2.urdf", "tool0"),
    ("rtb:xacro/unimation_puma560_description/urdf/puma560_robot.urdf", "link7"),
    ("erd:panda_description/urdf/panda.urdf", "panda_hand_tcp"),
    ("rtb:xacro/kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf", "tool0"),
)


def _path(root: ET.Element, tip: str) -> list[ET.Element]:
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
    out, link = [], tip
    while link in by_child:
        out.append(by_child[link])
        link = by_child[link].find("parent").get("link")
    return out[::-1]


def _moving(root, tip):
    return [j for j in _path(root, tip) if j.get("type") != "fixed"]


def _origin(j: ET.Element) -> np.ndarray:
    o = j.find("origin")
    T = np.eye(4)
    if o is not None:
        T[:3, :3] = Rotation.from_euler("xyz", [float(v) for v in o.get("rpy", "0 0 0")
                                                .split()]).as_matrix()
        T[:3, 3] = [float(v) for v in o.get("xyz", "0 0 0").split()]
    return T


def _set_origin(j: ET.Element, T: np.ndarray, rpy=None) -> None:
    o = j.find("origin")
    if o is None:
        o = ET.SubElement(j, "origin")
    if rpy is None:
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rpy = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")
    o.set("xyz", " ".join(f"{v:.17g}" for v in T[:3, 3]))
    o.set("rpy", " ".join(f"{v:.17g}" for v in rpy))


def _axis(j):
    a = j.find("axis")
    return np.array([float(v) for v in (a.get("xyz") if a is not None else "1 0 0").split()])


def _set_axis(j, v):
    a = j.find("axis")
    if a is None:
        a = ET.SubElement(j, "axis")
    a.set("xyz", " ".join(f"{x:.17g}" for x in v))


def fixed_split(root, tip, rng):
    """Every moving joint's origin moved onto a fixed joint before it (a new link between)."""
    for k, j in enumerate(_moving(root, tip)):
        T = _origin(j)
        parent = j.find("parent").get("link")
        mid = f"zoo_mid{k}"
        ET.SubElement(root, "link", name=mid)
        f = ET.SubElement(root, "joint", name=f"zoo_fixed{k}", type="fixed")
        ET.SubElement(f, "parent", link=parent)
        ET.SubElement(f, "child", link=mid)
        _set_origin(f, T)
        j.find("parent").set("link", mid)
        _set_origin(j, np.eye(4), rpy=[0, 0, 0])
    return tip


def world_joint(root, tip, rng):
    """A world link above the root, fixed at a pose that is not the identity."""
    links = {lk.get("name") for lk in root.findall("link")}
    kids = {j.find("child").get("link") for j in root.findall("joint")}
    (top,) = links - kids
    ET.SubElement(root, "link", name="zoo_world")
    f = ET.SubElement(root, "joint", name="zoo_world_joint", type="fixed")
    ET.SubElement(f, "parent", link="zoo_world")
    ET.SubElement(f, "child", link=top)
    ET.SubElement(f, "origin", xyz="0.3 -0.2 0.5", rpy="0.2 -0.4 1.1")
    return tip


def tool_rot(root, tip, rng):
    """A tool frame rotated off the flange (rpy with a quarter turn)."""
    ET.SubElement(root, "link", name="zoo_tcp")
    f = ET.SubElement(root, "joint", name="zoo_tcp_joint", type="fixed")
    ET.SubElement(f, "parent", link=tip)
    ET.SubElement(f, "child", link="zoo_tcp")
    ET.SubElement(f, "origin", xyz="0.01 -0.02 0.12", rpy="1.5707963267948966 0 0.7853981634")
    return "zoo_tcp"


def _reframe(root, tip, rng, pick):
    """Each moving joint's child frame turned by a rotation S (``pick``): the joint's origin
    becomes R·S, its axis S^T·a, and every joint leaving the child link is premultiplied by
    S^T; the geometry of the axes is unchanged."""
    by_parent: dict[str, list] = {}
    for j in root.findall("joint"):
        by_parent.setdefault(j.find("parent").get("link"), []).append(j)
    for j in _moving(root, tip):
        T = _origin(j)
        S = np.eye(4)
        S[:3, :3], rpy = pick(T)
        _set_origin(j, T @ S, rpy)
        _set_axis(j, S[:3, :3].T @ _axis(j))
        for c in by_parent.get(j.find("child").get("link"), []):
            _set_origin(c, S.T @ _origin(c))
    return tip


def reframed(root, tip, rng):
    """Axes not along z and rpy everywhere (a random turn of every child frame)."""
    def pick(T):
        S = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
        return S, None
    return _reframe(root, tip, rng, pick)


def gimbal(root, tip, rng):
    """Every moving joint's origin rpy at gimbal lock (pitch exactly ±π/2)."""
    def pick(T):
        rpy = [float(rng.uniform(-3, 3)), math.pi / 2 * rng.choice([-1, 1]),
               float(rng.uniform(-3, 3))]
        G = Rotation.from_euler("xyz", rpy).as_matrix()
        return T[:3, :3].T @ G, rpy
    return _reframe(root, tip, rng, pick)


def negated_axes(root, tip, rng):
    """Every moving joint's axis negated (``0 0 -1``, ``0 -1 0``...)."""
    for j in _moving(root, tip):
        _set_axis(j, -_axis(j))
    return tip


def continuous(root, tip, rng):
    for j in _moving(root, tip):
        if j.get("type") == "revolute":
            j.set("type", "continuous")
    return tip


def wide_limits(root, tip, rng):
    """Revolute limits of ±1.5 turns."""
    for j in _moving(root, tip):
        lim = j.find("limit")
        if j.get("type") == "revolute" and lim is not None:
            lim.set("lower", f"{-3 * math.pi:.17g}")
            lim.set("upper", f"{3 * math.pi:.17g}")
    return tip


def scientific(root, tip, rng):
    """Every number of the chain's origins, axes and limits in scientific notation."""
    def sci(text):
        return " ".join(f"{float(v):+.17E}" for v in text.split())
    for j in _path(root, tip):
        for el, key in ((j.find("origin"), "xyz"), (j.find("origin"), "rpy"),
                        (j.find("axis"), "xyz"), (j.find("limit"), "lower"),
                        (j.find("limit"), "upper")):
            if el is not None and el.get(key) is not None:
                el.set(key, sci(el.get(key)))
    return tip


def missing_meshes(root, tip, rng):
    for lk in root.findall("link"):
        v = ET.SubElement(lk, "visual")
        g = ET.SubElement(v, "geometry")
        ET.SubElement(g, "mesh", filename="package://zoo_absent/meshes/part.stl",
                      scale="0.001 0.001 0.001")
    return tip


def gripper(root, tip, rng):
    """Two prismatic fingers below the tip, the second mimicking the first: ``tip`` is no
    longer a leaf; the variant keeps the arm's tip (named)."""
    for k, sign in ((1, 1), (2, -1)):
        ET.SubElement(root, "link", name=f"zoo_finger{k}")
        f = ET.SubElement(root, "joint", name=f"zoo_finger_joint{k}", type="prismatic")
        ET.SubElement(f, "parent", link=tip)
        ET.SubElement(f, "child", link=f"zoo_finger{k}")
        ET.SubElement(f, "origin", xyz=f"0 {0.01 * sign} 0.05", rpy="0 0 0")
        ET.SubElement(f, "axis", xyz=f"0 {sign} 0")
        ET.SubElement(f, "limit", lower="0", upper="0.04", effort="1", velocity="1")
        if k == 2:
            ET.SubElement(f, "mimic", joint="zoo_finger_joint1", multiplier="1", offset="0")
    return tip


def prismatic_first(root, tip, rng):
    """The first moving joint made prismatic (travel ±0.3 m along its axis): a spherical-wrist
    arm then takes the decoupled all-solution solver."""
    j = _moving(root, tip)[0]
    j.set("type", "prismatic")
    lim = j.find("limit")
    if lim is None:
        lim = ET.SubElement(j, "limit", effort="1", velocity="1")
    lim.set("lower", "-0.3")
    lim.set("upper", "0.3")
    return tip


def prismatic_lateral(root, tip, rng):
    """The first moving joint made prismatic along the second one's axis (a PRR positioning
    chain that moves the wrist centre in three directions)."""
    path = _path(root, tip)
    moving = [k for k, j in enumerate(path) if j.get("type") != "fixed"]
    T = np.eye(4)
    for j in path[moving[0] + 1:moving[1] + 1]:
        T = T @ _origin(j)
    prismatic_first(root, tip, rng)
    _set_axis(path[moving[0]], T[:3, :3] @ _axis(path[moving[1]]))
    return tip


VARIANTS = {"fixed-split": fixed_split, "world-joint": world_joint, "tool-rot": tool_rot,
            "reframed": reframed, "gimbal": gimbal, "negated-axes": negated_axes,
            "continuous": continuous, "wide-limits": wide_limits, "scientific": scientific,
            "missing-meshes": missing_meshes, "gripper": gripper,
            "prismatic-first": prismatic_first, "prismatic-lateral": prismatic_lateral}


def _decorate(text: str) -> str:
    """Comments, CDATA, an XML declaration, a xacro namespace and a BOM around the text."""
    body = text.split("?>", 1)[-1] if text.lstrip().startswith("<?xml") else text
    if "xmlns:xacro" not in body:
        body = body.replace("<robot ", '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" ', 1)
    body = body.replace("<joint ", "<!-- a <joint> in a comment -->\n<joint ")
    body = body.replace("</robot>", "<gazebo><![CDATA[ <joint name='x'/> ]]></gazebo>"
                        "<!-- end --></robot>")
    return "\ufeff<?xml version='1.0' encoding='utf-8'?>\n<!-- generated -->\n" + body


def variants(files) -> list[tuple]:
    """(name, text, tip, expected to load, why not, base) of every variant of every base."""
    texts = dict(files)
    rng = np.random.default_rng(7)
    out = []
    for fname, tip in BASES:
        if fname not in texts:
            continue
        short = fname.rsplit("/", 1)[-1].removesuffix(".urdf")
        for vname, make in VARIANTS.items():
            root = ET.fromstring(texts[fname].encode())
            new_tip = make(root, tip, rng)
            text = ET.tostring(root, encoding="unicode")
            out.append((f"variant:{short}:{vname}", text, new_tip, True, "", None))
            if vname == "gripper":  # each finger by name; the mimic finger must be refused
                out.append((f"variant:{short}:finger1", text, "zoo_finger1", True, "", None))
                out.append((f"variant:{short}:finger2", text, "zoo_finger2", False,
                            "mimic joint zoo_finger_joint2", None))
        out.append((f"variant:{short}:decorated", _decorate(texts[fname]), tip, True, "", None))
        ns = texts[fname].replace("<robot ", '<robot xmlns="http://www.ros.org" ', 1)
        out.append((f"variant:{short}:default-ns", ns, tip, True, "", None))
    return out
