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
