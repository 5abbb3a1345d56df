"""``kinestat guide --to-pose``: a target given as a pose (issue 16)."""

from __future__ import annotations

import json

import numpy as np

from kinestat.cli.main import main
from kinestat.io.library import load
from kinestat.mechanism.nadkarni import hand_points
from kinestat.serial.fk import fk


def _json(capsys, args, status=0):
    assert main(["guide", *args, "--json"]) == status
    return json.loads(capsys.readouterr().out)


def test_a_pose_target_is_reached_as_its_three_hand_points(capsys, tmp_path):
    m = load("nadkarni-config2")
    q = np.radians([-15, 20, 0, 90, 90, 0])  # Illustration 5's final configuration
    T = fk(m, q)
    out = _json(capsys, ["nadkarni-config2", "--to-pose", ",".join(f"{v:.15g}" for v in
                                                                  T.ravel()), "--steps", "20"])
    np.testing.assert_allclose(out["final_hand_points"], hand_points(T), atol=1e-8)
    pts = ",".join(f"{v:.15g}" for v in hand_points(T).ravel())
    same = _json(capsys, ["nadkarni-config2", "--to", pts, "--steps", "20"])
    np.testing.assert_allclose(out["table"], same["table"], atol=1e-9)
    f = tmp_path / "pose.json"
    f.write_text(json.dumps({"pose": T.tolist()}), encoding="utf-8")
    from_file = _json(capsys, ["nadkarni-config2", "--to-pose", str(f), "--steps", "20"])
    np.testing.assert_allclose(from_file["table"], same["table"], atol=1e-9)


def test_points_and_poses_together_are_refused(capsys):
    assert main(["guide", "nadkarni-config2", "--to", "10,-10,20,11,-10,20,10,-10,19",
                 "--to-pose", ",".join(["1,0,0,0", "0,1,0,0", "0,0,1,0", "0,0,0,1"])]) == 2
    assert "not both" in capsys.readouterr().err


def test_a_non_rigid_pose_is_refused(capsys):
    assert main(["guide", "nadkarni-config2", "--to-pose",
                 "2,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1"]) == 2
    assert "--to-pose" in capsys.readouterr().err
