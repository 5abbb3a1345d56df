"""``kinestat control --arm MODEL``: another arm on the in-process simulated cell from the
command line (embedded name, URDF with its options, --arm-base) and its one-line refusals."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.viz.cell_scene import _logged_arm
from tests.cli._cell_helpers import json_of, use_fast_moves
from tests.urdf_arms import arm_path


@pytest.fixture(autouse=True)
def fast_robot(monkeypatch):
    use_fast_moves(monkeypatch)


def _log(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_ur5_urdf_press_json(tmp_path, capsys):
    log = tmp_path / "log.jsonl"
    rc = main(["control", "--arm", str(arm_path("ur5")), "--tip", "tool0", "--json",
               "--no-plot", "--log", str(log)])
    rep = json_of(capsys)
    assert rc == 0 and rep["converged"] is True
    assert abs(rep["true_force_magnitude"] - 4.0) <= 0.5
    arm = rep["arm"]
    assert arm["placement"] == "auto" and len(arm["joints"]) == 6
    # the final joints are the URDF model's, and reach the reported tool point from the base
    m = kinestat.load(arm_path("ur5"), tip="tool0")
    T = kinestat.fk(m, np.radians(rep["final_joints_deg"]))
    tool = 1000.0 * (T[:3, :3] @ np.array([0.0, 0.0, 0.235]) + T[:3, 3]) + arm["base"]
    np.testing.assert_allclose(tool, rep["tool_point"], atol=1e-6)
    records = _log(log)
    assert records[0]["arm"] == arm and records[-1]["type"] == "end"
    # the replay draws this arm: the chain the header records puts the tool where it was
    chain = _logged_arm(records[0]["arm"])
    for r in (r for r in records if r["type"] == "cycle"):
        T = kinestat.fk(chain, np.radians(r["measured"]["joints_deg"]))
        np.testing.assert_allclose(T[:3, :3] @ [0, 0, 235.0] + T[:3, 3],
                                   r["measured"]["tool_point"], atol=1e-6)
    html = tmp_path / "replay.html"
    assert main(["view", "log", str(log), "--html", str(html), "--no-open"]) == 0
    assert html.stat().st_size > 0


def test_arm_base_given_and_text_report(tmp_path, capsys):
    rc = main(["control", "--arm", "puma560", "--arm-base", "-965,277,-590", "--no-plot",
               "--log", str(tmp_path / "log.jsonl")])
    out = capsys.readouterr()
    assert rc == 0
    assert "arm puma560: base at (-965, 277, -590) mm, --arm-base" in out.out
    assert "arm puma560" in out.err


def test_thesis_arm_by_name_is_the_default_run(tmp_path, capsys):
    """``--arm puma762`` is the thesis's cell: the same report as no --arm (timing aside)."""
    reps = []
    for extra in ([], ["--arm", "puma762"]):
        assert main(["control", "--json", "--no-plot", "--ideal-sensor",
                     "--log", str(tmp_path / f"log{len(reps)}.jsonl"), *extra]) == 0
        rep = json_of(capsys)
        assert "arm" not in rep
        reps.append({k: rep[k] for k in ("states", "final_axis_deg", "force", "iterations")})
    assert reps[0] == reps[1]


@pytest.mark.parametrize("args, message", [
    (["--arm", "ur5", "--galil", "localhost:1", "--serial", "/dev/null"], "PUMA 762's hardware"),
    (["--arm", "puma762", "--arm-base", "0,0,0"], "fixed frame"),
    (["--arm-base", "0,0,0"], "give --arm"),
    (["--tip", "tool0"], "give --arm"),
    (["--arm", "ur5", "--arm-base", "5000,0,0"], "out of reach"),
    (["--arm", "ur5", "--arm-base", "1,2"], "arm-base"),
    (["--arm", "no-such-arm"], "unknown model"),
    (["--arm", "puma560", "--tip", "x"], "not a .urdf file"),
])
def test_bad_arm_requests_fail_before_any_motion(tmp_path, capsys, args, message):
    log = tmp_path / "log.jsonl"
    assert main(["control", "--no-plot", "--log", str(log), *args]) == 2
    err = capsys.readouterr().err
    assert message in err.replace("\n", " ")
    assert len([ln for ln in err.splitlines() if ln.strip()]) <= 3  # one error (wrapped)
    assert not log.exists()


def test_a_seven_joint_urdf_is_one_error(tmp_path, capsys):
    log = tmp_path / "log.jsonl"
    assert main(["control", "--arm", str(arm_path("panda")), "--tip", "panda_hand_tcp",
                 "--no-plot", "--log", str(log)]) == 2
    assert "has 7 joints" in capsys.readouterr().err
    assert not log.exists()


def test_a_wrist_flip_at_a_joint_limit_is_named(tmp_path, capsys):
    # a CLI fuzz draw: the PUMA 560's axis 4 at its lower limit (−109.9° of −110°); the turn's
    # continuous solution needs −110.3°, and the only one within the limits flips the wrist
    # (axes 4 and 6 by 180°): the envelope refuses the 180° step, and the reason says why
    rc = main(["control", "--arm", "puma560", "--task", "press", "--direction",
               "0.9461,0.1944,-0.2592", "--force", "3.1", "--workpiece",
               "cylinder:radius=524.2,axis=-0.6894,0.7211,0.0687", "--method", "fixed",
               "--estimator", "wrench", "--noise", "0.0009", "--step", "0.61", "--json",
               "--no-plot",
               "--log", str(tmp_path / "log.jsonl")])
    out = capsys.readouterr().out
    rep = json.loads(out[out.index("{"):])
    assert rc == 2 and not rep["converged"]
    assert "in one command" in rep["stop_reason"], rep["stop_reason"]
    assert "inverse-kinematics branch" in rep["stop_reason"]
