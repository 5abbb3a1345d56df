"""A negative --seed is one usage error (exit 2), not NumPy's ValueError traceback."""

from __future__ import annotations

import pytest

from kinestat.cli.main import main


@pytest.mark.parametrize("argv", [["control", "--seed", "-1", "--no-plot"],
                                  ["sim", "galil", "--seed", "-1", "--duration", "0"]])
def test_a_negative_seed_is_one_usage_error(tmp_path, capsys, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("kinestat: error: --seed must be a non-negative integer, got -1")
    assert err.count("\n") == 1, err
    assert not (tmp_path / "kinestat-runs").exists()  # refused before anything starts


def test_a_seed_of_zero_still_runs_the_simulator(capsys):
    assert main(["sim", "galil", "--seed", "0", "--duration", "0", "--json"]) == 0
    assert '"port"' in capsys.readouterr().out

