"""Issue 11 item 2-3: one stale or unsolicited reply must never desynchronise the Galil client,
and ST is retried once on a fresh connection when the link failed."""

from __future__ import annotations

import time

import numpy as np
import pytest

from kinestat.devices.galil import GalilClient
from kinestat.devices.galil_replies import expects_data, match_reply, split_reply
from kinestat.devices.motion_check import check_arrival
from kinestat.devices.safe_stop import send_stop
from kinestat.errors import DeviceError, ProtocolError
from kinestat.sim.dmc import DmcSimulator
from kinestat.sim.galil_server import GalilSimServer


def _wait_for_bytes(client: GalilClient, timeout: float = 1.0) -> None:
    """Block until the server's unsolicited bytes are in the client's socket."""
    import select

    r, _, _ = select.select([client._sock], [], [], timeout)
    assert r, "the injected bytes did not arrive"


@pytest.mark.parametrize(("cmd", "reply", "ok"), [
    ("MG _TPD", b" 12.0000\r\n:", True),
    ("MG _TPD", b":", False),          # a stale acknowledgement taken for the answer
    ("AC 1,2,3,4,5,6", b":", True),
    ("AC 1,2,3,4,5,6", b" 1234.0000\r\n:", False),  # a position taken for the ack
    ("TP", b" 1, 2, 3, 4, 5, 6\r\n:", True),
    ("BG", b"?", True),
    ("BG", b" 0.0000\r\n?", False),
])
def test_reply_kind_must_fit_the_command(cmd, reply, ok):
    if ok:
        match_reply(cmd, reply)
    else:
        with pytest.raises(ProtocolError, match="out of step"):
            match_reply(cmd, reply)


def test_split_reply_takes_exactly_one_reply():
    assert split_reply(b" 1.0") is None
    assert split_reply(b":: 2.0000\r\n:") == (b":", b": 2.0000\r\n:")
    assert expects_data("TC1") and expects_data("MG _BGA") and not expects_data("ST")


def test_stale_reply_waiting_in_the_socket_is_a_fault_not_an_answer(sim, client):
    """The campaign's case: a stale ' 0.0000\\r\\n:' before 'MG _TPD'. Before the fix the
    client took 0 for axis D's position."""
    client.define_position([0, 0, 0, 8000, 100, 0])
    assert sim.send_unsolicited(b" 0.0000\r\n:") == 1
    _wait_for_bytes(client)
    with pytest.raises(ProtocolError, match="waiting before 'MG _TPD'"):
        client.axis_position("D")
    assert not client.connected  # the link is out of step: closed, reconnect to go on
    client.connect()
    assert client.axis_position("D") == 8000


def test_stale_reply_queued_ahead_of_the_answer_is_refused(sim, client):
    client.define_position([0, 0, 0, 8000, 100, 0])
    sim.stale_before_next("MG _TPD")  # ' 0.0000\r\n:' then the real ' 8000.0000\r\n:'
    with pytest.raises(ProtocolError, match="after the reply"):
        client.axis_position("D")
    sim.stale_before_next("AC")       # the campaign's 'AC' taking a position for its ack
    client.connect()
    with pytest.raises(ProtocolError):
        client.move_absolute([0] * 6, 1000, 10000)
    assert not any(c.startswith("PA") for c in sim.controller.commands)


def test_compensated_move_with_a_stale_reply_never_commands_the_wrong_axis5(sim, client):
    """The 50.7° jump of the campaign cannot happen: nothing after the stale reply is sent."""
    client.define_position([0, 0, 0, 8000, 100, 0])
    sim.controller.commands.clear()
    sim.send_unsolicited(b" 0.0000\r\n:")
    _wait_for_bytes(client)
    with pytest.raises(ProtocolError):
        client.move_compensated([0, 0, 0, 8000, 100, 0], 5000, 50000, poll_interval=0)
    assert not any(c.startswith(("PA", "BG", "DP")) for c in sim.controller.commands)


def test_unsolicited_acknowledgement_between_commands(sim, client):
    client.position_counts()
    sim.send_unsolicited(b":")
    _wait_for_bytes(client)
    with pytest.raises(ProtocolError, match="unsolicited"):
        client.command("SH")


def test_stop_discards_pending_bytes_and_still_stops(sim, client):
    client.command("JG 1000")
    client.command("BG A")
    sim.send_unsolicited(b" 5.0000\r\n:")
    _wait_for_bytes(client)
    client.stop()
    assert sim.controller.commands[-1] == "ST"


def test_check_arrival_names_the_axes():
    check_arrival([0, 100, 0, 0, 0, 0], [1, 98, 0, 0, 0, 0])
    with pytest.raises(DeviceError, match="axis E read 50, commanded 0"):
        check_arrival([0] * 6, [0, 0, 0, 0, 50, 0])


def test_compensated_move_that_stops_short_is_not_hidden_by_dp(sim, client):
    """A move that ends away from its target (here: an ST from elsewhere) raises, and the
    axis-5 encoder is NOT redefined."""
    ctrl = sim.controller
    real_is_moving = client.is_moving
    calls = []

    def is_moving():
        calls.append(1)
        if len(calls) == 3:
            ctrl.handle("ST")  # another party stops the motion mid-way
        return real_is_moving()

    client.is_moving = is_moving
    with pytest.raises(DeviceError, match="disagree with the command"):
        client.move_compensated([20000, 0, 0, 0, 0, 0], 5000, 50000, poll_interval=0)
    assert not any(c.startswith("DP") for c in ctrl.commands)


# ----------------------------------------------------------------------------- ST on a fresh link


def test_st_on_a_fresh_connection_after_a_drop_stops_the_live_controller():
    ctrl = DmcSimulator(record=True)  # real time: the motion is really under way
    with GalilSimServer(controller=ctrl) as server, \
            GalilClient("127.0.0.1", server.port, timeout=0.5) as g:
        g.move_absolute([40000, 0, 0, 0, 0, 0], 10000, 100000)
        time.sleep(0.05)
        server.drop_link()
        with pytest.raises(DeviceError):
            g.is_moving()
        assert not g.connected and any(ctrl.moving())
        t0 = time.monotonic()
        what = send_stop(g)
        dt = time.monotonic() - t0
        assert what.confirmed and "on a fresh connection (the link was down)" in what.text
        # deceleration at 100000 counts/s^2 from <= 10000 counts/s: 0.1 s, then the proof
        assert dt < 0.5 and "ST" in ctrl.commands
        assert not any(ctrl.moving())
        assert server.true_axis_counts()[0] < 40000 - 1000  # stopped well short of the target
        assert np.all(ctrl.velocities() == 0)


def test_st_reports_accurately_when_the_controller_is_gone():
    ctrl = DmcSimulator()
    server = GalilSimServer(controller=ctrl).start()
    g = GalilClient("127.0.0.1", server.port, timeout=0.5).connect()
    server.stop()
    with pytest.raises(DeviceError):
        g.position_counts()
    t0 = time.monotonic()
    what = send_stop(g, reconnect_timeout=0.3)
    assert not what.confirmed
    assert what.text.startswith("ST unconfirmed: the link is gone (fresh connection: cannot "
                                "connect")
    assert time.monotonic() - t0 < 1.0 and not g.connected


def _delaying_server(delay_for: bytes, delay: float):
    """A TCP server answering like a DMC (':' for commands, ' 1.0000\\r\\n:' for MG), late for
    ``delay_for``; returns (listener, received commands)."""
    import socket
    import threading

    lst = socket.socket()
    lst.bind(("127.0.0.1", 0))
    lst.listen(1)
    got: list[bytes] = []

    def serve():
        conn, _ = lst.accept()
        buf = b""
        with conn:
            while True:
                chunk = conn.recv(1024)
                if not chunk:
                    return
                buf += chunk
                while b"\r" in buf:
                    cmd, buf = buf.split(b"\r", 1)
                    got.append(cmd)
                    if cmd == delay_for:
                        time.sleep(delay)
                    conn.sendall(b" 1.0000\r\n:" if cmd.startswith(b"MG") else b":")

    threading.Thread(target=serve, daemon=True).start()
    return lst, got


def test_an_interrupted_exchange_never_shifts_the_replies():
    """A signal (KeyboardInterrupt) while waiting for 'MG _BGA': its reply comes later. ST must
    skip it (and be acknowledged by its own ':'); any other command refuses to go on."""
    lst, got = _delaying_server(b"MG _BGA", 0.1)
    with GalilClient("127.0.0.1", lst.getsockname()[1], timeout=1.0) as g:
        real = g._receive

        def interrupted(cmd, buf=b""):
            g._receive = real
            raise KeyboardInterrupt

        g._receive = interrupted
        with pytest.raises(KeyboardInterrupt):
            g.is_moving()
        g.stop()  # reads the late ' 1.0000\r\n:' first, then ST's own ':'
        assert got[-1] == b"ST" and g.connected
        g._in_flight = "MG _BGA"  # as if interrupted again
        with pytest.raises(ProtocolError, match="never read"):
            g.command("SH")
    lst.close()
