"""``kinestat control --tool-offset … --a67 … --mount …`` through the simulated devices (issue
42): another tool, a67 and mount, given by their thesis names too, converge on the cell built
with them; the report and the log say which were used."""

from __future__ import annotations

import json
from importlib import resources

import numpy as np
import pytest

from kinestat.cli.main import main
from kinestat.serial import puma762
from tests.cli._cell_helpers import json_of, use_fast_moves


@pytest.fixture(autouse=True)
def fast_robot(monkeypatch):
    use_fast_moves(monkeypatch)


@pytest.mark.parametrize("names", [("--tool-offset", "--a67"), ("--tool-point-6", "--a67-f")])
def test_another_tool_and_mount_converge_through_the_devices(tmp_path, capsys, names):
    platform = tmp_path / "platform.toml"
    platform.write_text((resources.files("kinestat.data") / "platforms"
                         / "prototype-2011.toml").read_text()
                        + "\n[mount]\noffset = 5.0\nturn_deg = 20.0\n")
    log = tmp_path / "log.jsonl"
    tool_name, a67_name = names
    assert main(["control", "--json", "--ideal-sensor", "--no-plot", "--log", str(log),
                 tool_name, "12,-8,200", a67_name, "0,1,0", "--mount", str(platform)]) == 0
    out = json_of(capsys)
    assert out["converged"]
    assert abs(out["true_force_magnitude"] - 4.0) <= 0.5
    assert out["tool_point_6"] == [12.0, -8.0, 200.0] and out["a67_start"] == [0.0, 1.0, 0.0]
    # the generic names of the same (any arm's end frame) beside the thesis's
    assert out["tool_offset"] == out["tool_point_6"]
    assert out["x_base_end_start"] == out["a67_start"]
    assert out["mount_source"] == str(platform)
    assert np.linalg.norm(out["torque_about_tip"]) <= 0.05
    # the simulator's TRUE tool point (its own forward analysis with its own tool) is the
    # report's: the simulated cell carries the same tool
    recs = [json.loads(line) for line in log.read_text().splitlines()]
    last = [r for r in recs if r["type"] == "cycle"][-1]
    np.testing.assert_allclose(last["true"]["tool_point"], out["tool_point"], atol=0.05)
    q = np.radians(last["true"]["joints_deg"])
    np.testing.assert_allclose(puma762.forward(q, np.array([12.0, -8.0, 200.0])).tool_point,
                               last["true"]["tool_point"], atol=1e-9)
    head = recs[0]
    assert head["config"]["tool_point_6"] == [12.0, -8.0, 200.0]
    assert head["mount_source"] == str(platform)
