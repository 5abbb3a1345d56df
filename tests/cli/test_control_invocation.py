"""Issue 11 items 8, 9, 12: `kinestat control` refuses bad invocations before anything starts,
leaves no empty log behind, and names the log when it cannot be written."""

from __future__ import annotations

import socket

import pytest

from kinestat.app.control_run import MAX_ITERATIONS, MAX_SAMPLES
from kinestat.cli.main import main


@pytest.mark.parametrize(("args", "message"), [
    (["--samples", str(MAX_SAMPLES + 1)], f"--samples must be in 1..{MAX_SAMPLES}"),
    (["--samples", "0"], "--samples must be in 1.."),
    (["--max-iterations", str(MAX_ITERATIONS + 1)],
     f"--max-iterations must be in 1..{MAX_ITERATIONS}"),
    (["--max-iterations", "0"], "--max-iterations must be in 1.."),
])
def test_ceilings_are_refused_before_anything_starts(tmp_path, capsys, args, message):
    log = tmp_path / "run" / "log.jsonl"
    assert main(["control", "--log", str(log), "--no-plot", *args]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("error") == 1
    assert not log.exists() and not (tmp_path / "run").exists()


def _free_port() -> int:
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def test_a_refused_galil_connection_leaves_no_log(tmp_path, capsys):
    log = tmp_path / "log.jsonl"
    code = main(["control", "--galil", f"127.0.0.1:{_free_port()}", "--serial", "/dev/null",
                 "--log", str(log), "--no-plot"])
    assert code == 2 and "cannot connect to the Galil" in capsys.readouterr().err
    assert not log.exists()


def test_a_missing_serial_device_leaves_no_log(tmp_path, capsys):
    from kinestat.sim.galil_server import GalilSimServer

    log = tmp_path / "log.jsonl"
    with GalilSimServer() as server:
        code = main(["control", "--galil", f"127.0.0.1:{server.port}", "--serial",
                     str(tmp_path / "no-such-tty"), "--log", str(log), "--no-plot",
                     "--assume-homed"])  # an unhomed robot is refused first (and logged)
    assert code == 2 and "cannot open encoder stream" in capsys.readouterr().err
    assert not log.exists()


def test_plot_onto_an_existing_file_is_refused_before_running(tmp_path, capsys):
    target = tmp_path / "plot.png"
    target.write_text("keep me")
    log = tmp_path / "log.jsonl"
    assert main(["control", "--plot", str(target), "--log", str(log)]) == 2
    err = capsys.readouterr().err
    assert "--plot" in err and "not a directory" in err and err.count("error") == 1
    assert not log.exists() and target.read_text() == "keep me"


def test_an_unwritable_log_is_named(tmp_path, capsys):
    assert main(["control", "--log", "/dev/full", "--no-plot"]) == 2
    err = capsys.readouterr().err
    assert "cycle log '/dev/full'" in err and "No space left" in err
