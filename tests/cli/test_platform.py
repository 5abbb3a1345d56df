"""``kinestat platform`` end to end."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.cli.main import main
from kinestat.io.library import prototype
from kinestat.io.platform_toml import write_platform
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import special_6_6
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


def test_nonpositive_leg_is_named(capsys):
    # used to say "at index (5,)"
    err = run_err(capsys, "fk", "--legs", "79,81,81,68,67,-68")
    assert "--legs: leg T has length -68" in err


def test_binary_pose_file_is_clean(capsys, tmp_path):
    # used to end in a UnicodeDecodeError traceback
    f = tmp_path / "pose.json"
    f.write_bytes(b"\xff\xfe\x00")
    err = run_err(capsys, "ik", "--pose", str(f))
    assert err.startswith(f"kinestat: error: {f}: not a text file") and len(err.splitlines()) == 1


def test_ik_fk_round_trip_through_the_cli(capsys, tmp_path, rng):
    # platform ik at a pose near home, then platform fk on those legs: one mode is that pose
    p = prototype()
    from kinestat.parallel._refine import apply_twist

    T = apply_twist(p.home_pose, rng.normal(size=6) * np.r_[[0.05] * 3, [2.0] * 3])
    f = tmp_path / "pose.json"
    f.write_text(json.dumps({"pose": T.tolist()}))
    legs = run_json(capsys, "ik", "--pose", str(f))["leg_lengths"]
    out = run_json(capsys, "fk", "--legs", ",".join(repr(x) for x in legs))
    err = [np.abs(np.array(s["pose"]) - T).max() for s in out["solutions"]]
    assert min(err) < 1e-9
    best = out["solutions"][int(np.argmin(err))]
    np.testing.assert_allclose(best["top_points"], (T[:3, :3] @ p.top_points.T).T + T[:3, 3],
                               atol=1e-9)


def _general_platform_file(tmp_path):
    from kinestat.parallel.platform import Platform

    base = np.array([[100, 0, 0], [90, 40, 0], [-30, 95, 0], [-70, 60, 0], [-60, -80, 0],
                     [-10, -100, 0]], dtype=float)
    top = np.array([[40, 10, 0], [20, 40, 0], [-15, 45, 0], [-45, 5, 0], [-30, -35, 0],
                    [30, -30, 0]], dtype=float)
    home = np.eye(4)
    home[2, 3] = 60.0
    plat = Platform(base_points=base, top_points=top, stiffness=np.full(6, 2.0),
                    free_lengths=np.linalg.norm(top + [0, 0, 60] - base, axis=1), home_pose=home,
                    leg_names=tuple("abcdef"), name="general")
    f = tmp_path / "general.toml"
    write_platform(plat, f)
    return plat, f


def test_general_platform_fk_and_its_failure_message(capsys, tmp_path, rng):
    from kinestat.parallel._refine import apply_twist

    plat, f = _general_platform_file(tmp_path)
    T = apply_twist(plat.home_pose, rng.normal(size=6) * np.r_[[0.02] * 3, [1.0] * 3])
    legs = ",".join(repr(float(x)) for x in leg_lengths(plat, T))
    out = run_json(capsys, "fk", "--legs", legs, "--platform", str(f))
    assert out["count"] == 1
    np.testing.assert_allclose(out["solutions"][0]["pose"], T, atol=1e-8)
    # far from home: the message used to advise "another guess or fk_all", neither of which
    # the command offers (and fk_all refuses a general platform)
    err = run_err(capsys, "fk", "--legs", "10,10,10,10,10,500", "--platform", str(f))
    assert "general 6-6 platform" in err and "fk_all" not in err
    assert len(err.splitlines()) == 1
