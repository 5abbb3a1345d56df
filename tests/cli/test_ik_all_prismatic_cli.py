"""``kinestat ik stanford --pose ... --all``: every solution of an arm with a prismatic joint
(the decoupled solver), re-checked here with ``kinestat.fk``; prismatic values stay lengths."""

from __future__ import annotations

import json

import numpy as np

import kinestat
from kinestat.cli.main import main


def _pose_args(T):
    return ",".join(f"{v:.17g}" for v in np.asarray(T).ravel())


def test_stanford_every_solution_and_the_selected_one(capsys):
    m = kinestat.load("stanford")
    rng = np.random.default_rng(4)
    for _ in range(3):
        q = rng.uniform(np.maximum(m.lower, -1.2), np.minimum(m.upper, 1.2))
        T = kinestat.fk(m, q)
        ref = np.where(m.prismatic, q, np.degrees(q))
        assert main(["ik", "stanford", "--pose", _pose_args(T), "--all", "--current-deg",
                     ",".join(map(str, ref)), "--json"]) == 0
        out = json.loads(capsys.readouterr().out)
        assert out["method"] == "decoupled" and out["reason"] == ""
        qs = np.array([s["q"] for s in out["solutions"]])
        assert len(qs) == out["n_solutions"] >= 2
        np.testing.assert_allclose(kinestat.fk(m, qs), np.broadcast_to(T, (len(qs), 4, 4)),
                                   atol=1e-9)
        # q_deg: rotating joints in degrees, the boom (joint 3) in metres
        np.testing.assert_allclose([s["q_deg"] for s in out["solutions"]],
                                   np.where(m.prismatic, qs, np.degrees(qs)), atol=1e-9)
        assert out["selected"]["motion"] < 1e-7
        np.testing.assert_allclose(out["selected"]["q"], q, atol=1e-7)


def test_unreachable_pose_is_an_empty_set_with_the_reason(capsys):
    T = np.eye(4)
    T[:3, 3] = [0.05, 0.0, 1.263]  # the wrist centre 0.05 m from axis 1 (< d2 = 0.154 m)
    assert main(["ik", "stanford", "--pose", _pose_args(T), "--all", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["solutions"] == [] and out["selected"] is None
    assert "no real solution" in out["reason"]


def test_nadkarni_config2_is_solved_ppp_with_a_spherical_wrist(capsys):
    """DISP's manipulator #2 (PPPRRR), refused before the decoupled solver, is solved now."""
    m = kinestat.load("nadkarni-config2")
    q = m.q_home + np.array([1.0, -2.0, 0.5, 0.3, 0.2, -0.4])
    T = kinestat.fk(m, q)
    assert main(["ik", "nadkarni-config2", "--pose", _pose_args(T), "--all", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    qs = np.array([s["q"] for s in out["solutions"]])
    assert out["method"] == "decoupled" and len(qs) == 2  # a gantry: one position, two wrists
    np.testing.assert_allclose(kinestat.fk(m, qs), np.broadcast_to(T, (2, 4, 4)), atol=1e-9)
    d = np.where(m.prismatic, qs - q, np.mod(qs - q + np.pi, 2 * np.pi) - np.pi)
    assert np.min(np.max(np.abs(d), axis=1)) < 1e-9


def test_a_prismatic_joint_in_the_wrist_is_refused_naming_it(capsys, tmp_path):
    rows = "".join(
        f'[[joints]]\nname = "{i + 1}"\ntype = "{kind}"\ntheta = 0.0\nd = 0.1\na = 0.2\n'
        f'alpha = 30.0\n\n' for i, kind in enumerate(["revolute"] * 5 + ["prismatic"]))
    path = tmp_path / "rrrrrp.toml"
    path.write_text('name = "rrrrrp"\nnotation = "standard_dh"\nlength_unit = "m"\n'
                    'angle_unit = "deg"\n\n' + rows)
    assert main(["ik", str(path), "--pose", _pose_args(np.eye(4)), "--all"]) == 2
    err = capsys.readouterr().err
    assert "joint 6 of model 'rrrrrp' is prismatic" in err and "spherical wrist" in err
    assert len(err.strip().splitlines()) == 1
