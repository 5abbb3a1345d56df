"""URDF export/import, checked against Pinocchio as an independent oracle."""

import numpy as np
import pytest

import kinestat
from kinestat.errors import KinestatError
from kinestat.io.urdf import from_urdf, to_urdf
from kinestat.mechanism.chain import from_standard_dh


@pytest.mark.parametrize("name", ["puma560", "puma762", "nadkarni-config2"])
def test_round_trip(name, rng):
    m = kinestat.load(name)
    m2 = from_urdf(to_urdf(m), length_unit=m.length_unit)  # URDF is metres: convert back
    q = m.q_home + rng.uniform(-1, 1, (20, m.n))
    np.testing.assert_allclose(kinestat.fk(m2, q), kinestat.fk(m, q), atol=1e-9)
    assert [j.kind for j in m2.joints] == [j.kind for j in m.joints]


@pytest.mark.parametrize("name", ["puma560", "puma762"])
def test_pinocchio_agrees(name, rng):
    pin = pytest.importorskip("pinocchio")
    m = kinestat.load(name)
    scale = 1e-3 if m.length_unit == "mm" else 1.0
    pm = pin.buildModelFromXML(to_urdf(m, scale=scale))
    data = pm.createData()
    fid = pm.getFrameId("tool")
    for _ in range(30):
        q = rng.uniform(-np.pi, np.pi, 6)
        pin.framesForwardKinematics(pm, data, q)
        ref = data.oMf[fid].homogeneous
        T = kinestat.fk(m, q)
        np.testing.assert_allclose(T[:3, :3], ref[:3, :3], atol=1e-10)
        np.testing.assert_allclose(T[:3, 3] * scale, ref[:3, 3], atol=1e-10)


def test_arbitrary_axes_import(rng):
    urdf = """<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
    <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
      <origin xyz="0.1 0.2 0.3" rpy="0.1 0.2 0.3"/><axis xyz="1 0 0"/>
      <limit lower="-1" upper="1" effort="0" velocity="0"/></joint>
    <joint name="j2" type="prismatic"><parent link="b"/><child link="c"/>
      <origin xyz="0 0 0.5"/><axis xyz="0 -1 0"/>
      <limit lower="0" upper="0.2" effort="0" velocity="0"/></joint></robot>"""
    m = from_urdf(urdf)
    q = np.array([0.4, 0.1])
    # independent: compose the URDF semantics directly
    from scipy.spatial.transform import Rotation as R
    T1 = np.eye(4)
    T1[:3, :3] = R.from_euler("xyz", [0.1, 0.2, 0.3]).as_matrix()
    T1[:3, 3] = [0.1, 0.2, 0.3]
    J1 = np.eye(4)
    J1[:3, :3] = R.from_rotvec([0.4, 0, 0]).as_matrix()
    T2 = np.eye(4)
    T2[:3, 3] = [0, 0, 0.5]
    J2 = np.eye(4)
    J2[:3, 3] = [0, -0.1, 0]
    np.testing.assert_allclose(kinestat.fk(m, q), T1 @ J1 @ T2 @ J2, atol=1e-12)
    assert m.joints[1].kind == "prismatic" and m.upper[1] == 0.2


@pytest.mark.parametrize("text", ["<robot", "<foo/>", "<robot><link name='a'/><link name='b'/>"
                                  "</robot>", "<robot><link name='a'/><link name='b'/><joint "
                                  "name='j' type='planar'><parent link='a'/><child link='b'/>"
                                  "</joint></robot>"])
def test_bad_urdf(text):
    with pytest.raises(KinestatError):
        from_urdf(text)


def test_screw_joint_refused():
    m = from_standard_dh([[0, 0, 0, 0]], ["screw"], pitches=[1.0])
    with pytest.raises(KinestatError, match="screw"):
        to_urdf(m)


def test_binary_file_is_a_parse_error(tmp_path):
    # used to escape as a UnicodeDecodeError traceback
    from kinestat.errors import ParseError
    from kinestat.io.urdf import read_urdf

    p = tmp_path / "bin.urdf"
    p.write_bytes(b"\xff\xfe<robot/>")
    with pytest.raises(ParseError, match="not UTF-8"):
        read_urdf(p)
