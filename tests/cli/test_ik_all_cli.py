"""``kinestat ik MODEL --pose ... --all``: every analytic solution (issue 15), on embedded,
TOML-free and URDF models; solutions re-checked here with ``kinestat.fk``."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from tests.urdf_arms import arm_path

UNREACHABLE = "1,0,0,5,0,1,0,0,0,0,1,0,0,0,0,1"  # 5 m away: beyond every arm here


def _run(capsys, *args, status=0):
    assert main([*map(str, args)]) == status
    cap = capsys.readouterr()
    return cap


def _pose_args(T):
    return ",".join(f"{v:.17g}" for v in np.asarray(T).ravel())


def _wrapped_equal(a, b, tol=1e-7):
    d = np.mod(np.asarray(a) - np.asarray(b) + np.pi, 2 * np.pi) - np.pi
    return bool(np.all(np.abs(d) < tol))


@pytest.mark.parametrize("spec", ["puma560", "ur5"])
def test_every_solution_reproduces_the_pose_and_the_generator_is_among_them(spec, capsys, rng):
    if spec == "ur5":
        m, args = kinestat.load(arm_path("ur5"), tip="tool0"), [arm_path("ur5"), "--tip", "tool0"]
    else:
        m, args = kinestat.load(spec), [spec]
    for _ in range(3):
        q = rng.uniform(np.maximum(m.lower, -1.2), np.minimum(m.upper, 1.2))  # within limits
        T = kinestat.fk(m, q)
        out = json.loads(_run(capsys, "ik", *args, "--pose", _pose_args(T), "--all",
                              "--current-deg", ",".join(map(str, np.degrees(q))), "--json").out)
        sols = out["solutions"]
        assert out["n_solutions"] == len(sols) >= 2 and out["reason"] == ""
        qs = np.array([s["q"] for s in sols])
        np.testing.assert_allclose(kinestat.fk(m, qs), np.broadcast_to(T, (len(sols), 4, 4)),
                                   atol=1e-9)
        np.testing.assert_allclose([s["q_deg"] for s in sols], np.degrees(qs), atol=1e-9)
        assert all(s["residual"]["position"] <= 1e-9 for s in sols)
        assert any(_wrapped_equal(s, q) for s in qs)
        # the reference is the generating configuration: it is selected, with no motion
        assert out["selected"]["motion"] < 1e-7
        np.testing.assert_allclose(out["selected"]["q"], q, atol=1e-7)
        assert out["joint_names"] == [j.name for j in m.joints]
        assert out["method"] == ("pieper" if spec == "puma560" else "three-parallel")


def test_q0_deg_is_the_same_reference_as_current_deg(capsys):
    m = kinestat.load("puma560")
    q_ref = "20,30,-40,10,60,-30"
    T = kinestat.fk(m, np.radians([25, 35, -45, 15, 55, -35]))
    a = json.loads(_run(capsys, "ik", "puma560", "--pose", _pose_args(T), "--all",
                        "--current-deg", q_ref, "--json").out)
    b = json.loads(_run(capsys, "ik", "puma560", "--pose", _pose_args(T), "--all",
                        "--q0-deg", q_ref, "--json").out)
    assert a["selected"] == b["selected"]
    # nearest: no other within-limit solution is closer to the reference
    ref = np.radians([float(v) for v in q_ref.split(",")])
    wrapped = [np.abs(np.mod(np.array(s["q"]) - ref + np.pi, 2 * np.pi) - np.pi).sum()
               for s in a["solutions"] if s["within_limits"]]
    assert a["selected"]["motion"] == pytest.approx(min(wrapped), abs=1e-9)


def test_unreachable_pose_is_an_empty_set_with_the_reason(capsys):
    out = json.loads(_run(capsys, "ik", "puma560", "--pose", UNREACHABLE, "--all",
                          "--json").out)
    assert out["solutions"] == [] and out["n_solutions"] == 0 and out["selected"] is None
    assert "out of reach" in out["reason"]
    cap = _run(capsys, "ik", "puma560", "--pose", UNREACHABLE, "--all")
    assert "no solution" in cap.out and "unreachable" in cap.out and cap.err == ""


def test_puma762_wrist_singular_pose_reports_a_family(capsys):
    m = kinestat.load("puma762")
    q = np.radians([200, 10, 20, 30, 0, 50])  # theta5 = 0: only theta4 - theta6 is fixed
    out = json.loads(_run(capsys, "ik", "puma762", "--pose", _pose_args(kinestat.fk(m, q)),
                          "--all", "--current-deg", "200,10,20,25,0,55", "--json").out)
    fams = out["singular_families"]
    assert len(fams) >= 1
    f = fams[0]
    assert out["solutions"][f["solution"]]["singular"]
    assert _wrapped_equal(q[3] + f["sign"] * q[5], f["value"], 1e-9)
    sel = np.radians(out["selected"]["q_deg"])
    np.testing.assert_allclose(kinestat.fk(m, sel), kinestat.fk(m, q), atol=1e-6)


def test_a_batch_of_poses_gives_one_record_per_target(capsys, tmp_path):
    m = kinestat.load("puma560")
    T = kinestat.fk(m, np.array([[0.1, 0.2, 0.3, 0.4, 0.5, 0.6], [0.0, 0.0, 0.0, 0, 0, 0]]))
    p = tmp_path / "poses.json"
    p.write_text(json.dumps(T.tolist()))
    out = json.loads(_run(capsys, "ik", "puma560", "--pose", p, "--all", "--json").out)
    assert len(out["targets"]) == 2
    for rec, Tk in zip(out["targets"], T, strict=True):
        qs = np.array([s["q"] for s in rec["solutions"]])
        np.testing.assert_allclose(kinestat.fk(m, qs), np.broadcast_to(Tk, (len(qs), 4, 4)),
                                   atol=1e-9)


def test_human_table_names_the_joints(capsys):
    path = arm_path("ur5")
    m = kinestat.load(path, tip="tool0")
    T = kinestat.fk(m, [0.1, -1.0, 1.2, -0.3, 0.9, 0.4])
    cap = _run(capsys, "ik", path, "--tip", "tool0", "--pose", _pose_args(T), "--all")
    assert "shoulder_pan_joint" in cap.out and "selected #" in cap.out


@pytest.mark.parametrize("args, msg", [
    (["puma560", "--current-deg", "0,0,0,0,0,0", "--q0-deg", "0,0,0,0,0,0"],
     "give the reference configuration once"),
    (["puma762", "--tool-point", "0,0,0"], "--all goes with --pose"),
])
def test_errors_name_why(capsys, args, msg):
    cap = _run(capsys, "ik", *args, "--pose", UNREACHABLE, "--all", status=2)
    assert msg in cap.err and len(cap.err.strip().splitlines()) == 1


def test_seven_joint_urdf_arm_has_no_analytic_solver(capsys):
    cap = _run(capsys, "ik", arm_path("panda"), "--tip", "panda_hand_tcp", "--pose", UNREACHABLE,
               "--all", status=2)
    assert "'panda' has 7 joints" in cap.err and "exactly 6" in cap.err
