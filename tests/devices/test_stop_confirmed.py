"""Issue 43 item 1: every stop is proved by the controller's own answer, whatever the wire
does to ST and to its replies (a proxy between the client and the simulator), and the report
says what the controller confirmed."""

from __future__ import annotations

import signal
import time

import numpy as np
import pytest

from kinestat.devices.galil import GalilClient
from kinestat.devices.safe_stop import confirm_stop
from kinestat.sim.dmc import DmcSimulator
from kinestat.sim.galil_server import GalilSimServer
from tests._galil_proxy import GalilProxy

FAR = [400000, 0, 0, 0, 0, 0]  # 40 s at 10000 counts/s: still moving when the stop comes


@pytest.fixture
def cell():
    """A real-time simulator behind a fault-injecting proxy; a client on the proxy."""
    ctrl = DmcSimulator(record=True)
    with GalilSimServer(controller=ctrl) as server, GalilProxy(server.port) as proxy:
        g = GalilClient("127.0.0.1", proxy.port, timeout=0.5).connect()
        try:
            yield ctrl, proxy, g
        finally:
            g.close()


def _moving_then(ctrl, proxy, g, *rules):
    g.move_absolute(FAR, 10000, 100000)
    time.sleep(0.05)
    assert any(ctrl.moving())
    for prefix, action, kw in rules:
        proxy.rule(prefix, action, **kw)


def _assert_truthful(rep, ctrl):
    """Confirmed means the simulated axes are at rest (and were told ST)."""
    assert rep.confirmed, rep.text
    assert rep.text.startswith("ST confirmed by the controller")
    assert not any(ctrl.moving()) and np.all(ctrl.velocities() == 0)
    assert "ST" in ctrl.commands
    assert ctrl.true_axis_counts()[0] < FAR[0] / 2  # stopped, not arrived


@pytest.mark.parametrize(("rules", "fresh"), [
    ([("ST", "lose_reply", {})], False),                       # ST's ':' lost
    ([("ST", "lose", {})], False),                             # ST itself lost: sent again
    ([("ST", "lose", {"times": 3})], False),
    ([("MG", "lose_reply", {})], True),                        # the proof lost: fresh link
    ([("ST", "late", {"delay": 0.3})], False),                 # ST's ':' late
    ([("MG", "late", {"delay": 0.8})], True),                  # the proof too late: fresh link
    ([("ST", "dup", {}), ("MG", "dup", {})], False),           # duplicated replies
    ([("ST", "garble", {})], False),                           # ST's ':' garbled
    ([("MG", "garble", {})], None),  # the proof garbled: the tag (fresh link) or a value
    ([("ST", "drop", {})], True),                              # link cut when ST goes out
    ([("MG", "drop", {})], True),
])
def test_each_wire_fault_ends_in_a_confirmed_stop(cell, rules, fresh):
    ctrl, proxy, g = cell
    _moving_then(ctrl, proxy, g, *rules)
    rep = confirm_stop(g)
    _assert_truthful(rep, ctrl)
    if fresh is None:  # which byte the garble hits depends on how TCP split the reply
        fresh = "on a fresh connection" in rep.text
    assert ("on a fresh connection" in rep.text) == fresh, rep.text
    assert rep.attempts == (2 if fresh else 1)


def test_a_garbled_flag_saying_stopped_cannot_confirm_alone(cell):
    """The adversarial garble: the motion flags of one answer flipped to 0 while the axis
    moves and ST was lost. The second answer must agree before the stop counts."""
    ctrl, proxy, g = cell

    def flags_to_zero(reply: bytes) -> bytes:
        head, *flags = reply[:-3].split(b" 1.0000")
        return head + b" 0.0000" * len(flags) + reply[-3:]

    _moving_then(ctrl, proxy, g, ("ST", "lose", {}), ("MG", "garble", {"garble": flags_to_zero}))
    rep = confirm_stop(g)
    _assert_truthful(rep, ctrl)
    assert proxy.forwarded.count("ST") >= 1 and proxy.lost == ["ST"]


def test_the_late_colon_of_bg_is_never_taken_for_st(cell):
    """The campaign's case: a signal while BG's reply is pending (0.3 s late on the wire),
    then ST lost. The late ':' must not count: ST is repeated until the answer proves it."""
    ctrl, proxy, g = cell
    proxy.rule("BG", "late", delay=0.3)
    proxy.rule("BG", "signal", sig=signal.SIGINT)
    proxy.rule("ST", "lose")
    with pytest.raises(KeyboardInterrupt):
        g.move_absolute(FAR, 10000, 100000)
    assert g._in_flight == "BG"
    rep = confirm_stop(g)
    _assert_truthful(rep, ctrl)
    assert proxy.lost == ["ST"] and "ST" in proxy.forwarded
    assert rep.attempts == 1


def test_a_controller_that_ignores_st_is_reported_moving(cell):
    ctrl, proxy, g = cell
    _moving_then(ctrl, proxy, g)
    ctrl.reject_next("ST", times=10**6)
    t0 = time.monotonic()
    rep = confirm_stop(g, stop_timeout=0.3)
    assert not rep.confirmed and any(ctrl.moving())
    assert rep.text == "ST unconfirmed: axes A still in motion 0.3 s after ST"
    assert time.monotonic() - t0 < 1.5


def test_a_link_gone_for_good_is_reported_unconfirmed_within_bounds():
    ctrl = DmcSimulator()
    server = GalilSimServer(controller=ctrl).start()
    proxy = GalilProxy(server.port).start()
    g = GalilClient("127.0.0.1", proxy.port, timeout=0.5).connect()
    g.move_absolute(FAR, 10000, 100000)
    proxy.stop()  # the link and the way back are gone; the controller still moves
    t0 = time.monotonic()
    rep = confirm_stop(g, reconnect_timeout=0.3)
    dt = time.monotonic() - t0
    server.stop()
    assert not rep.confirmed and rep.text.startswith("ST unconfirmed: the link is gone (")
    assert rep.attempts == 3 and dt < 1.5 and not g.connected


# ----------------------------------------------------------------------------- homing


def test_sigterm_during_the_coarse_move_with_st_lost_is_confirmed_stopped(tmp_path):
    """Homing's case of the campaign: SIGTERM while BG's reply is pending (late on the wire)
    and the first ST lost; the log's fault record says what the controller confirmed."""
    from kinestat.app.homing_run import run_home
    from kinestat.app.signals import stop_on_signals
    from kinestat.control.log import read_log

    sim = DmcSimulator.unknown_start(3, record=True)  # real time: the coarse move takes s
    with GalilSimServer(controller=sim) as srv, GalilProxy(srv.port) as proxy:
        proxy.rule("BG", "late", delay=0.3)
        proxy.rule("BG", "signal", sig=signal.SIGTERM)
        proxy.rule("ST", "lose")
        with stop_on_signals():
            rep = run_home("127.0.0.1", proxy.port, tmp_path / "h.jsonl", samples=2,
                           timeout=1.0)
        moving = any(sim.moving())
    recs = read_log(tmp_path / "h.jsonl")
    fault = [r for r in recs if r["type"] == "fault"]
    assert not rep.homed and rep.stop_reason.startswith("stopped by SIGTERM")
    assert "ST confirmed by the controller" in rep.stop_reason and "MO sent" in rep.stop_reason
    assert len(fault) == 1 and fault[0]["stop_confirmed"] is True
    assert [r["type"] for r in recs][-1] == "end" and not moving
    assert proxy.lost == ["ST"] and sim.commands[-2] == "MO"  # then its proof, MG <tag>,_MOA..
    assert sim.commands[-1].endswith(",_MOA,_MOB,_MOC,_MOD,_MOE,_MOF")
    assert "MO sent and confirmed" in rep.stop_reason
    bg = sim.commands.index("BG")
    assert "ST" in sim.commands[bg:]


def test_a_link_drop_while_homing_is_stopped_on_a_fresh_connection(tmp_path):
    from kinestat.app.homing_run import run_home
    from kinestat.control.log import read_log

    sim = DmcSimulator.unknown_start(4, record=True)
    with GalilSimServer(controller=sim) as srv, GalilProxy(srv.port) as proxy:
        proxy.rule("MG _BG", "drop")  # the first poll of the coarse move cuts the link
        rep = run_home("127.0.0.1", proxy.port, tmp_path / "h.jsonl", samples=2, timeout=0.5)
        moving = any(sim.moving())
    fault = [r for r in read_log(tmp_path / "h.jsonl") if r["type"] == "fault"][0]
    assert not rep.homed and "device fault" in rep.stop_reason
    assert fault["stop_confirmed"] is True and "on a fresh connection" in fault["action"]
    assert not moving and proxy.connections == 2
