"""URDF as a model source (issue 15): ``kinestat.load(path.urdf, tip=, base=)``, units,
refusals (<mimic>, floating joints), export in metres; FK checked against Pinocchio loading the
same real URDF files (example-robot-data)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import kinestat
from kinestat.errors import InputError, KinestatWarning, ModelError, ParseError
from kinestat.io.urdf import from_urdf, to_urdf
from kinestat.mechanism.chain import from_standard_dh
from tests.urdf_arms import ARMS, arm_path

pin = pytest.importorskip("pinocchio")


def _pin_q(pm, model, q):
    """Pinocchio's configuration vector with kinestat's joints set by name, others neutral."""
    qp = pin.neutral(pm)
    for name, v in zip([j.name for j in model.joints], q, strict=True):
        jm = pm.joints[pm.getJointId(name)]
        if jm.nq == 2:  # continuous joint: (cos, sin)
            qp[jm.idx_q:jm.idx_q + 2] = [np.cos(v), np.sin(v)]
        else:
            qp[jm.idx_q] = v
    return qp


def _random_q(model, rng, n):
    lo = np.where(np.isfinite(model.lower), model.lower, -np.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, np.pi)
    return lo + (hi - lo) * rng.random((n, model.n))


#: the one leaf link of the arms whose chain the loader chooses by itself (read off the files)
_ONLY_LEAF = {"xarm7": "link_eef", "so100": "jaw", "z1": "gripperMover"}


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_fk_equals_pinocchio_on_real_arms(arm, rng):
    path = arm_path(arm)
    tip = ARMS[arm][1]
    m = kinestat.load(path, tip=tip)
    pm = pin.buildModelFromUrdf(str(path))
    data = pm.createData()
    if tip is None:  # the loader chose the only chain: the same as naming its end link
        tip = _ONLY_LEAF[arm]
        assert kinestat.fk(m, m.q_home).tolist() == kinestat.fk(
            kinestat.load(path, tip=tip), m.q_home).tolist()
    fid = pm.getFrameId(tip)
    qs = _random_q(m, rng, 50)
    T = kinestat.fk(m, qs)
    worst = 0.0
    for q, Tk in zip(qs, T, strict=True):
        pin.framesForwardKinematics(pm, data, _pin_q(pm, m, q))
        worst = max(worst, float(np.abs(Tk - data.oMf[fid].homogeneous).max()))
    assert worst < 1e-12, worst
    assert all(pm.existJointName(j.name) for j in m.joints)


def test_base_link_gives_the_relative_pose(rng):
    path = arm_path("ur5")
    sub = kinestat.load(path, base="upper_arm_link", tip="tool0")
    full = kinestat.load(path, tip="tool0")
    assert [j.name for j in sub.joints] == [j.name for j in full.joints][2:]
    pm = pin.buildModelFromUrdf(str(path))
    data = pm.createData()
    for q in _random_q(full, rng, 10):
        pin.framesForwardKinematics(pm, data, _pin_q(pm, full, q))
        ref = data.oMf[pm.getFrameId("upper_arm_link")].inverse() * data.oMf[
            pm.getFrameId("tool0")]
        np.testing.assert_allclose(kinestat.fk(sub, q[2:]), ref.homogeneous, atol=1e-12)


def test_chain_choice_errors():
    path = arm_path("ur5")
    with pytest.raises(ParseError, match=r"2 chains .*'ee_link', 'tool0'.*--tip"):
        kinestat.load(path)
    with pytest.raises(ParseError, match="'shoulder_link' \\(tip\\) is not below link "
                                         "'wrist_1_link'"):
        kinestat.load(path, base="wrist_1_link", tip="shoulder_link")
    with pytest.raises(ParseError, match="no link named 'nope' \\(base\\)"):
        kinestat.load(path, base="nope", tip="tool0")
    with pytest.raises(InputError, match="tip: options of URDF models"):
        kinestat.load("puma560", tip="tool0")


def test_length_unit_converts_and_scale_multiplies(rng):
    path = arm_path("ur5")
    m = kinestat.load(path, tip="tool0")
    mm = kinestat.load(path, tip="tool0", length_unit="mm")
    q = _random_q(m, rng, 5)
    assert mm.length_unit == "mm"
    np.testing.assert_allclose(kinestat.fk(mm, q)[:, :3, 3], 1000 * kinestat.fk(m, q)[:, :3, 3],
                               atol=1e-9)
    inch = kinestat.load(path, tip="tool0", length_unit="in")
    np.testing.assert_allclose(kinestat.fk(inch, q)[:, :3, 3] * 0.0254,
                               kinestat.fk(m, q)[:, :3, 3], atol=1e-12)
    with pytest.raises(InputError, match="'furlong' cannot be converted"):
        kinestat.load(path, tip="tool0", length_unit="furlong")


def test_millimetre_urdf_warns_and_scale_reads_it(rng):
    puma = kinestat.load("puma762")
    text_mm = to_urdf(puma, scale=1.0)  # numbers in millimetres: not what URDF means
    with pytest.warns(KinestatWarning, match="look like millimetres.*scale=0.001"):
        from_urdf(text_mm)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        in_m = from_urdf(text_mm, scale=1e-3)  # the user says what the numbers are
        in_mm = from_urdf(text_mm, scale=1.0, length_unit="mm")
    q = puma.q_home + rng.uniform(-1, 1, (10, 6))
    np.testing.assert_allclose(kinestat.fk(in_m, q)[:, :3, 3] * 1e3,
                               kinestat.fk(puma, q)[:, :3, 3], atol=1e-9)
    np.testing.assert_allclose(kinestat.fk(in_mm, q), kinestat.fk(puma, q), atol=1e-9)


def test_export_converts_to_metres(rng):
    puma = kinestat.load("puma762")  # millimetres
    pm = pin.buildModelFromXML(to_urdf(puma))
    data = pm.createData()
    for q in puma.q_home + rng.uniform(-1, 1, (10, 6)):
        pin.framesForwardKinematics(pm, data, q)
        T = kinestat.fk(puma, q)
        ref = data.oMf[pm.getFrameId("tool")].homogeneous
        np.testing.assert_allclose(ref[:3, 3], T[:3, 3] / 1000.0, atol=1e-12)
        np.testing.assert_allclose(ref[:3, :3], T[:3, :3], atol=1e-12)
    inch = kinestat.load("nadkarni-config1")
    assert inch.length_unit == "in"
    back = from_urdf(to_urdf(inch), length_unit="in")
    q = inch.q_home + rng.uniform(-0.5, 0.5, (5, inch.n))
    np.testing.assert_allclose(kinestat.fk(back, q), kinestat.fk(inch, q), atol=1e-9)
    odd = from_standard_dh([[0, 0, 1, 0]], length_unit="furlong")
    with pytest.raises(InputError, match="'furlong' cannot be converted to metres"):
        to_urdf(odd)
    assert 'xyz="201.16' in to_urdf(odd, scale=201.168).replace("201.168", "201.16")


def test_mimic_joint_on_the_chain_is_refused():
    path = arm_path("panda")
    with pytest.raises(ParseError, match="joint 'panda_finger_joint2' mimics joint "
                                         "'panda_finger_joint1'"):
        kinestat.load(path, tip="panda_rightfinger")
    # a mimic joint elsewhere in the file does not matter
    assert kinestat.load(path, tip="panda_hand_tcp").n == 7


def test_floating_joint_on_the_chain_is_refused():
    text = """<robot name="r"><link name="world"/><link name="a"/><link name="b"/>
    <joint name="free" type="floating"><parent link="world"/><child link="a"/></joint>
    <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    </joint></robot>"""
    with pytest.raises(ParseError, match="joint 'free' is floating .*--base"):
        from_urdf(text)
    assert from_urdf(text, base="a").n == 1


def test_no_moving_joint_is_a_model_error():
    text = """<robot name="r"><link name="a"/><link name="b"/>
    <joint name="f" type="fixed"><parent link="a"/><child link="b"/></joint></robot>"""
    with pytest.raises(ModelError, match="no moving joint"):
        from_urdf(text, tip="b")


def _fixed_mimic_chains():
    """(file, leaf) of every Talos chain (example-robot-data) passing through a FIXED joint
    that carries a <mimic>, read off the files."""
    import xml.etree.ElementTree as ET

    from tests.urdf_arms import robots_dir

    out = []
    for f in sorted((robots_dir() / "talos_data" / "robots").glob("talos*.urdf")):
        joints = ET.parse(f).getroot().findall("joint")
        by_child = {j.find("child").get("link"): j for j in joints}
        parents = {j.find("parent").get("link") for j in joints}
        for leaf in sorted(set(by_child) - parents):
            link, via = leaf, False
            while link in by_child:
                j = by_child[link]
                via |= j.get("type") == "fixed" and j.find("mimic") is not None
                link = j.find("parent").get("link")
            if via:
                out.append((f, leaf))
    return out


def test_a_mimic_on_a_fixed_joint_couples_nothing_talos_equals_pinocchio(rng):
    """Issue 43: a fixed joint with a <mimic> refused the whole chain (28 Talos chains of
    example-robot-data). A fixed joint has no value to couple: the chains import, and their FK
    equals Pinocchio's model of the same file."""
    chains = _fixed_mimic_chains()
    assert len(chains) == 28  # talos_left_arm 4, talos_reduced{,_box,_corrected} 8 each
    models: dict = {}
    for path, leaf in chains:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", KinestatWarning)
            m = kinestat.load(path, tip=leaf)
        if path not in models:
            models[path] = pin.buildModelFromUrdf(str(path))
        pm = models[path]
        data = pm.createData()
        fid = pm.getFrameId(leaf)
        worst = 0.0
        for q in _random_q(m, rng, 5):
            pin.framesForwardKinematics(pm, data, _pin_q(pm, m, q))
            worst = max(worst, float(np.abs(kinestat.fk(m, q) - data.oMf[fid].homogeneous).max()))
        assert worst < 1e-12, (path.name, leaf, worst)


def test_a_mimic_on_a_moving_joint_is_still_refused_and_scale_must_be_positive(tmp_path):
    text = ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
            '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>'
            '<axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>'
            '<joint name="j2" type="{kind}"><parent link="b"/><child link="c"/>'
            '<axis xyz="0 0 1"/><limit lower="-1" upper="1"/><mimic joint="j1"/></joint>'
            '</robot>')
    assert from_urdf(text.format(kind="fixed")).n == 1
    with pytest.raises(ParseError, match="mimics joint 'j1'"):
        from_urdf(text.format(kind="revolute"))
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(InputError, match="scale"):
            from_urdf(text.format(kind="fixed"), scale=bad)
