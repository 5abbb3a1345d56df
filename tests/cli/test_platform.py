"""``kinestat platform`` end to end."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.cli.main import main
from kinestat.io.platform_toml import write_platform
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import prototype, special_6_6
from kinestat.parallel.statics import line_jacobian

THESIS = "79.6804,81.8285,81.2669,68.6500,67.2037,68.2854"


def run_json(capsys, *args):
    assert main(["platform", *args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def run_err(capsys, *args):
    assert main(["platform", *args]) == 2
    return capsys.readouterr().err


def test_info(capsys):
    out = run_json(capsys, "info")
    p = prototype()
    np.testing.assert_allclose(out["free_lengths"], p.free_lengths)
    np.testing.assert_allclose(out["home_pose"], p.home_pose)
    assert out["special"] is True and out["leg_names"] == list("OPQRST")
    assert out["design"]["home_twist_deg"] == pytest.approx(-60.0)


def test_fk_thesis_example(capsys):
    out = run_json(capsys, "fk", "--legs", THESIS)
    L = np.array([float(v) for v in THESIS.split(",")])
    assert out["count"] == len(out["solutions"]) == 8
    p = prototype()
    for s in out["solutions"]:
        T = np.array(s["pose"])
        np.testing.assert_allclose(leg_lengths(p, T), L, atol=1e-9)
        X = np.array(s["top_points"])
        np.testing.assert_allclose(np.linalg.norm(X - p.base_points, axis=1), L, atol=1e-9)
    assert out["solutions"][0]["above_base"] is True


def test_ik_home_and_pose_forms(capsys, tmp_path):
    p = prototype()
    out = run_json(capsys, "ik", "--pose", "home")
    np.testing.assert_allclose(out["leg_lengths"], p.free_lengths, atol=1e-12)
    T = p.home_pose.copy()
    T[:3, 3] += [1.0, -2.0, 0.5]
    f = tmp_path / "pose.json"
    f.write_text(json.dumps({"pose": T.tolist()}))
    a = run_json(capsys, "ik", "--pose", str(f))
    g = tmp_path / "pose.toml"
    g.write_text("pose = " + json.dumps(T.tolist()) + "\n")
    b = run_json(capsys, "ik", "--pose", str(g))
    c = run_json(capsys, "ik", "--pose", ",".join(repr(float(v)) for v in T.ravel()))
    for o in (a, b, c):
        np.testing.assert_allclose(o["leg_lengths"], leg_lengths(p, T), atol=1e-12)


def test_statics_balances_the_wrench(capsys):
    w = [1.0, -2.0, -10.0, 30.0, -20.0, 5.0]
    out = run_json(capsys, "statics", "--pose", "home", "--wrench", ",".join(map(str, w)))
    j = line_jacobian(prototype(), prototype().home_pose)
    np.testing.assert_allclose(j @ np.array(out["leg_forces"]), w, atol=1e-9)
    assert out["jacobian_det"] == pytest.approx(np.linalg.det(j))


def test_stiffness_symmetric_home_asymmetric_loaded(capsys):
    K0 = np.array(run_json(capsys, "stiffness", "--pose", "home")["stiffness"])
    np.testing.assert_allclose(K0, K0.T, atol=1e-9)
    out = run_json(capsys, "stiffness", "--pose", "home", "--wrench", "0,0,-20,50,0,0")
    K = np.array(out["stiffness"])
    assert np.abs(K - K.T).max() > 1.0 and out["asymmetry"] > 1.0
    Ka = np.array(run_json(capsys, "stiffness", "--twist-order", "axis")["stiffness"])
    np.testing.assert_allclose(Ka, np.c_[K0[:, 3:], K0[:, :3]], atol=1e-9)


def test_platform_file_option(capsys, tmp_path):
    plat = special_6_6(base_offset=20.0, top_offset=10.0, name="other")
    f = tmp_path / "other.toml"
    write_platform(plat, f)
    out = run_json(capsys, "info", "--platform", str(f))
    assert out["name"] == "other"
    np.testing.assert_allclose(out["free_lengths"], plat.free_lengths)
    legs = ",".join(map(str, plat.free_lengths))
    fk = run_json(capsys, "fk", "--legs", legs, "--platform", str(f))
    np.testing.assert_allclose(fk["solutions"][0]["pose"], plat.home_pose, atol=1e-9)


def test_human_output(capsys):
    assert main(["platform", "fk", "--legs", THESIS]) == 0
    assert "8" in capsys.readouterr().out
    for cmd in (["info"], ["ik", "--pose", "home"], ["stiffness"],
                ["statics", "--pose", "home", "--wrench", "0,0,-5,0,0,0"]):
        assert main(["platform", *cmd]) == 0
        assert capsys.readouterr().out.strip()


@pytest.mark.parametrize("args, msg", [
    (["fk", "--legs", "-79,81,81,68,67,68"], "positive"),
    (["fk", "--legs", "nan,81,81,68,67,68"], "finite"),
    (["fk", "--legs", "79,81,81"], "6"),
    (["fk", "--legs", "500,81,81,68,67,68"], "no real assembly"),
    (["ik", "--pose", "1,2,3"], "16"),
    (["ik", "--pose", "2,0,0,0,0,2,0,0,0,0,2,0,0,0,0,1"], "rigid"),
    (["statics", "--pose", "home", "--wrench", "1,2"], "6"),
    (["info", "--platform", "/nonexistent/p.toml"], "cannot read"),
])
def test_errors_are_clean(capsys, args, msg):
    assert msg in run_err(capsys, *args)


def test_singular_pose_statics_error(capsys, tmp_path):
    import math

    from kinestat.spatial.transforms import make_pose, rot_z

    p = prototype()
    R = rot_z(math.radians(30.0))[:3, :3]
    T = make_pose(R, p.base_points[:3].mean(0) + [0, 0, 60] - R @ p.top_points[3:].mean(0))
    f = tmp_path / "singular.json"
    f.write_text(json.dumps(T.tolist()))
    assert "singular" in run_err(capsys, "statics", "--pose", str(f), "--wrench", "0,0,-1,0,0,0")
