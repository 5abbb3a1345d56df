"""Homing (startup_initialize.m, Vibhute App. D.4) against the simulated DMC (issue 12 item 5)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.app.homing_run import run_home
from kinestat.cli.main import main
from kinestat.control.log import read_log
from kinestat.devices.galil import GalilClient
from kinestat.devices.homing import home, is_homed
from kinestat.hardware.puma762_homing import (
    HOME_COUNTS,
    INDEX_PERIOD_COUNTS,
    SECOND_OFFSET,
    index_layout,
)
from kinestat.sim.dmc import DmcSimulator, SimClock
from kinestat.sim.galil_server import GalilSimServer


def _sim(seed, **kw) -> DmcSimulator:
    return DmcSimulator.unknown_start(seed, clock=SimClock(step_per_command=0.05), **kw)


def test_table_2_1_index_periods_and_the_layout():
    # one motor revolution (Table 2-1, degrees) over the encoder scale (degrees per count)
    rev_deg = np.array([4.0, 2.78, 3.57, 6.26, 6.26, 13.4])
    scale = np.array([0.00125, 0.00086875, 0.001115625, 0.00626, 0.00626, 0.01337])
    np.testing.assert_allclose(rev_deg / scale, INDEX_PERIOD_COUNTS, rtol=3e-3)
    assert DmcSimulator().index_period == tuple(float(p) for p in INDEX_PERIOD_COUNTS)
    phase, ready = index_layout()
    np.testing.assert_array_equal((HOME_COUNTS - SECOND_OFFSET - phase) % INDEX_PERIOD_COUNTS, 0)


def test_homing_from_20_random_start_positions():
    for seed in range(20):
        sim = _sim(seed)
        start = sim.motor_counts()
        with GalilSimServer(controller=sim) as srv, GalilClient("127.0.0.1", srv.port) as g:
            assert not is_homed(g)
            assert g.position_counts() == (0,) * 6  # unknown: encoders read 0 at power-up
            rep = home(g, poll_interval=0)
            assert rep.homed, (seed, rep.stop_reason)
            assert g.position_counts() == tuple(HOME_COUNTS.tolist())
            assert is_homed(g) and sim.homed
        # physically at the same home whatever the start (the index marks are fixed)
        np.testing.assert_array_equal(sim.motor_counts(), HOME_COUNTS)
        assert np.any(np.abs(start - HOME_COUNTS) > 1000)


@pytest.mark.parametrize("inputs, what", [({3: 1}, "VAL controller's power is off"),
                                          ({1: 1}, "arm's power is off")])
def test_failed_power_on_check_moves_nothing(inputs, what):
    sim = _sim(5, inputs=inputs, record=True)
    start = sim.motor_counts()
    with GalilSimServer(controller=sim) as srv, GalilClient("127.0.0.1", srv.port) as g:
        rep = home(g, poll_interval=0)
        assert not rep.homed and what in rep.stop_reason and "MO sent" in rep.stop_reason
        assert g.query("MG _MOA") == 1  # amplifiers off
        assert not is_homed(g)
    np.testing.assert_array_equal(sim.motor_counts(), start)
    assert not any(c.startswith(("BG", "PR", "PA", "FI")) for c in sim.commands)


def test_a_link_drop_while_homing_stops_safely_with_a_complete_log(tmp_path):
    sim = _sim(7, record=True)
    with GalilSimServer(controller=sim) as srv:
        sim.silence_next("FI")  # the link dies at the first index search
        rep = run_home("127.0.0.1", srv.port, tmp_path / "home.jsonl", timeout=0.3)
        recs = read_log(tmp_path / "home.jsonl")
    assert not rep.homed and "device fault" in rep.stop_reason
    assert [r["type"] for r in recs][0] == "start" and recs[-1]["type"] == "end"
    assert any(r["type"] == "fault" for r in recs)
    assert recs[-1]["report"]["homed"] is False
    assert "ST" in sim.commands and sim.commands[-2] == "MO"  # stopped after reconnecting
    assert sim.commands[-1].endswith(",_MOF")  # the proof that the amplifiers are off
    assert not sim.homed


def _json(capsys) -> dict:
    out = capsys.readouterr().out
    return json.loads(out[out.index("{"):])


def test_cli_home_and_control_refuses_an_unhomed_robot(tmp_path, capsys):
    sim = _sim(11, record=True)
    with GalilSimServer(controller=sim) as srv:
        addr = f"127.0.0.1:{srv.port}"
        code = main(["control", "--galil", addr, "--serial", "/dev/null", "--no-plot",
                     "--log", str(tmp_path / "c.jsonl")])
        assert code == 2 and "not homed" in capsys.readouterr().err
        assert not any(c.startswith(("BG", "PA")) for c in sim.commands)
        code = main(["home", "--galil", addr, "--json", "--log", str(tmp_path / "h.jsonl")])
        out = _json(capsys)
        assert code == 0 and out["homed"] and len(out["axes"]) == 6
        assert [a["position"] for a in out["axes"]] == HOME_COUNTS.tolist()
    bad = _sim(12, inputs={3: 1})
    with GalilSimServer(controller=bad) as srv:
        code = main(["home", "--galil", f"127.0.0.1:{srv.port}", "--json", "--log",
                     str(tmp_path / "h2.jsonl")])
        out = _json(capsys)
        assert code == 2 and out["homed"] is False and "input 3" in out["stop_reason"]


def test_the_unhomed_refusal_logs_start_fault_end_and_prints_json(tmp_path, capsys):
    sim = _sim(13, record=True)
    log = tmp_path / "c.jsonl"
    with GalilSimServer(controller=sim) as srv:
        code = main(["control", "--galil", f"127.0.0.1:{srv.port}", "--serial", "/dev/null",
                     "--no-plot", "--json", "--log", str(log)])
    cap = capsys.readouterr()
    assert code == 2 and "not homed" in cap.err
    out = json.loads(cap.out[cap.out.index("{"):])
    assert out["converged"] is False and "not homed" in out["stop_reason"]
    assert out["iterations"] == 0 and out["moves"] == 0
    recs = read_log(log)
    assert [r["type"] for r in recs] == ["start", "fault", "end"]
    assert recs[1]["action"] == "nothing sent" and "not homed" in recs[1]["reason"]
    assert recs[2]["report"]["stop_reason"] == out["stop_reason"]
    assert not any(c.startswith(("BG", "PA", "PR")) for c in sim.commands)
