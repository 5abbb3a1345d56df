"""``kinestat sim galil`` and ``kinestat sim encoders``."""

from __future__ import annotations

import json
import os
import threading
import time

import pytest

from kinestat.cli.main import main
from kinestat.devices.encoder_stream import EncoderReader
from kinestat.devices.galil import GalilClient


def run_in_thread(argv):
    result = {}

    def target():
        result["rc"] = main(argv)

    t = threading.Thread(target=target, daemon=True)
    t.start()
    return t, result


def wait_json(capsys, timeout=10.0):
    """Collect stdout until it parses as one JSON object (bounded)."""
    out = ""
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        out += capsys.readouterr().out
        try:
            return json.loads(out)
        except json.JSONDecodeError:
            time.sleep(0.02)
    pytest.fail(f"no JSON on stdout: {out!r}")


def test_sim_galil_serves_and_stops(capsys):
    t, result = run_in_thread(["sim", "galil", "--json", "--duration", "1.0",
                               "--initial-counts", "1,2,3,4,5,6"])
    info = wait_json(capsys)
    assert info["host"] == "127.0.0.1" and info["port"] > 0
    with GalilClient(info["host"], info["port"], timeout=1) as g:
        assert g.position_counts() == (1, 2, 3, 4, 5, 6)
    t.join(10)
    assert not t.is_alive() and result["rc"] == 0


def test_sim_galil_human_output(capsys):
    assert main(["sim", "galil", "--duration", "0.05"]) == 0
    out = capsys.readouterr().out
    assert "listening on 127.0.0.1:" in out and "stopped" in out


def test_sim_galil_refuses_remote_bind(capsys):
    assert main(["sim", "galil", "--host", "0.0.0.0", "--duration", "0"]) == 2
    err = capsys.readouterr().err
    assert "refusing" in err and "--allow-remote" in err


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs a pseudo-terminal")
def test_sim_encoders_streams_counts(capsys):
    t, result = run_in_thread(["sim", "encoders", "--json", "--duration", "1.0", "--rate", "200",
                               "--counts", "10,20,30,40,50,60"])
    info = wait_json(capsys)
    assert info["channel_counts"]["A"] == 20  # leg 2 on channel A (thesis wiring)
    with EncoderReader(info["path"], stale_after=0.5) as rd:
        assert rd.read().counts.tolist() == [10, 20, 30, 40, 50, 60]
    t.join(10)
    assert not t.is_alive() and result["rc"] == 0


@pytest.mark.parametrize("argv, msg", [
    (["sim", "encoders", "--format", "xml", "--duration", "0"], "--format"),
    (["sim", "encoders", "--counts", "1,2,3", "--duration", "0"], "--counts"),
    (["sim", "encoders", "--counts", "1.5,2,3,4,5,6", "--duration", "0"], "integers"),
    (["sim", "encoders", "--rate", "0", "--duration", "0"], "--rate"),
    (["sim", "galil", "--initial-counts", "1,2", "--duration", "0"], "--initial-counts"),
])
def test_sim_bad_options(capsys, argv, msg):
    assert main(argv) == 2
    assert msg in capsys.readouterr().err


@pytest.mark.parametrize("argv, msg", [
    # a bad --duration used to be noticed only after the server/emitter had started and
    # printed its address
    (["sim", "galil", "--duration", "-1"], "--duration"),
    (["sim", "encoders", "--duration", "-1"], "--duration"),
    # counts beyond 32 bits used to start the emitter, warn from NumPy, then fail late
    (["sim", "encoders", "--counts", "1e11,0,0,0,0,0", "--duration", "0"], "signed 32-bit"),
        (["sim", "encoders", "--counts", "1e30,0,0,0,0,0", "--duration", "0"], "implausibly large"),
    # the Galil simulator took fractional or out-of-range encoder counts
    (["sim", "galil", "--initial-counts", "1.5,0,0,0,0,0", "--duration", "0"], "integers"),
    (["sim", "galil", "--initial-counts", "3e9,0,0,0,0,0", "--duration", "0"], "signed 32-bit"),
])
def test_sim_options_checked_before_starting(capsys, argv, msg):
    assert main(argv) == 2
    out = capsys.readouterr()
    assert msg in out.err and len(out.err.splitlines()) == 1
    assert out.out == ""  # nothing was started


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs a pseudo-terminal")
def test_sim_galil_plant_mujoco_serves_the_galil_and_the_legs_of_one_cell(capsys):
    pytest.importorskip("mujoco")
    t, result = run_in_thread(["sim", "galil", "--plant", "mujoco", "--json", "--duration",
                               "3.0"])
    info = wait_json(capsys, timeout=60.0)
    assert info["plant"] == "mujoco"
    host, port = info["galil"].rsplit(":", 1)
    with GalilClient(host, int(port), timeout=2) as g:
        counts = g.position_counts()
    assert any(c != 0 for c in counts)  # the robot at the start pose of the default cell
    with EncoderReader(info["serial"], stale_after=1.0) as rd:
        legs = rd.read().counts
    assert legs.shape == (6,)
    t.join(30)
    assert not t.is_alive() and result["rc"] == 0


@pytest.mark.parametrize("argv, msg", [
    (["sim", "galil", "--plant", "bullet", "--duration", "0"], "--plant must be"),
    (["sim", "galil", "--plant", "mujoco", "--seed", "3", "--duration", "0"], "do not apply"),
    (["sim", "galil", "--friction", "0.3", "--duration", "0"], "options of --plant mujoco"),
])
def test_sim_galil_plant_refuses_bad_input(capsys, argv, msg):
    assert main(argv) == 2
    assert msg in capsys.readouterr().err
