"""``kinestat control``: the main job, end to end through the simulated devices."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.app import sim_cell as harness_mod
from kinestat.app.control_run import DEFAULT_START, default_plane
from kinestat.cli.main import main
from kinestat.control.controller import THESIS_FORCE_DIRECTION, ControllerConfig
from kinestat.hardware.leg_calibration import THESIS_CALIBRATION
from kinestat.parallel.platform import special_6_6
from kinestat.sim.contact import make_cell
from kinestat.sim.sensor import Sensor
from tests.cli._cell_helpers import json_of, use_fast_moves


@pytest.fixture(autouse=True)
def fast_robot(monkeypatch):
    """Command fast moves (a few ms each) by default, to keep the tests short."""
    use_fast_moves(monkeypatch)


_json = json_of


def test_default_run_reports_and_plots(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)  # the default run directory is ./kinestat-runs/<timestamp>/
    assert main(["control", "--json"]) == 0
    out = _json(capsys)
    for key in ("converged", "iterations", "force", "torque", "force_magnitude", "true_force",
                "tool_axis", "tool_point", "final_joints_deg", "final_leg_lengths", "log",
                "states", "stop_reason", "method"):
        assert key in out
    assert out["converged"] and out["states"][0] == "a" and out["states"][-1] == "e"
    assert len(out["force"]) == 3 and len(out["final_joints_deg"]) == 6
    assert abs(out["force_magnitude"] - 4.0) <= 0.5
    assert abs(np.linalg.norm(out["true_force"]) - 4.0) <= 0.6
    log = tmp_path / out["log"]
    assert log.exists() and log.parent.parent.name == "kinestat-runs"
    assert out["plots"] and (tmp_path / out["plots"][0]).exists()


def test_human_output_and_explicit_paths(tmp_path, capsys):
    log = tmp_path / "run" / "cycles.jsonl"
    assert main(["control", "--log", str(log), "--plot", str(tmp_path / "plots"),
                 "--force-tol", "0.1", "--friction", "0.3"]) == 0
    out = capsys.readouterr()
    assert "converged" in out.out and "true |F|" in out.out
    assert "cycle" in out.err  # progress on stderr
    assert log.exists() and (tmp_path / "plots" / "wrench-vs-state.png").exists()


def test_ideal_sensor_tight_tolerances(tmp_path, capsys):
    assert main(["control", "--json", "--ideal-sensor", "--force-tol", "0.01",
                 "--align-tol-deg", "0.05", "--log", str(tmp_path / "l.jsonl"),
                 "--no-plot"]) == 0
    out = _json(capsys)
    assert abs(np.linalg.norm(out["true_force"]) - 4.0) <= 0.01
    assert out["axis_error_deg"] <= 0.1
    assert out["plots"] == []


def test_fixed_step_limit_cycle_exits_with_status_2(tmp_path, capsys):
    code = main(["control", "--json", "--method", "fixed", "--log", str(tmp_path / "l.jsonl"),
                 "--no-plot"])
    captured = capsys.readouterr()
    assert code == 2 and "did not converge" in captured.err
    out = json.loads(captured.out[captured.out.index("{"):])
    assert not out["converged"] and "limit cycle" in out["stop_reason"]


def test_target_beyond_the_load_limit(tmp_path, capsys):
    code = main(["control", "--json", "--force", "60", "--log", str(tmp_path / "l.jsonl"),
                 "--no-plot"])
    captured = capsys.readouterr()
    assert code == 2 and "load limit" in captured.err
    assert json.loads(captured.out[captured.out.index("{"):])["iterations"] == 0


@pytest.mark.parametrize("args, message", [
    (["--galil", "127.0.0.1:5000"], "both --galil"),
    (["--force", "-1"], "positive"),
    (["--direction", "0,0,0"], "zero vector"),
    (["--plane-normal", "0,0,0"], "nonzero"),
    (["--method", "magic"], "method"),
    (["--ideal-sensor", "--noise", "0.01"], "exclude"),
    (["--galil", "nohost", "--serial", "/dev/null"], "HOST:PORT"),
])
def test_bad_input_is_reported(tmp_path, capsys, args, message):
    code = main(["control", "--log", str(tmp_path / "l.jsonl"), "--no-plot", *args])
    assert code == 2
    assert message in capsys.readouterr().err


def test_real_device_options_drive_external_devices(tmp_path, capsys):
    """--galil/--serial: the CLI talks to devices it did not start (here: a harness)."""

    plat = special_6_6()
    p0 = np.array([float(v) for v in DEFAULT_START.split(",")])
    pp, pn = default_plane(p0, THESIS_FORCE_DIRECTION, 2.5, 5.0)
    # the external cell's legs follow the thesis's calibration, the CLI's default (issue 12)
    cell = make_cell(plat, plane_point=pp, plane_normal=pn, legs=THESIS_CALIBRATION)
    sensor = Sensor()
    cfg = ControllerConfig(model=harness_mod.control_model(cell, sensor),
                           force=4 * THESIS_FORCE_DIRECTION, start_tool_point=p0)
    with harness_mod.SimHarness(cell, sensor, start_counts=harness_mod.start_counts(cfg)) as h:
        host, port = h.galil_address
        code = main(["control", "--json", "--galil", f"{host}:{port}", "--serial",
                     h.serial_path, "--log", str(tmp_path / "l.jsonl"), "--no-plot"])
        truth = h.truth()
    out = _json(capsys)
    assert code == 0 and out["converged"] and out["true_force"] is None
    assert abs(np.linalg.norm(truth["tool_force"]) - 4.0) <= 0.6


def test_runs_started_in_the_same_second_get_their_own_directories(tmp_path, monkeypatch):
    """``run_dir`` claims the directory (an atomic mkdir): two CLI runs started in the same
    second wrote one interleaved log when it only checked that the name was free."""
    from kinestat.app import control_api

    monkeypatch.setattr(control_api.time, "strftime", lambda fmt: "20261203-130150")
    dirs = [control_api.run_dir(tmp_path / "kinestat-runs") for _ in range(3)]
    assert len(set(dirs)) == 3 and all(d.is_dir() for d in dirs)
    assert [d.name for d in dirs] == ["20261203-130150", "20261203-130150-2",
                                      "20261203-130150-3"]
