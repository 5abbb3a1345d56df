"""``kinestat control --task follow``: options, JSON contract, plots, one-line errors."""

from __future__ import annotations

import json

import pytest

from kinestat.cli._control_options import parse_workpiece as _workpiece
from kinestat.cli.main import main
from kinestat.errors import InputError
from tests.cli._cell_helpers import use_fast_moves


@pytest.fixture(autouse=True)
def fast_robot(monkeypatch):
    use_fast_moves(monkeypatch)


def test_follow_cylinder_json_and_plots(tmp_path, capsys):
    # no --travel-dir: the default, +y made perpendicular to the thesis's F_req (+y itself)
    rc = main(["control", "--task", "follow", "--travel", "6",
               "--workpiece", "cylinder:radius=200,axis=0,0,1", "--json",
               "--log", str(tmp_path / "log.jsonl"), "--plot", str(tmp_path / "plots")])
    out = capsys.readouterr().out
    rep = json.loads(out[out.index("{"):])
    assert rc == 0 and rep["completed"] is True
    assert rep["travel"] == pytest.approx(6.0, abs=1.0)
    assert rep["contact_lost"] == 0
    assert rep["travel_dir"] == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    assert rep["normal_force_max_error"] <= 0.5
    for key in ("converged", "force", "true_force", "stop_reason", "states", "cycles"):
        assert key in rep
    last = rep["cycles"][-1]
    for key in ("tool_point", "force", "true_force", "normal_estimate", "true_normal", "travel"):
        assert key in last
    names = sorted(p.rsplit("/", 1)[-1] for p in rep["plots"])
    assert names == ["normal-force-vs-travel.png", "tool-path.png", "wrench-vs-state.png"]
    # the surface was probed before the force was raised: its fit is in the report
    assert "p" in rep["states"]
    fit = next(c["probe"] for c in rep["cycles"] if c.get("probe"))
    assert fit["used"] and fit["points"] >= 6 and len(fit["normal"]) == 3


@pytest.mark.parametrize("args, message", [
    (["--travel-dir", "0.9713,0,-0.2375"], "approach direction"),
    (["--travel-dir", "0,1,0", "--force", "40"], "cannot be carried"),
    (["--travel-dir", "0,0,0"], "travel direction"),
    (["--travel-dir", "0,1,0", "--workpiece", "sphere:radius=3"], "--workpiece"),
    (["--travel-dir", "0,1,0", "--task", "slide"], "--task"),
    (["--travel-dir", "0,1,0", "--probe-span", "-1"], "probe_span"),
    (["--travel-dir", "0,1,0", "--probe-span", "30"], "probe_span"),
    (["--task", "press", "--travel", "30"], "--travel only apply to --task follow"),
    (["--task", "press", "--tilt-deg", "5", "--no-auto-tilt"],
     "--tilt-deg, --auto-tilt only apply to --task follow"),
    (["--travel-dir", "0,1,0", "--max-approach", "0"], "--max-approach"),
    (["--travel-dir", "0,1,0", "--workpiece", "cylinder:radius=200,axis=0,0,1,point=0,0,0"],
     "not ahead of the tool"),
    (["--task", "press", "--plane-point", "0,0,0", "--plane-normal", "0,0,1"],
     "inside the simulated plane"),
    (["--task", "press", "--plane-point", "0,0,0", "--plane-normal", "0,0,-1"],
     "not ahead of the tool"),
    (["--task", "press", "--direction", "0,1,0"], "the start pose (tool point (-400, 800, -100)"),
    (["--direction", "0,1,0"], "choose another --start or --direction"),
])
def test_bad_follow_requests_fail_before_any_motion(tmp_path, capsys, args, message):
    argv = ["control", "--log", str(tmp_path / "log.jsonl"), "--no-plot"]
    if "--task" not in args:
        argv += ["--task", "follow"]
    assert main(argv + args) != 0
    assert message in capsys.readouterr().err.replace("\n", " ")
    assert not (tmp_path / "log.jsonl").exists()


def test_workpiece_option_parsing():
    assert _workpiece(None) is None and _workpiece("plane") is None
    c = _workpiece("cylinder:radius=150,axis=0,0,1,point=1,2,3")
    assert c.radius == 150.0 and c.axis.tolist() == [0, 0, 1] and c.point.tolist() == [1, 2, 3]
    for bad in ("cylinder:axis=0,0,1", "cylinder:radius=1,axis=0,1", "cylinder:radius=1,"
                "axis=0,0,1,colour=3", "cylinder:radius=1,radius=2,axis=0,0,1", "cylinder"):
        with pytest.raises(InputError):
            _workpiece(bad)
