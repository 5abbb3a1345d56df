"""`kinestat home` stops the robot on SIGTERM and SIGHUP as on Ctrl-C: ST and MO reach the
controller, the motion stops, the log ends with `fault` and `end`, exit status 2.

The CLI runs as a subprocess (PYTHONPATH = this worktree) against the Galil simulator with an
unknown start (`DmcSimulator.unknown_start`, what `kinestat sim galil --seed N` runs), served
in this process so that the test sees the commands and the motors."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from kinestat.control.log import read_log
from kinestat.sim.dmc import DmcSimulator
from kinestat.sim.galil_server import GalilSimServer
from tests.cli._cell_helpers import wait_until

ROOT = Path(__file__).resolve().parents[2]


_wait = wait_until


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_during_the_coarse_move_stops_the_robot(tmp_path, sig):
    sim = DmcSimulator.unknown_start(3, record=True)
    log = tmp_path / "home.jsonl"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    with GalilSimServer(controller=sim) as srv:
        proc = subprocess.Popen([sys.executable, "-m", "kinestat.cli.main", "home", "--galil",
                                 f"127.0.0.1:{srv.port}", "--log", str(log), "--samples", "5"],
                                cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        try:
            _wait(lambda: (any(c.startswith("PR") for c in sim.commands) and any(sim.moving()))
                  or proc.poll() is not None, 60, "the coarse move")
            assert proc.poll() is None, proc.communicate()
            assert not any(c.startswith("FI") for c in sim.commands)  # still the coarse move
            proc.send_signal(sig)
            out, err = proc.communicate(timeout=30)
        finally:
            if proc.poll() is None:
                proc.kill()
        _wait(lambda: not any(sim.moving()), 10, "the motion to stop")
        commands = list(sim.commands)
        stopped_at = sim.motor_counts().copy()
        time.sleep(0.3)
        still = sim.motor_counts()
    assert proc.returncode == 2, err
    assert "ST" in commands and commands[-2] == "MO" and commands[-1].endswith(",_MOF")
    assert commands.index("ST") > max(i for i, c in enumerate(commands) if c == "BG")
    np.testing.assert_array_equal(still, stopped_at)  # no unsupervised motion afterwards
    assert not sim.homed
    recs = read_log(log)
    kinds = [r["type"] for r in recs]
    assert kinds[0] == "start" and kinds[-2:] == ["fault", "end"], kinds
    assert recs[-2]["reason"] == f"stopped by {sig.name}"
    assert "ST confirmed by the controller" in recs[-2]["action"]
    assert "MO sent" in recs[-2]["action"]
    assert recs[-2]["stop_confirmed"] is True
    assert recs[-1]["report"]["homed"] is False
    assert err.count(f"stopped by {sig.name}") == 1 and err.startswith("kinestat: error:")


def test_a_refused_connection_is_reported_once(tmp_path, capsys):
    from kinestat.cli.main import main

    code = main(["home", "--galil", "127.0.0.1:1", "--log", str(tmp_path / "h.jsonl")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("Connection refused") == 1 and err.count("nothing sent") == 1, err
    assert err.startswith("kinestat: error:") and err.count("\n") == 1, err


@pytest.mark.parametrize("n", ["0", "1001", "100000000"])
def test_home_samples_has_a_ceiling(tmp_path, capsys, n):
    from kinestat.cli.main import main

    code = main(["home", "--galil", "127.0.0.1:1", "--samples", n, "--log",
                 str(tmp_path / "h.jsonl")])
    err = capsys.readouterr().err
    assert code == 2 and "--samples must be in 1..1000" in err
    assert not (tmp_path / "h.jsonl").exists()  # refused before anything starts
