"""The Galil DMC simulator: bind policy, reply formats, profiles, thesis command sequences."""

from __future__ import annotations

import math
import socket

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.devices.galil import GalilClient
from kinestat.errors import InputError
from kinestat.sim.dmc import DmcSimulator, SimClock, trapezoid
from kinestat.sim.galil_server import GalilSimServer, check_bind_address


@pytest.mark.parametrize("host", ["0.0.0.0", "", "::", "8.8.8.8", "192.168.0.84"])
def test_refuses_non_loopback_unless_allowed(host):
    with pytest.raises(InputError, match="allow"):
        GalilSimServer(host, 0)
    check_bind_address(host or "0.0.0.0", allow_remote=True)  # allowed when asked


@pytest.mark.parametrize("host", ["127.0.0.1", "localhost", "127.0.0.2"])
def test_accepts_loopback(host):
    check_bind_address(host, allow_remote=False)


def test_ephemeral_port_and_stop():
    srv = GalilSimServer(port=0).start()
    try:
        assert srv.port > 0
        with GalilClient("127.0.0.1", srv.port, timeout=1) as g:
            assert g.position_counts() == (0,) * 6
    finally:
        srv.stop()
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", srv.port), timeout=0.5)


def raw_exchange(port: int, data: bytes, expect_end: int) -> bytes:
    """Send raw bytes; collect until ``expect_end`` terminators (':' or '?') arrived."""
    with socket.create_connection(("127.0.0.1", port), timeout=2) as s:
        s.sendall(data)
        buf = b""
        while buf.count(b":") + buf.count(b"?") < expect_end:
            chunk = s.recv(1024)
            if not chunk:
                break
            buf += chunk
        return buf


def test_reply_formats():
    with GalilSimServer(controller=DmcSimulator(initial_counts=[1234, -5, 0, 0, 0, 0])) as srv:
        assert raw_exchange(srv.port, b"MG _TPA\r", 1) == b" 1234.0000\r\n:"
        assert raw_exchange(srv.port, b"MG _TPB\r", 1) == b"-5.0000\r\n:"
        assert raw_exchange(srv.port, b"TPA\r", 1) == b" 1234\r\n:"
        assert raw_exchange(srv.port, b"SP 100\r", 1) == b":"
        assert raw_exchange(srv.port, b"SP 100;AC 1000\r", 2) == b"::"
        assert raw_exchange(srv.port, b"XYZ\r", 1) == b"?"
        assert raw_exchange(srv.port, b"TC1\r", 1) == b"1 Unrecognized command\r\n:"
        assert raw_exchange(srv.port, b"SP -1\r", 1) == b"?"
        assert raw_exchange(srv.port, b"TC1\r", 1) == b"6 Number out of range\r\n:"
        assert raw_exchange(srv.port, b"PA 1,2,x\r", 1) == b"?"
        assert raw_exchange(srv.port, b"TC1\r", 1) == b"4 Operand error\r\n:"


def sim_ctrl(**kw) -> tuple[DmcSimulator, SimClock]:
    clock = SimClock()
    return DmcSimulator(clock=clock, **kw), clock


def ok(ctrl: DmcSimulator, cmd: str) -> str:
    reply = ctrl.handle(cmd)
    assert reply is not None and reply.endswith(":"), (cmd, reply)
    return reply[:-1].strip()


def run_until_idle(ctrl, clock, dt=0.001, limit=100.0):
    t0 = clock.now()
    samples = []
    while any(ctrl.moving()):
        samples.append((clock.now(), ctrl.encoder_counts().copy(), ctrl.velocities().copy()))
        clock.advance(dt)
        assert clock.now() - t0 < limit
    return clock.now() - t0, samples


@settings(max_examples=25)
@given(st.floats(1, 50000), st.floats(100, 5000), st.floats(1000, 50000), st.floats(1000, 50000),
       st.booleans())
def test_trapezoid_duration_matches_closed_form(dist, speed, acc, dec, negative):
    d = -dist if negative else dist
    segs = trapezoid(d, speed, acc, dec)
    total = sum(t for t, _ in segs)
    if dist >= speed**2 / (2 * acc) + speed**2 / (2 * dec):  # reaches cruise speed
        expect = dist / speed + speed / (2 * acc) + speed / (2 * dec)
    else:  # triangle
        vp = math.sqrt(2 * dist * acc * dec / (acc + dec))
        expect = vp / acc + vp / dec
    assert total == pytest.approx(expect, rel=1e-9)
    # integrating the segments lands on the target
    x = v = 0.0
    for t, a in segs:
        x += v * t + 0.5 * a * t * t
        v += a * t
    assert x == pytest.approx(d, rel=1e-9, abs=1e-9) and v == pytest.approx(0, abs=1e-6)


def test_profile_sampled_in_sim_time():
    ctrl, clock = sim_ctrl()
    ok(ctrl, "AC 20000,20000,20000,20000,20000,20000")
    ok(ctrl, "DC 10000,10000,10000,10000,10000,10000")
    ok(ctrl, "SP 5000,5000,5000,5000,5000,5000")
    ok(ctrl, "PA 20000,,,,,-300")
    ok(ctrl, "BG")
    duration, samples = run_until_idle(ctrl, clock, dt=0.002)
    # axis A: 20000 counts at 5000 c/s, accel 20000, decel 10000
    assert duration == pytest.approx(20000 / 5000 + 5000 / 40000 + 5000 / 20000, abs=0.003)
    vel = np.array([s[2] for s in samples])
    assert np.max(np.abs(vel)) <= 5000 + 1e-9
    assert ctrl.encoder_counts()[0] == 20000 and ctrl.encoder_counts()[5] == -300
    assert ok(ctrl, "MG _BGA") == "0.0000"


def test_motion_rules():
    ctrl, clock = sim_ctrl()
    ok(ctrl, "SP 1000")
    ok(ctrl, "PA 5000")
    ok(ctrl, "BGA")
    clock.advance(0.5)
    assert ok(ctrl, "MG _BGA") == "1.0000"
    assert ctrl.handle("PA 0") == "?" and ok(ctrl, "TC1").startswith("7 ")
    assert ctrl.handle("BGA") == "?" and ok(ctrl, "TC1").startswith("21 ")
    assert ctrl.handle("DP 0") == "?"
    ok(ctrl, "ST A")
    v = ctrl.velocities()[0]
    x = ctrl.encoder_counts()[0]
    run_until_idle(ctrl, clock)
    # stops within v^2 / (2 DC) (DC default 256000)
    assert ctrl.encoder_counts()[0] == pytest.approx(x + v * v / (2 * 256000), abs=1.0)
    ok(ctrl, "MO")
    assert ctrl.handle("BG") == "?" and ok(ctrl, "TC1").startswith("20 ")
    assert ok(ctrl, "MG _MOA") == "1.0000"


def test_dp_moves_nothing_physically():
    ctrl, _ = sim_ctrl(initial_counts=[10, 20, 30, 40, 50, 60])
    ok(ctrl, "DP ,,,,5000,")
    assert np.allclose(ctrl.encoder_counts(), [10, 20, 30, 40, 5000, 60])
    assert np.allclose(ctrl.true_axis_counts(), [10, 20, 30, 40, 50, 60])


def test_jog_and_find_index():
    ctrl, clock = sim_ctrl(initial_counts=[1000, 0, 0, 0, 0, 0], index_period=4000)
    ok(ctrl, "JG 2000,0,0,0,0,0")
    ok(ctrl, "FI A")
    ok(ctrl, "BG A")
    run_until_idle(ctrl, clock)
    # found the next index mark (motor position 4000) and zeroed the encoder there
    assert ctrl.true_axis_counts()[0] == pytest.approx(4000)
    assert ok(ctrl, "TPA") == "0"
    ok(ctrl, "JG -3000")
    ok(ctrl, "BG A")
    clock.advance(1.0)
    assert ctrl.velocities()[0] == pytest.approx(-3000)
    ok(ctrl, "ST")
    run_until_idle(ctrl, clock)
    assert not any(ctrl.moving())


def test_coupling_seen_only_by_true_position():
    ctrl, clock = sim_ctrl()
    ok(ctrl, "PR 0,0,0,23962,0,0")
    ok(ctrl, "BG")
    run_until_idle(ctrl, clock)
    assert ctrl.encoder_counts()[4] == 0
    assert ctrl.true_axis_counts()[4] == pytest.approx(-11200)
    ctrl2, _ = sim_ctrl(coupling=0.0)
    ok(ctrl2, "PR 0,0,0,23962,0,0")
    assert ctrl2.true_axis_counts()[4] == 0


def test_thesis_startup_sequence_runs():
    """startup_initialize.m's command sequence (Vibhute App. D.4), through the client."""
    clock = SimClock(step_per_command=0.01)
    with GalilSimServer(controller=DmcSimulator(clock=clock)) as srv, \
            GalilClient("127.0.0.1", srv.port) as g:
        for cmd in ["MO", "OP0", "AF 0,0,0,0,0,0", "SH", "OP1", "DP 0,0,0,0,0,0",
                    "AF 0,0,0,0,0,0", "JG 5000,5000,5000,1000,1000,1000", "SH",
                    "AC 2000,2000,2000,400,400,400", "SP 5000,5000,5000,1000,1000,1000",
                    "PR120,-340,55,7,0,-12", "BG"]:
            g.command(cmd)
        assert g.query("MG @IN[3]") == 0
        g.wait_motion_complete(timeout=10, poll_interval=0)
        for cmd in ["JG 1000,1000,1000,200,200,200", "SP 1000,1000,1000,200,200,200", "FI",
                    "BG"]:
            g.command(cmd)
        g.wait_motion_complete(timeout=10, poll_interval=0)
        assert g.position_counts() == (0,) * 6  # every axis zeroed at its index
        g.command("PA 4450, 0, 2000, 810, 975, 2500")
        g.command("BG")
        g.wait_motion_complete(timeout=10, poll_interval=0)
        assert g.position_counts() == (4450, 0, 2000, 810, 975, 2500)
        g.command("DP 0,103597,80672,0,0,0")
        assert g.position_counts() == (0, 103597, 80672, 0, 0, 0)


def test_multiple_clients_and_drop_link():
    with GalilSimServer() as srv:
        a = GalilClient("127.0.0.1", srv.port, timeout=1).connect()
        b = GalilClient("127.0.0.1", srv.port, timeout=1).connect()
        a.define_position([5, 0, 0, 0, 0, 0])
        assert b.axis_position("A") == 5
        srv.drop_link()
        for c in (a, b):
            with pytest.raises(Exception) as exc:
                c.position_counts()
            assert exc.type.__name__ == "DeviceError"


def test_simulator_argument_checks():
    with pytest.raises(InputError):
        DmcSimulator(initial_counts=[0] * 5)
    with pytest.raises(InputError):
        GalilSimServer(port=70000)
    with pytest.raises(InputError):
        SimClock().advance(-1)


# ----------------------------------------------------------------------------- issue 11 item 11


@pytest.mark.parametrize("flag", ["false", "False", 0, 1, None, "yes"])
def test_allow_remote_must_be_a_real_bool(flag):
    with pytest.raises(InputError, match="allow_remote must be True or False"):
        GalilSimServer("0.0.0.0", 0, allow_remote=flag)
    with pytest.raises(InputError, match="allow_remote must be True or False"):
        check_bind_address("127.0.0.1", flag)


def test_the_host_is_resolved_once_and_the_checked_address_is_bound(monkeypatch):
    """A name that resolves to loopback when checked and to 0.0.0.0 later (DNS rebinding)
    must not end up bound to all interfaces."""
    real = socket.getaddrinfo
    calls = []

    def rebinding(host, *a, **k):
        calls.append(host)
        if host == "sim.example" and len(calls) > 1:
            return real("0.0.0.0", *a, **k)
        return real("127.0.0.1" if host == "sim.example" else host, *a, **k)

    monkeypatch.setattr(socket, "getaddrinfo", rebinding)
    srv = GalilSimServer("sim.example", 0).start()
    try:
        assert srv._listener.getsockname()[0] == "127.0.0.1"
        assert calls == ["sim.example"]
    finally:
        srv.stop()


def test_allow_remote_true_binds_all_interfaces_deliberately():
    srv = GalilSimServer("0.0.0.0", 0, allow_remote=True).start()
    try:
        assert srv._listener.getsockname()[0] == "0.0.0.0"
    finally:
        srv.stop()


def test_an_operand_beyond_reach_is_answered_and_the_connection_lives_on():
    """Issue 43: ``MG @IN[<5000 digits>]`` killed the connection's thread (a ValueError from
    the 4300-digit limit); it is a '?' (TC1 6) and the next command is answered."""
    import socket

    with GalilSimServer() as srv, socket.create_connection(("127.0.0.1", srv.port), 2) as s:
        for line, want in ((b"MG @IN[" + b"9" * 5000 + b"]", b"?"), (b"TC1", b"4 Operand error"),
                           (b"MG @IN[3]", b" 0.0000\r\n:")):
            s.sendall(line + b"\r")
            got = b""
            while not got.endswith((b":", b"?")):
                got += s.recv(4096)
            assert got.startswith(want) or want in got, (line[:20], got)
        assert srv.connections == 1
