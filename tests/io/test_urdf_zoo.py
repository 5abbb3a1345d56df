"""Valid but tricky URDF text (the classes scripts/urdf_zoo_campaign.py exercises on real
files), each compared with Pinocchio built from the same string: namespaces, fixed joints
between moving ones, world and tool frames, axes off z and negative, prismatic and continuous
joints, wide limits, gimbal-lock rpy, scientific notation, comments/CDATA, branches, missing
meshes; invalid trees refused with one error; coupled (same-line) joints refused by ik_all."""

from __future__ import annotations

import math

import numpy as np
import pytest

import kinestat
from kinestat.errors import ModelError, ParseError
from kinestat.io.urdf import from_urdf

pin = pytest.importorskip("pinocchio")

_LIMIT = '<limit lower="{lo}" upper="{hi}" effort="1" velocity="1"/>'


def _joint(name, kind, parent, child, xyz, rpy, axis, lo=-2.5, hi=2.5, extra=""):
    lim = "" if kind in ("fixed", "continuous") else _LIMIT.format(lo=lo, hi=hi)
    ax = "" if kind == "fixed" else f'<axis xyz="{axis}"/>'
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}" rpy="{rpy}"/>{ax}{lim}{extra}</joint>')


def _arm(rng, kinds=("revolute",) * 6, fixed_between=False, mesh=False, fmt="{:.17g}",
         gimbal=False):
    """A random arm: joint origins and axes drawn at random (axes off z, some negative);
    ``fmt`` writes the numbers, ``gimbal`` puts every rpy at pitch ±π/2."""
    def v(s, pitch=None):
        x = rng.uniform(-s, s, 3)
        if pitch is not None:
            x[1] = pitch
        return " ".join(fmt.format(e) for e in x)

    links, joints, parent = ["base"], [], "base"
    for i, kind in enumerate(kinds):
        if fixed_between:
            links.append(f"mid{i}")
            joints.append(_joint(f"f{i}", "fixed", parent, f"mid{i}", v(0.2), v(3), ""))
            parent = f"mid{i}"
        links.append(f"l{i}")
        ax = rng.normal(size=3)
        ax[rng.integers(3)] = -abs(ax[rng.integers(3)]) - 0.5  # a negative component
        pitch = math.pi / 2 * (-1) ** i if gimbal else None
        joints.append(_joint(f"j{i}", kind, parent, f"l{i}", v(0.3), v(3, pitch),
                             " ".join(fmt.format(e) for e in ax)))
        parent = f"l{i}"
    mesh_el = ('<visual><geometry><mesh filename="package://absent/m.stl"/></geometry>'
               '</visual>') if mesh else ""
    body = "".join(f'<link name="{lk}">{mesh_el}</link>' for lk in links) + "".join(joints)
    return body, parent


def _robot(body, head='<robot name="zoo">'):
    return f"{head}{body}</robot>"


def _pin_q(pm, model, q):
    qp = pin.neutral(pm)
    for j, v in zip(model.joints, q, strict=True):
        jm = pm.joints[pm.getJointId(j.name)]
        qp[jm.idx_q:jm.idx_q + jm.nq] = [math.cos(v), math.sin(v)] if jm.nq == 2 else [v]
    return qp


def _agree_with_pinocchio(text, tip, rng, pin_text=None, n=10):
    """Worst |FK - Pinocchio| and |Jacobian - Pinocchio's WORLD Jacobian| over random q."""
    m = from_urdf(text, tip=tip)
    pm = pin.buildModelFromXML(pin_text or text)
    data, fid = pm.createData(), pm.getFrameId(tip)
    cols = [pm.joints[pm.getJointId(j.name)].idx_v for j in m.joints]
    lo = np.where(np.isfinite(m.lower), m.lower, -np.pi)
    hi = np.where(np.isfinite(m.upper), m.upper, np.pi)
    worst = 0.0
    for q in lo + (hi - lo) * rng.random((n, m.n)):
        qp = _pin_q(pm, m, q)
        pin.framesForwardKinematics(pm, data, qp)
        J = pin.computeFrameJacobian(pm, data, qp, fid, pin.ReferenceFrame.WORLD)
        worst = max(worst, float(np.abs(kinestat.fk(m, q) - data.oMf[fid].homogeneous).max()),
                    float(np.abs(kinestat.jacobian(m, q) - np.vstack([J[3:], J[:3]])[:, cols])
                          .max()))
    return m, worst


def test_default_namespace_loads_like_pinocchio(rng):
    """<robot xmlns="..."> puts every tag in a namespace; it was refused as not <robot>."""
    body, tip = _arm(rng)
    _, worst = _agree_with_pinocchio(_robot(body, '<robot name="zoo" xmlns="http://x.org/u">'),
                                     tip, rng)
    assert worst < 1e-12


@pytest.mark.parametrize("variant", ["fixed-between", "world-and-tool", "prismatic-continuous",
                                     "wide-limits", "gimbal", "scientific", "decorated",
                                     "branches", "missing-meshes"])
def test_tricky_valid_files_equal_pinocchio(variant, rng):
    kinds = ("revolute",) * 6
    if variant == "prismatic-continuous":
        kinds = ("prismatic", "continuous", "revolute", "prismatic", "continuous", "revolute")
    body, tip = _arm(rng, kinds, fixed_between=variant == "fixed-between",
                     mesh=variant == "missing-meshes", gimbal=variant == "gimbal",
                     fmt="{:+.17E}" if variant == "scientific" else "{:.17g}")
    head, pin_head = '<robot name="zoo">', None
    if variant == "world-and-tool":
        body += ('<link name="world"/><link name="tcp"/>'
                 + _joint("w", "fixed", "world", "base", "0.3 -0.2 0.5", "0.2 -0.4 1.1", "")
                 + _joint("t", "fixed", tip, "tcp", "0 0 0.1", "1.5707963267948966 0 0.78", ""))
        tip = "tcp"
    elif variant == "wide-limits":
        body = body.replace('lower="-2.5" upper="2.5"', 'lower="-9.42" upper="9.42"')
    elif variant == "scientific":
        body = body.replace('lower="-2.5"', 'lower="-25e-1"')
    elif variant == "decorated":
        body = body.replace("<joint ", "<!-- <joint name='x'/> -->\n<joint ").replace(
            "</link>", "<![CDATA[ <joint> ]]></link>", 1)
        head = ("\ufeff<?xml version='1.0' encoding='utf-8'?>\n"
                '<robot name="zoo" xmlns:xacro="http://www.ros.org/wiki/xacro">')
        pin_head = head.lstrip("\ufeff")
    elif variant == "branches":  # two fingers below the tip: the tip is named, not a leaf
        for k, s in ((1, 1), (2, -1)):
            body += f'<link name="finger{k}"/>' + _joint(
                f"fj{k}", "prismatic", tip, f"finger{k}", f"0 {0.01 * s} 0.05", "0 0 0",
                f"0 {s} 0", 0, 0.04, '<mimic joint="fj1"/>' if k == 2 else "")
        with pytest.raises(ParseError, match="2 chains"):
            from_urdf(_robot(body))
        with pytest.raises(ParseError, match="'fj2' mimics joint 'fj1'"):
            from_urdf(_robot(body), tip="finger2")
        assert _agree_with_pinocchio(_robot(body), "finger1", rng)[0].n == 7
    text = _robot(body, head)
    m, worst = _agree_with_pinocchio(text, tip, rng,
                                     pin_text=_robot(body, pin_head) if pin_head else None)
    assert worst < 1e-9, (variant, worst)
    assert m.n == 6 and [j.name for j in m.joints] == [f"j{i}" for i in range(6)]


@pytest.mark.parametrize("change, match", [
    (lambda t: t.replace('name="j1"', 'name="j0"'), "joint 'j0' is declared twice"),
    (lambda t: t.replace('<link name="l2">', '<link name="l2"/><link name="l2">'),
     "link 'l2' is declared twice"),
    (lambda t: t.replace('<parent link="l3"/>', '<parent link="nowhere"/>'),
     "joint 'j4': its parent link 'nowhere' is not declared"),
    (lambda t: t.replace(' name="j3"', ""), "a <joint> has no name"),
])
def test_an_ambiguous_or_broken_tree_is_one_parse_error(change, match, rng):
    """Duplicate names and undeclared links: accepted (or the joint ignored) before; one error
    naming the element now, as Pinocchio's URDF parser refuses the same text."""
    body, tip = _arm(rng)
    text = change(_robot(body))
    with pytest.raises(ParseError, match=match):
        from_urdf(text, tip=tip)
    with pytest.raises(ValueError):
        pin.buildModelFromXML(text)


@pytest.mark.parametrize("sign", [1, -1])
def test_joints_on_one_line_are_refused_by_ik_all(sign, rng):
    """A 6-joint chain whose joints 5 and 6 turn about one line has a continuum of solutions
    per pose (Pinocchio's Jacobian has rank 5 everywhere); ik_all listed isolated solutions
    that missed the generating configuration. Now one ModelError naming the pair."""
    body, tip = _arm(rng, ("revolute",) * 5)
    # joint 6 on joint 5's axis: the same origin line, axis along it (either sense)
    j5_axis = body.rsplit('<axis xyz="', 1)[1].split('"')[0]
    a = np.array([float(v) for v in j5_axis.split()])
    a = sign * a / np.linalg.norm(a)
    off = " ".join(f"{0.07 * v:.17g}" for v in a)
    body += '<link name="spin"/>' + _joint("spin_joint", "revolute", tip, "spin", off, "0 0 0",
                                           " ".join(f"{v:.17g}" for v in a))
    text = _robot(body)
    m, worst = _agree_with_pinocchio(text, "spin", rng)
    assert worst < 1e-12
    pm = pin.buildModelFromXML(text)
    data = pm.createData()
    for q in rng.uniform(-2, 2, (5, 6)):
        J = pin.computeJointJacobians(pm, data, _pin_q(pm, m, q))
        assert np.linalg.matrix_rank(J, tol=1e-9) == 5
    T = kinestat.fk(m, rng.uniform(-2, 2, 6))
    with pytest.raises(ModelError, match=r"joints 5 and 6 \('j4', 'spin_joint'\) .* turn about one "
                                         r"line.*--tip"):
        kinestat.ik_all(m, T)
    assert bool(kinestat.ik(m, T).success)  # one solution numerically: still fine


def test_a_locked_joint_of_the_pair_frees_ik_all(rng):
    """7 joints whose last two turn about one line: locking one of them leaves six independent
    joints (every solution reproduces the pose by Pinocchio's FK, the generating one among
    them); locking another joint leaves the pair and is refused."""
    body, tip = _arm(rng, ("revolute",) * 6)
    j6_axis = body.rsplit('<axis xyz="', 1)[1].split('"')[0]
    body += '<link name="spin"/>' + _joint("spin_joint", "revolute", tip, "spin", "0 0 0", "0 0 0",
                                           j6_axis)
    text = _robot(body)
    m = from_urdf(text, tip="spin")
    pm = pin.buildModelFromXML(text)
    data, fid = pm.createData(), pm.getFrameId("spin")
    q = rng.uniform(-2, 2, 7)
    T = kinestat.fk(m, q)
    res = kinestat.ik_all(m, T, locked={6: q[6]})
    sols = res.solutions()
    assert len(sols) >= 1
    assert np.min(np.abs(np.mod(sols - q + np.pi, 2 * np.pi) - np.pi).max(axis=1)) < 1e-6
    for s in sols:
        pin.framesForwardKinematics(pm, data, _pin_q(pm, m, s))
        assert np.abs(data.oMf[fid].homogeneous - T).max() < 1e-9
    with pytest.raises(ModelError, match="joints 6 and 7"):
        kinestat.ik_all(m, T, locked={2: q[2]})


def test_an_axis_without_xyz_is_named(rng):
    """``<axis/>`` is a zero axis (urdfdom reads it so); the error says which joint and why,
    and no <axis> at all is URDF's default x axis, as Pinocchio reads it."""
    body, tip = _arm(rng)
    j3_axis = body.split('name="j3"', 1)[1].split('<axis xyz="', 1)[1].split('"')[0]
    with pytest.raises(ParseError, match="joint 'j3': the joint axis is zero .<axis> without"):
        from_urdf(_robot(body.replace(f'<axis xyz="{j3_axis}"/>', "<axis/>")), tip=tip)
    _, worst = _agree_with_pinocchio(_robot(body.replace(f'<axis xyz="{j3_axis}"/>', "")), tip,
                                     rng)
    assert worst < 1e-12


def test_visuals_of_a_namespaced_file(tmp_path, rng):
    """The viewer's mesh reader reads the same elements as the chain loader (a default XML
    namespace included): a package:// mesh that does not exist is reported, not fatal."""
    from kinestat.io.urdf_visuals import read_visuals

    body, tip = _arm(rng, mesh=True)
    p = tmp_path / "ns.urdf"
    p.write_text(_robot(body, '<robot name="zoo" xmlns="http://x.org/u">'), encoding="utf-8")
    visuals, _ = read_visuals(p)
    assert len(visuals) == 7 and all(v.path is None and v.missing for v in visuals)
    assert kinestat.load(p, tip=tip).n == 6


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_numerical_ik_does_not_stall_on_a_finger_at_its_limit(backend, rng):
    """A 6R arm with a prismatic finger of 4 cm travel (chosen by its tip link): the finger
    often ends a step on a limit it is pushed beyond; the clipped step then stalled, restarts
    ran out (here 78 % success; the Panda of example-robot-data with a finger: 95 %, 29
    attempts a pose). A blocked joint now leaves the step, and every reachable pose is solved,
    each success checked by Pinocchio's FK."""
    body, tip = _arm(rng)
    body += '<link name="finger"/>' + _joint("finger_joint", "prismatic", tip, "finger",
                                             "0 0.01 0.05", "0 0 0", "0 1 0", 0, 0.04)
    text = _robot(body)
    m = from_urdf(text, tip="finger")
    pm = pin.buildModelFromXML(text)
    data, fid = pm.createData(), pm.getFrameId("finger")
    q = m.lower + (m.upper - m.lower) * rng.random((60, 7))
    res = kinestat.ik(m, kinestat.fk(m, q), backend=backend)
    assert res.success.all(), res.success.mean()
    for qi, T in zip(res.q, kinestat.fk(m, q), strict=True):
        assert m.within_limits(qi)
        pin.framesForwardKinematics(pm, data, _pin_q(pm, m, qi))
        assert np.abs(data.oMf[fid].homogeneous - T).max() < 1e-8
