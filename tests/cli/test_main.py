"""``kinestat.cli.main.main``: exit statuses and one-line errors."""

from __future__ import annotations

import kinestat
from kinestat.cli.main import main


def test_kinestat_error_is_one_line_exit_2(capsys):
    assert main(["fk", "puma762", "--q", "1,2,3"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("kinestat: error: --q:") and len(err.splitlines()) == 1


def test_os_error_is_one_line_exit_2(capsys, monkeypatch):
    # an OSError (permissions, a full disk, a vanished file) used to escape as a traceback
    def refuse(name):
        raise PermissionError(13, "Permission denied", "/models/arm.toml")

    monkeypatch.setattr(kinestat, "load", refuse)
    assert main(["fk", "arm.toml", "--q", "0"]) == 2
    err = capsys.readouterr().err
    assert err == "kinestat: error: Permission denied: /models/arm.toml\n"


def test_help_and_usage_errors(capsys):
    assert main(["--help"]) == 0
    assert "fk" in capsys.readouterr().out
    assert main(["fk", "puma762", "--no-such-option"]) == 2
