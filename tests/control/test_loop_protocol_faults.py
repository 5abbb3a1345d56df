"""Issue 11: protocol faults and the final command's envelope, through the whole loop over
the simulated devices (real client and reader, TCP loopback and a pty)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from kinestat.app.sim_cell import SimHarness, start_counts
from kinestat.control.envelope import Envelope, check_sent_counts, sent_command_guard
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import run
from kinestat.devices.cell_io import DeviceIO, MotionProfile
from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX, GalilClient
from kinestat.errors import SafetyStop
from kinestat.hardware.puma762_axes import AXIS4_TO_5_COUPLING, AXIS_DEG_PER_COUNT
from kinestat.sim.dmc import DmcSimulator
from kinestat.sim.galil_server import GalilSimServer

from .conftest import scenario

FAST = MotionProfile(speed=tuple(20 * np.asarray(THESIS_SPEED_MAX)),
                     accel=tuple(400 * np.asarray(THESIS_ACCEL)))
COUPLED = -11200.0 / 23962.0


def _run(tmp_path, inject, at_cycle=2):
    scn = scenario(coupling=COUPLED)
    cfg = scn.config()
    path = tmp_path / "log.jsonl"
    with SimHarness(scn.cell, scn.sensor, start_counts=start_counts(cfg), record=True) as h:
        io = h.device_io(profile=FAST, client_timeout=0.5,
                         guard=sent_command_guard(cfg.envelope, cfg.model))
        marks = {}

        def progress(rec):
            if rec["cycle"] == at_cycle:
                marks["n"] = len(h.controller.commands)
                inject(h, io)

        with CycleLog(path) as log:
            rep = run(cfg, io, log, progress=progress)
        commands = list(h.controller.commands)
    return rep, read_log(path), commands, marks.get("n"), scn


def _pa_within_envelope(commands, scn, start):
    """Every PA sent: inside the axis limits and <= 30° from the previous one."""
    lo, hi = scn.model.limits_deg.T
    prev = np.asarray(start, dtype=float)
    for c in commands:
        if c.startswith("PA"):
            counts = np.array([float(v) for v in c[2:].split(",")])
            deg = counts * AXIS_DEG_PER_COUNT
            assert np.all((deg >= lo) & (deg <= hi)), c
            assert np.max(np.abs(counts - prev) * AXIS_DEG_PER_COUNT) <= 30.0, c
            prev = counts


def _assert_stopped_with_complete_log(rep, recs):
    kinds = [r["type"] for r in recs]
    assert kinds[0] == "start" and kinds[-2:] == ["fault", "end"]
    assert not rep.converged and recs[-1]["report"]["stop_reason"] == rep.stop_reason


def _wait_for_bytes(io):
    import select

    assert select.select([io.client._sock], [], [], 1.0)[0]


def test_stale_reply_before_a_command_stops_the_loop(tmp_path):
    def inject(h, io):
        h.server.send_unsolicited(b" 0.0000\r\n:")
        _wait_for_bytes(io)

    rep, recs, commands, n, scn = _run(tmp_path, inject)
    _assert_stopped_with_complete_log(rep, recs)
    assert "stale or unsolicited reply" in rep.stop_reason
    assert "ST confirmed by the controller" in rep.stop_reason
    assert "on a fresh connection" in rep.stop_reason
    after = commands[n:]
    # nothing but the stop (ST and its proof, MG <tag>,_BGA..) once the stale bytes were there
    assert after[0] == "ST" and all(c == "ST" or c.endswith(",_BGA,_BGB,_BGC,_BGD,_BGE,_BGF")
                                    for c in after)
    _pa_within_envelope(commands, scn, start_counts(scn.config()))


def test_stale_reply_queued_ahead_of_an_answer_stops_the_loop(tmp_path):
    rep, recs, commands, n, scn = _run(tmp_path, lambda h, io: h.server.stale_before_next("TP"))
    _assert_stopped_with_complete_log(rep, recs)
    assert "out of step" in rep.stop_reason or "after the reply" in rep.stop_reason
    assert not any(c.startswith(("PA", "DP")) for c in commands[n:])
    assert [c for c in commands if not c.endswith(",_BGF")][-1] == "ST"  # then its proof
    _pa_within_envelope(commands, scn, start_counts(scn.config()))


def test_unsolicited_reply_during_the_motion_stops_the_loop(tmp_path):
    """An unsolicited ':' arrives while the axes move (between two polls)."""
    def inject(h, io):
        real_poll = io.reader.poll

        def poll():
            if not getattr(poll, "done", False):
                poll.done = True
                h.server.send_unsolicited(b":")
                _wait_for_bytes(io)
            return real_poll()

        io.reader.poll = poll

    rep, recs, commands, n, scn = _run(tmp_path, inject)
    _assert_stopped_with_complete_log(rep, recs)
    assert "unexpected" in rep.stop_reason
    assert [c for c in commands if not c.endswith(",_BGF")][-1] == "ST"  # then its proof
    assert not any(c.startswith("DP") for c in commands[n:])
    _pa_within_envelope(commands, scn, start_counts(scn.config()))


def test_the_final_compensated_command_goes_through_the_envelope(tmp_path):
    """A wrong axis-4 reading (here: a read-back of 0 for axis D, as the campaign's stale
    reply produced) would compensate axis 5 by tens of degrees: the guard refuses it and
    nothing is sent."""
    scn = scenario(coupling=COUPLED)
    cfg = scn.config()
    c0 = start_counts(cfg)
    with SimHarness(scn.cell, scn.sensor, start_counts=c0, record=True) as h:
        io = h.device_io(profile=FAST, guard=sent_command_guard(cfg.envelope, cfg.model))
        real = io.client.position_counts

        def wrong_d():
            c = list(real())
            c[3] = 0
            return tuple(c)

        io.client.position_counts = wrong_d
        with pytest.raises(SafetyStop, match="final command"):
            io.move(c0)
        assert not any(c.startswith(("PA", "BG")) for c in h.controller.commands)


def test_check_sent_counts_measures_the_axis5_motor_step():
    scn = scenario(coupling=COUPLED)
    model, env = scn.model, Envelope()
    now = np.array([0, 0, 0, 8000, 0, 0])
    ok = now.copy()
    assert check_sent_counts(env, model, ok, now) == []
    jump = now.copy()
    jump[4] = -8100  # 50.7° on axis 5
    bad = check_sent_counts(env, model, jump, now)
    assert len(bad) == 1 and "axis 5 would move 50.706°" in bad[0]


def test_tcp_drop_mid_move_sends_st_on_a_fresh_connection_and_stops_the_controller():
    """The link drops while the axes move; the controller itself is alive: ST goes out on a
    fresh connection and the simulator's motion stops short of the target."""
    ctrl = DmcSimulator(record=True)  # real time
    with GalilSimServer(controller=ctrl) as server:
        client = GalilClient("127.0.0.1", server.port, timeout=0.5).connect()

        class Reader:
            polls = 0

            def poll(self):
                Reader.polls += 1
                if Reader.polls == 20:
                    server.drop_link()
                time.sleep(0.002)
                return []

        io = DeviceIO(client, Reader(), profile=MotionProfile(speed=(8000.0,) * 6,
                                                              accel=(80000.0,) * 6),
                      coupling=AXIS4_TO_5_COUPLING)
        target = np.array([16000, 0, 0, 0, 0, 0])
        with pytest.raises(Exception, match="closed the link|failed"):
            io.move(target)
        assert any(ctrl.moving())
        t0 = time.monotonic()
        what = io.stop()
        latency = time.monotonic() - t0
        assert what.confirmed and "on a fresh connection" in what.text, what
        assert latency < 0.5 and "ST" in ctrl.commands
        assert not any(ctrl.moving())  # confirmed: at rest already
        assert server.true_axis_counts()[0] < 16000 - 2000
        client.close()


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_while_bg_is_pending_and_st_lost_ends_in_a_confirmed_stop(tmp_path, sig):
    """Issue 43, the control path: the signal arrives while the loop waits for BG's reply (late
    on the wire, through a proxy) and the first ST is lost. The late ':' of BG is not taken for
    ST's; the fault record says what the controller confirmed."""
    import signal as signals

    from kinestat.app.signals import stop_on_signals
    from kinestat.app.sim_cell import SimCheckedReader
    from tests._galil_proxy import GalilProxy

    scn = scenario(coupling=COUPLED)
    cfg = scn.config()
    path = tmp_path / "log.jsonl"
    with SimHarness(scn.cell, scn.sensor, start_counts=start_counts(cfg), record=True) as h, \
            GalilProxy(h.server.port) as proxy:
        client = GalilClient("127.0.0.1", proxy.port, timeout=1.0).connect()
        reader = SimCheckedReader(h.reader(), h.emitter)
        io = DeviceIO(client, reader, truth=h.truth, settle=2.5 / h.emitter.rate_hz,
                      guard=sent_command_guard(cfg.envelope, cfg.model))

        def progress(rec):
            if rec["cycle"] == 2:
                proxy.rule("BG", "late", delay=0.3)
                proxy.rule("BG", "signal", sig=getattr(signals, sig))
                proxy.rule("ST", "lose")

        with stop_on_signals(), CycleLog(path) as log:
            rep = run(cfg, io, log, progress=progress)
        moving = any(h.controller.moving())
        commands = list(h.controller.commands)
        client.close()
    recs = read_log(path)
    _assert_stopped_with_complete_log(rep, recs)
    fault = recs[-2]
    assert fault["reason"] in ("interrupted by the user", f"stopped by {sig}")
    assert fault["stop_confirmed"] is True, fault
    assert fault["action"].startswith("ST confirmed by the controller")
    assert proxy.lost == ["ST"] and not moving
    last_bg = max(i for i, c in enumerate(commands) if c == "BG")
    assert "ST" in commands[last_bg:]
