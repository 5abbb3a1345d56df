"""``kinestat.app.run(RunSpec(...))``: the Python API runs what ``kinestat control`` runs, and
the example of docs/control.md runs as written (issue 41)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from kinestat.app import run
from kinestat.cli.main import main
from kinestat.control import RunSpec

DOC = Path(__file__).resolve().parents[2] / "docs" / "control.md"


def test_the_control_guides_python_example_runs(tmp_path, monkeypatch):
    text = DOC.read_text(encoding="utf-8")
    section = text[text.index("## Python\n"):]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(block, str(DOC), "exec"), namespace)  # its assert lines are the checks
    assert namespace["report"]["converged"] and (tmp_path / "press" / "log.jsonl").is_file()


def test_the_api_and_the_command_report_the_same_run(tmp_path, capsys):
    api = run(RunSpec(), log=tmp_path / "api.jsonl")
    assert main(["control", "--json", "--no-plot", "--log", str(tmp_path / "cli.jsonl")]) == 0
    cli = json.loads(capsys.readouterr().out)
    assert set(cli) == set(api)
    for key in ("converged", "iterations", "states", "moves", "tool_point", "tool_axis",
                "final_joints_deg", "mount", "a67_start"):
        assert cli[key] == api[key], key
    assert api["plots"] == [] and api["log"] == str(tmp_path / "api.jsonl")
