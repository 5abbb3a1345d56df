"""``kinestat control`` with the issue-12 options, end to end through the simulated devices."""

from __future__ import annotations

import json
from importlib import resources

import numpy as np
import pytest

from kinestat.cli.main import main
from tests.cli._cell_helpers import json_of, use_fast_moves


@pytest.fixture(autouse=True)
def fast_robot(monkeypatch):
    use_fast_moves(monkeypatch)


_json = json_of


def test_files_thesis_procedure_and_the_new_report_keys(tmp_path, capsys):
    cal = tmp_path / "mine.toml"
    cal.write_text((resources.files("kinestat.data") / "calibrations" / "thesis-2011.toml")
                   .read_text().replace('name = "thesis-2011"', 'name = "mine"'))
    plat = resources.files("kinestat.data") / "platforms" / "prototype-2011.toml"
    log = tmp_path / "l.jsonl"
    code = main(["control", "--json", "--no-plot", "--log", str(log), "--calibration", str(cal),
                 "--platform", str(plat), "--procedure", "thesis", "--step", "0.2"])
    out = _json(capsys)
    assert code == 0 and out["converged"]
    assert out["calibration"] == "mine" and out["procedure"] == "thesis"
    f = np.asarray(out["equivalent_wrench"][:3])
    np.testing.assert_allclose(np.subtract(out["torque_about_base"], out["torque_about_tool"]),
                               np.cross(out["tool_point"], f), atol=1e-6)
    assert np.linalg.norm(f - np.asarray(out["true_force"])) < 0.1
    acts = [c["action"] for c in out["cycles"]]
    assert acts[0] == "measure" and acts[-1] == "done" and acts.count("reorient") == 1
    recs = [json.loads(x) for x in log.read_text().splitlines()]
    moves = [r for r in recs if r["type"] == "move"]
    assert len(moves) == out["moves"] and all(len(m["move"]["speed"]) == 6 for m in moves)


def test_human_report_shows_both_torques(tmp_path, capsys):
    assert main(["control", "--no-plot", "--log", str(tmp_path / "l.jsonl")]) == 0
    out = capsys.readouterr().out
    assert "torque about tool point" in out and "torque about robot base" in out


@pytest.mark.parametrize("args, message", [
    (["--calibration", "nosuch"], "unknown calibration"),
    (["--sim-legs", "nominal", "--galil", "h:1", "--serial", "x"], "--sim-legs"),
    (["--procedure", "matlab"], "procedure"),
    (["--move-rule", "fastest"], "--move-rule"),
])
def test_bad_options(tmp_path, capsys, args, message):
    assert main(["control", "--no-plot", "--log", str(tmp_path / "l.jsonl"), *args]) == 2
    assert message in capsys.readouterr().err
