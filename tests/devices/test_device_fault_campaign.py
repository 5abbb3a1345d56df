"""The hardware path's safety contract under injected faults (scripts/device_fault_campaign.py,
tests/_fault_injector.py): every wire fault, stream fault or signal during `kinestat control`'s
press and `kinestat home` ends with ST received by the simulated DMC after it and a complete
log whose last record says why; every PA stays in the joint limits; good-but-odd replies (split
byte by byte, padded with blanks) are accepted. One seeded case per fault class."""

from __future__ import annotations

import importlib.util
import signal
import sys
from pathlib import Path

import pytest

from kinestat.app.homing_run import run_home
from kinestat.app.signals import stop_on_signals
from kinestat.control.log import read_log
from kinestat.sim.dmc import DmcSimulator, SimClock
from kinestat.sim.galil_server import GalilSimServer
from tests._fault_injector import GOOD_WIRE, STREAM_FAULTS, WIRE_FAULTS, FaultProxy

_path = Path(__file__).resolve().parents[2] / "scripts" / "device_fault_campaign.py"
_spec = importlib.util.spec_from_file_location("device_fault_campaign", _path)
campaign = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = campaign
_spec.loader.exec_module(campaign)


def _clean(case: dict) -> None:
    assert case["fired"], case  # the fault reached the run
    assert case["violations"] == [], case
    if case["kind"] in GOOD_WIRE:
        assert case["converged"] and not case["faulted"], case


@pytest.mark.parametrize("kind", WIRE_FAULTS + GOOD_WIRE)
def test_press_wire_fault(tmp_path, kind):
    case = campaign.press_case(kind, 40, seed=7, tmp=tmp_path)
    _clean(case)
    if kind not in GOOD_WIRE:
        assert case["faulted"] and "ST confirmed by the controller" in case["reason"], case


@pytest.mark.parametrize("kind", STREAM_FAULTS)
def test_press_stream_fault(tmp_path, kind):
    """A damaged encoder stream is either tolerated (a checksum, sequence or framing fault
    counted, the sample taken from good frames) or stops the run; never a silent bad move."""
    case = campaign.press_case(kind, 8, seed=7, tmp=tmp_path)
    _clean(case)
    if kind == "stall":  # 1.5 times the reader's staleness limit: the run must stop on it
        assert case["faulted"] and "stale encoder data" in case["reason"], case


def test_press_count_jump_inside_the_sample_stops(tmp_path):
    """Frames in sequence with a valid checksum whose counts jumped by 2^30, while the loop
    samples: the run stops (ST confirmed) rather than measuring through them, and the stop
    names the leg counts (checked against the legs' deflection limit before the platform's
    kinematics), not a failed assembly."""
    case = campaign.press_case("jump", 1, seed=7, tmp=tmp_path)
    _clean(case)
    assert case["faulted"] and "ST confirmed" in case["reason"], case
    assert "leg counts outside the envelope" in case["reason"], case


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_press_signal(tmp_path, sig):
    case = campaign.press_case(sig, 0.1, seed=7, tmp=tmp_path)
    _clean(case)
    assert case["faulted"], case


@pytest.mark.parametrize("kind", WIRE_FAULTS + GOOD_WIRE)
def test_homing_wire_fault(tmp_path, kind):
    case = campaign.home_case(kind, 300, seed=7, tmp=tmp_path)
    _clean(case)
    if kind not in GOOD_WIRE:
        assert case["faulted"] and "MO sent" in case["reason"], case


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_homing_signal_during_the_stop_of_a_fault(tmp_path, sig):
    """The campaign's violation: a '?' to a motion poll stops the homing, and the run's first
    signal arrives as its ST goes out. Before the fix the KeyboardInterrupt escaped
    confirm_stop: the stop was cut short and the log had neither its fault nor its end."""
    sim = DmcSimulator.unknown_start(5, clock=SimClock(step_per_command=0.05), record=True)
    log = tmp_path / "h.jsonl"
    with GalilSimServer(controller=sim) as srv, FaultProxy(srv.port, seed=1) as proxy:
        proxy.arm("qmark", 1, prefix="MG _BG")
        proxy.rule("ST", "signal", sig=sig)
        with stop_on_signals() as signals:
            rep = run_home("127.0.0.1", proxy.port, log, samples=2, timeout=0.4)
        moving = any(sim.moving())
    assert [name for name, _ in signals.received] == [sig.name]
    recs = read_log(log)
    assert recs[0]["type"] == "start" and recs[-1]["type"] == "end"
    faults = [r for r in recs if r["type"] == "fault"]
    assert len(faults) == 1 and faults[0]["stop_confirmed"] is True, faults
    assert faults[0]["reason"].startswith("device fault: Galil rejected 'MG _BG")
    assert not rep.homed and "MO sent and confirmed" in rep.stop_reason
    after = sim.commands[sim.commands.index(proxy.fired):]
    assert "ST" in after and "MO" in after and not moving


def test_homing_accepts_every_reply_split_or_padded(tmp_path):
    """Good input is never refused: the replies to the power-on checks, the pots and the
    coarse move's start (the first 150 commands) split into one-byte TCP segments, then padded
    with blanks."""
    for kind in GOOD_WIRE:
        sim = DmcSimulator.unknown_start(6, clock=SimClock(step_per_command=0.05))
        with GalilSimServer(controller=sim) as srv, FaultProxy(srv.port) as proxy:
            proxy.arm(kind, 1, span=150)
            rep = run_home("127.0.0.1", proxy.port, tmp_path / f"{kind}.jsonl", samples=1,
                           timeout=2.0)
        assert rep.homed, (kind, rep.stop_reason)
        assert proxy._count >= 150


@pytest.mark.parametrize("kind", GOOD_WIRE)
def test_the_stop_is_proved_through_split_or_padded_replies(tmp_path, kind):
    """Good input during the stop itself: TP rejected mid-run, every reply (the stop's tagged
    proof included) split byte by byte or padded; the stop is still confirmed."""
    case = {}

    def reject_tp(h, proxy):
        proxy.arm(kind, 1, span=10**6)
        h.server.reject_next("TP", times=1)
        case["proxy"] = proxy

    rep, recs = campaign.press_with(reject_tp, tmp_path)
    assert recs[-1]["type"] == "end" and recs[-2]["type"] == "fault"
    assert recs[-2]["stop_confirmed"] is True and "rejected 'TP'" in rep.stop_reason
    assert case["proxy"].fired is not None
