"""An unknown --calibration / --sim-legs names the option and lists every accepted value."""

from __future__ import annotations

import pytest

from kinestat.cli.main import main


@pytest.mark.parametrize("option", ["--calibration", "--sim-legs"])
def test_an_unknown_calibration_lists_every_accepted_name(tmp_path, capsys, monkeypatch, option):
    from kinestat.io.library import list_calibrations

    monkeypatch.chdir(tmp_path)
    assert main(["control", option, "foo", "--no-plot"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"kinestat: error: {option}: unknown calibration 'foo'")
    for name in ("thesis", "nominal", *list_calibrations()):
        assert name in err
    assert err.count("\n") == 1
