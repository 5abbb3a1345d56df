"""``kinestat sweep`` end to end: the JSON contract, plots, resume, clear errors."""

from __future__ import annotations

import json

import pytest

from kinestat.cli.main import main


def run(capsys, *args):
    code = main(["sweep", *args])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_workspace_default_cluster_json_contract(capsys, tmp_path, planar_model):
    out = tmp_path / "ws"
    code, stdout, _ = run(capsys, "workspace", "--model", planar_model, "--grid", "21",
                          "--chunk-size", "100", "--output", str(out), "--json")
    assert code == 0
    doc = json.loads(stdout)
    assert {"study", "summary", "output", "chunks", "elapsed_s"} <= set(doc)
    assert doc["study"] == "workspace" and doc["complete"] is True
    s = doc["summary"]
    assert s["points"] == 441 and doc["chunks"]["total"] == 5
    assert s["reach_max"] == pytest.approx(1.5) and s["reach_min"] == pytest.approx(0.5)
    assert set(s["manipulability"]) == {"min", "mean", "max"}
    for name in doc["plots"]:
        assert (out / "plots" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.loads((out / "summary.json").read_text())["summary"]["points"] == 441


def test_staged_run_resumes_from_default_output(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ["platform-range", "--grid", "3", "--chunk-size", "100", "--threads", "--workers",
            "1", "--no-plots", "--json"]
    code, stdout, _ = run(capsys, *args, "--max-chunks", "3")
    first = json.loads(stdout)
    assert code == 0 and first["complete"] is False and first["summary"] is None
    runs = list((tmp_path / "kinestat-runs").iterdir())
    assert len(runs) == 1 and runs[0].name.startswith("platform-range-")
    assert not (runs[0] / "summary.json").exists()
    code, stdout, _ = run(capsys, *args)
    second = json.loads(stdout)
    assert second["complete"] is True and second["chunks"] == {"total": 8, "computed": 5,
                                                               "reused": 3, "damaged": 0}
    assert second["summary"]["poses"] == 729
    code, stdout, _ = run(capsys, *args[:-1])  # complete: nothing to compute, human output
    assert code == 0 and "within_both" in stdout


@pytest.mark.parametrize("args, message", [
    (["workspace", "--grid", "1"], "at least 2 values"),
    (["workspace", "--grid", "0"], "at least 2 values"),
    (["workspace", "--model", "no-such-arm", "--grid", "3"], "unknown model"),
    (["workspace", "--grid", "3", "--scheduler", "tcp://127.0.0.1:9", "--timeout", "1"],
     "cannot connect"),
    (["workspace", "--grid", "3", "--scheduler", "nowhere"], "tcp://HOST:PORT"),
    (["platform-design", "--height", "50:70"], "needs a count"),
    (["tolerance", "--samples", "0"], "at least 1"),
])
def test_bad_specs_exit_2_with_one_line(capsys, tmp_path, args, message):
    out = tmp_path / "out"
    code, stdout, err = run(capsys, *args, "--output", str(out), "--no-plots", "--quiet")
    assert code == 2
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("kinestat: error:") and message in lines[0]
    assert not out.exists()  # nothing that could be mistaken for a result


def test_zero_workers_is_an_error(capsys, tmp_path):
    code, _, err = run(capsys, "workspace", "--grid", "2", "--workers", "0", "--output",
                       str(tmp_path / "w"))
    assert code == 2 and "--workers must be at least 1" in err
    assert not (tmp_path / "w").exists()
