"""``kinestat sweep workspace`` on a URDF model (example-robot-data's UR5), with the URDF
options --tip/--base/--scale/--length-unit as fk and ik take them."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.studies.base import build_study
from kinestat.studies.engine import run_reference
from kinestat.studies.workspace import workspace_spec
from tests.urdf_arms import arm_path


def _reach(model, grid):
    """Reach |p| over the full joint grid, computed here from kinestat.fk."""
    axes = [np.linspace(lo, hi, grid) for lo, hi in zip(model.lower, model.upper, strict=True)]
    q = np.array(list(itertools.product(*axes)))
    return np.linalg.norm(kinestat.fk(model, q)[:, :3, 3], axis=1)


@pytest.mark.parametrize("opts", [{"tip": "tool0", "length_unit": "mm"},
                                  {"tip": "wrist_3_link"}, {"tip": "tool0", "scale": 2.0}])
def test_workspace_spec_on_urdf_matches_plain_reference(opts):
    path = str(arm_path("ur5"))
    spec = workspace_spec(path, grid=3, chunk_size=200, **opts)
    s = run_reference(build_study("workspace", spec))
    model = kinestat.load(path, **opts)
    reach = _reach(model, 3)
    assert s["points"] == reach.size and s["length_unit"] == model.length_unit
    assert s["reach_max"] == pytest.approx(reach.max(), rel=1e-12)
    assert s["reach_mean"] == pytest.approx(reach.mean(), rel=1e-12)


def test_toml_specs_unchanged_by_the_urdf_options():
    assert "urdf" not in workspace_spec("puma762", grid=3)  # resumable runs keep their hash


def test_cli_sweep_workspace_urdf(capsys, tmp_path):
    path = str(arm_path("ur5"))
    out = tmp_path / "ws"
    code = main(["sweep", "workspace", "--model", path, "--tip", "tool0", "--length-unit", "mm",
                 "--grid", "3", "--chunk-size", "300", "--threads", "--workers", "1",
                 "--no-plots", "--output", str(out), "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    s = json.loads(cap.out)["summary"]
    model = kinestat.load(path, tip="tool0", length_unit="mm")
    assert s["length_unit"] == "mm" and s["points"] == 729
    assert s["reach_max"] == pytest.approx(_reach(model, 3).max(), rel=1e-12)
    # a bad tip is one clear error, exit 2
    code = main(["sweep", "workspace", "--model", path, "--tip", "no_such_link", "--grid", "3",
                 "--output", str(tmp_path / "bad")])
    assert code == 2 and "no_such_link" in capsys.readouterr().err
