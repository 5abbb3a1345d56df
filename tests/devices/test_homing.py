"""Homing (startup_initialize.m, Vibhute App. D.4) against the simulated DMC (issue 12 item 5)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.app.homing_run import run_home
from kinestat.cli.main import main
from kinestat.control.log import read_log
from kinestat.devices import homing as homing_mod
from kinestat.devices.galil import GalilClient
from kinestat.devices.homing import home, is_homed
from kinestat.robots.puma762.homing import (
    FIRST_OFFSET,
    HOME_COUNTS,
    INDEX_PERIOD_COUNTS,
    SECOND_OFFSET,
)
from kinestat.robots.puma762.layout import HOME_PAST_INDEX, layout
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
    phase, ready = layout()
    np.testing.assert_array_equal((HOME_COUNTS - HOME_PAST_INDEX - phase) % INDEX_PERIOD_COUNTS,
                                  0)


def _homed_physically(sim: DmcSimulator) -> np.ndarray:
    with GalilSimServer(controller=sim) as srv, GalilClient("127.0.0.1", srv.port) as g:
        rep = home(g, poll_interval=0)
        assert rep.homed, rep.stop_reason  # the read-back passes: DP defines the counts
    return sim.motor_counts()


def _next_mark_ahead(x, p):
    """Where a positive index search starting at ``x`` (counts from a mark) stops."""
    return p * (np.floor_divide(x, p) + 1)


@pytest.mark.parametrize("which", ["first", "second"])
def test_a_restored_minus_sign_ends_away_from_home(monkeypatch, which):
    """The simulated robot's layout is its own (kinestat.robots.puma762.layout), not derived from
    the PA offsets: a minus restored on any offset ends the homing physically away from home,
    by the amount the index periods give (computed here from the search's rule)."""
    sign = np.array([1, -1, 1, -1, 1, -1])  # restore a minus on axes B, D, F
    first, second = FIRST_OFFSET.copy(), SECOND_OFFSET.copy()
    if which == "first":
        first = first * sign
    else:
        second = second * sign
    monkeypatch.setattr(homing_mod, "FIRST_OFFSET", first)
    monkeypatch.setattr(homing_mod, "SECOND_OFFSET", second)
    P = INDEX_PERIOD_COUNTS
    expected = (_next_mark_ahead(first, P) + second) - (_next_mark_ahead(FIRST_OFFSET, P)
                                                         + SECOND_OFFSET)
    end = _homed_physically(_sim(11))
    np.testing.assert_array_equal(end - HOME_COUNTS, expected)
    moved = sign < 0
    if which == "second":
        moved &= SECOND_OFFSET != 0  # axis B's second offset is 0: no sign to restore
    assert np.all(expected[moved] != 0) and np.all(expected[~moved] == 0)


def _margin(offset, p):
    return np.minimum(offset % p, p - offset % p)


@pytest.mark.parametrize("signs", [(1, 1), (-1, 1), (1, -1), (-1, -1)])
def test_every_reading_of_the_signs_homes_a_robot_laid_out_for_it(monkeypatch, signs):
    """Why the seed cannot decide the signs: the second search's margin (its start's distance
    from a mark) is the same for either sign, and each reading homes exactly a robot whose
    marks and pots sit where that reading puts them (its layout computed here)."""
    P = INDEX_PERIOD_COUNTS
    first, second = signs[0] * FIRST_OFFSET, signs[1] * SECOND_OFFSET
    np.testing.assert_array_equal(_margin(first, P), _margin(FIRST_OFFSET, P))
    assert _margin(FIRST_OFFSET, P)[4] == 0  # axis E: 3000 counts, three revolutions
    monkeypatch.setattr(homing_mod, "FIRST_OFFSET", first)
    monkeypatch.setattr(homing_mod, "SECOND_OFFSET", second)
    end = _next_mark_ahead(first, P) + second  # home, counted from the first search's mark
    sim = _sim(3)
    sim.index_phase = tuple(float(v) for v in (HOME_COUNTS - end) % P)
    sim.pot_ready = (HOME_COUNTS - end - P // 2).astype(float)
    np.testing.assert_array_equal(_homed_physically(sim), HOME_COUNTS)


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
