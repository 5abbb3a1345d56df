"""``kinestat control --workpiece-stiffness``: a compliant simulated workpiece, refused when it
is not a finite positive number of N/mm or with real devices."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.cli.main import main
from tests.cli._cell_helpers import json_of, use_fast_moves


@pytest.fixture(autouse=True)
def fast_robot(monkeypatch):
    use_fast_moves(monkeypatch)


@pytest.mark.parametrize("value", ["0", "-2", "nan", "inf"])
def test_a_stiffness_that_is_not_finite_and_positive_is_one_clear_error(tmp_path, capsys, value):
    log = tmp_path / "l.jsonl"
    assert main(["control", "--workpiece-stiffness", value, "--log", str(log), "--no-plot"]) == 2
    err = capsys.readouterr().err
    assert "kinestat: error: --workpiece-stiffness must be a finite number of N/mm > 0" in err
    assert err.count("error") == 1 and not log.exists()  # refused before anything moved


def test_the_stiffness_describes_the_simulated_cell_only(tmp_path, capsys):
    assert main(["control", "--workpiece-stiffness", "2", "--galil", "127.0.0.1:1",
                 "--serial", "/dev/null", "--no-plot", "--log", str(tmp_path / "l.jsonl")]) == 2
    assert "--workpiece-stiffness" in capsys.readouterr().err


def test_the_press_converges_on_a_compliant_workpiece(tmp_path, capsys):
    log = tmp_path / "l.jsonl"
    assert main(["control", "--json", "--workpiece-stiffness", "2", "--log", str(log),
                 "--no-plot"]) == 0
    out = json_of(capsys)
    assert out["converged"]
    assert abs(np.linalg.norm(out["true_force"]) - 4.0) <= 0.6
    header = json.loads(log.read_text().splitlines()[0])
    assert header["workpiece_stiffness"] == 2.0
