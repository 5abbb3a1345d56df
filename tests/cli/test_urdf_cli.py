"""``kinestat fk``, ``ik`` and ``guide`` on real arms' URDF files (issue 15)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.io.urdf import to_urdf
from tests.urdf_arms import arm_path


def _json(capsys, *args):
    assert main([*map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_fk_ik_guide_on_the_ur5_urdf(capsys, tmp_path):
    path = arm_path("ur5")
    m = kinestat.load(path, tip="tool0")
    q_deg = [10, -60, 70, -20, 50, 30]
    fk = _json(capsys, "fk", path, "--tip", "tool0", "--q-deg", ",".join(map(str, q_deg)))
    np.testing.assert_allclose(fk["pose"], kinestat.fk(m, np.radians(q_deg)), atol=1e-12)
    assert fk["joint_names"] == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                 "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
    pose = tmp_path / "pose.json"
    pose.write_text(json.dumps({"pose": fk["pose"]}))
    ik = _json(capsys, "ik", path, "--tip", "tool0", "--pose", pose)
    assert ik["success"]
    np.testing.assert_allclose(kinestat.fk(m, ik["q"]), fk["pose"], atol=1e-9)
    g = _json(capsys, "guide", path, "--tip", "tool0", "--to-pose", pose, "--q0-deg",
              "0,-50,60,-10,40,20")
    assert not g["stopped"] and g["final_pose_error"]["position"] < 1e-9
    np.testing.assert_allclose(g["final_hand_points"][0], np.array(fk["pose"])[:3, 3],
                               atol=1e-9)


def test_human_fk_names_the_urdf_joints(capsys):
    assert main(["fk", str(arm_path("ur5")), "--tip", "tool0", "--q-deg", "0,0,0,0,0,0"]) == 0
    out = capsys.readouterr().out
    assert "shoulder_pan_joint" in out and "wrist_3_joint" in out


def test_length_unit_option(capsys):
    path = arm_path("ur5")
    m_ = _json(capsys, "fk", path, "--tip", "tool0", "--q-deg", "0,0,0,0,0,0")
    mm = _json(capsys, "fk", path, "--tip", "tool0", "--q-deg", "0,0,0,0,0,0", "--length-unit",
               "mm")
    assert mm["length_unit"] == "mm" and mm["units"]["length"] == "mm"
    np.testing.assert_allclose(np.array(mm["pose"])[:3, 3], 1000 * np.array(m_["pose"])[:3, 3])


def test_millimetre_urdf_warns_on_one_line(capsys, tmp_path):
    p = tmp_path / "puma762_mm.urdf"
    p.write_text(to_urdf(kinestat.load("puma762"), scale=1.0))  # numbers in mm
    assert main(["fk", str(p), "--q-deg", "0,0,0,0,0,0", "--json"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("kinestat: warning:") and "millimetres" in err[0]
    assert main(["fk", str(p), "--q-deg", "0,0,0,0,0,0", "--scale", "0.001", "--json"]) == 0
    cap = capsys.readouterr()
    assert cap.err == ""
    T = kinestat.fk(kinestat.load("puma762"), np.zeros(6))
    np.testing.assert_allclose(np.array(json.loads(cap.out)["pose"])[:3, 3] * 1e3, T[:3, 3],
                               atol=1e-9)


@pytest.mark.parametrize("args, msg", [
    (["--q-deg", "0,0,0,0,0,0"], "2 chains below link 'world'"),
    (["--tip", "nope", "--q-deg", "0,0,0,0,0,0"], "no link named 'nope'"),
])
def test_urdf_errors_are_one_line(capsys, args, msg):
    assert main(["fk", str(arm_path("ur5")), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and msg in err[0]


def test_urdf_options_on_a_toml_model_are_refused(capsys):
    assert main(["fk", "puma560", "--tip", "x", "--q-deg", "0,0,0,0,0,0"]) == 2
    assert "not a .urdf file" in capsys.readouterr().err


def test_numerical_ik_json_names_the_joints(capsys):
    path = arm_path("ur5")
    m = kinestat.load(path, tip="tool0")
    T = kinestat.fk(m, [0.1, -1.0, 1.2, -0.3, 0.9, 0.4])
    pose = ",".join(f"{v:.17g}" for v in T.ravel())
    out = _json(capsys, "ik", path, "--tip", "tool0", "--pose", pose)
    assert out["joint_names"] == [j.name for j in m.joints]


def test_view_model_of_a_urdf(tmp_path, capsys):
    out = tmp_path / "ur5.html"
    assert main(["view", "model", str(arm_path("ur5")), "--tip", "tool0", "--q-deg",
                 "0,-90,90,0,90,0", "--html", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert "shoulder_pan_joint" in text and "wrist_3_joint" in text
