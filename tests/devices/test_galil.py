"""Galil DMC client and the thesis's axis conventions (against the simulator and fake servers)."""

from __future__ import annotations

import math
import socket
import threading

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from kinestat.devices.cell_io import DeviceIO
from kinestat.devices.galil import (
    THESIS_ACCEL,
    THESIS_SPEED_MAX,
    GalilClient,
    GalilCommandError,
    parse_number,
    parse_numbers,
    thesis_move_plan,
)
from kinestat.errors import DeviceError, InputError, ProtocolError
from kinestat.robots.puma762.axes import (
    AXIS4_TO_5_COUPLING,
    AXIS_DEG_PER_COUNT,
    JOINT1_OFFSET_DEG,
    axis45_compensation,
    axis_deg_to_counts,
    axis_deg_to_joint_rad,
    counts_to_axis_deg,
    counts_to_joint_rad,
    joint_rad_to_axis_deg,
    joint_rad_to_counts,
    round_half_away,
)

counts6 = st.lists(st.integers(-10_000_000, 10_000_000), min_size=6, max_size=6)

# ----------------------------------------------------------------------------- conversions


def test_scales_reproduce_thesis_home_definition():
    # startup_initialize.m: "DP 0,103597,80672,0,0,0 %Define current position 0,90,90,0,0,0"
    deg = counts_to_axis_deg([0, 103597, 80672, 0, 0, 0])
    assert deg[1] == pytest.approx(90.0, abs=1e-3) and deg[2] == pytest.approx(90.0, abs=1e-3)
    # Axis_4_5_Correction.m's ratio 11200/23962 is 70.1 deg of axis 5 per 150.0 deg of axis 4
    assert 23962 * AXIS_DEG_PER_COUNT[3] == pytest.approx(150.0, abs=0.01)
    assert abs(AXIS4_TO_5_COUPLING) == pytest.approx(11200 / 23962)


@given(counts6)
def test_counts_degrees_round_trip(c):
    assert axis_deg_to_counts(counts_to_axis_deg(c)).tolist() == c
    assert joint_rad_to_counts(counts_to_joint_rad(c)).tolist() == c


def test_joint_offset_and_batch_shapes():
    q = counts_to_joint_rad(np.zeros((2, 3, 6)))
    assert q.shape == (2, 3, 6)
    assert np.allclose(q[..., 0], math.radians(JOINT1_OFFSET_DEG)) and np.allclose(q[..., 1:], 0)
    a = joint_rad_to_axis_deg([math.pi / 2, 0, 0, 0, 0, 0])
    assert a[0] == pytest.approx(90.0 - 180.0)
    assert np.allclose(axis_deg_to_joint_rad(a), [math.pi / 2, 0, 0, 0, 0, 0])


def test_rounding_is_matlab_round():
    assert round_half_away([0.5, 1.5, 2.5, -0.5, -2.5]).tolist() == [1, 2, 3, -1, -3]
    assert axis_deg_to_counts(-5.6 * AXIS_DEG_PER_COUNT).tolist() == [-6] * 6


@pytest.mark.parametrize("bad", [[0] * 5, [float("nan")] * 6, "abc", [1e15] * 6])
def test_conversions_reject_bad_input(bad):
    with pytest.raises(InputError):
        axis_deg_to_counts(bad)


@given(st.integers(-50000, 50000), st.integers(-20000, 20000), st.integers(-50000, 50000),
       st.integers(-20000, 20000))
def test_axis45_compensation_cancels_the_coupling(d_now, e_now, d_cmd, e_cmd):
    """Physics, written independently: axis 5 ends at its encoder motion plus the coupled
    motion coupling*(axis-4 motion); the encoder of axis 5 sees only the former."""
    corr = axis45_compensation(d_cmd, e_cmd, d_now)
    true_e = e_now + (int(corr.axis5_command) - e_now) + AXIS4_TO_5_COUPLING * (d_cmd - d_now)
    assert abs(true_e - e_cmd) <= 0.5 + 1e-9
    assert int(corr.axis5_reset) == e_cmd


def test_axis45_matches_thesis_formula_with_restored_signs():
    # Actual_PosE_E = (Apparant_Deg_E/ENC_DEG_5) - (PosE_D - Apparant_Deg_D/ENC_DEG_4)*k
    k = 11200 / 23962
    s4, s5 = AXIS_DEG_PER_COUNT[3], AXIS_DEG_PER_COUNT[4]
    deg_d, deg_e, pos_d = 40.0, -12.5, 1234
    thesis = (deg_e / s5) - (pos_d - deg_d / s4) * k
    ours = axis45_compensation(deg_d / s4, deg_e / s5, pos_d)
    assert int(ours.axis5_command) == round(thesis)
    assert int(ours.axis5_reset) == round(deg_e / s5)


@given(st.lists(st.integers(-40, 40), min_size=1, max_size=300), st.integers(-2000, 2000))
def test_chained_axis45_compensations_keep_true_axis5_within_half_a_count(d4_steps, e_target):
    """Physics, written independently, over a run of moves: each move turns the true axis 5 by
    its encoder motion plus coupling x (axis-4 motion); the encoder is then reset to the
    target. With each move's residual carried into the next, the true axis 5 never strays
    more than half a count from the encoder, however many moves."""
    d_now, true_e, enc_e, carry = 0, float(e_target), e_target, 0.0
    for d4 in d4_steps:
        corr = axis45_compensation(d_now + d4, e_target, d_now, carry=carry)
        true_e += (int(corr.axis5_command) - enc_e) + AXIS4_TO_5_COUPLING * d4
        enc_e, d_now, carry = int(corr.axis5_reset), d_now + d4, float(corr.residual)
        assert abs(true_e - enc_e) <= 0.5 + 1e-9
        assert abs((true_e - enc_e) - carry) <= 1e-9


def test_discarded_axis45_residuals_add_up_and_carried_ones_do_not():
    """The thesis's recipe (every residual discarded) drifts on a run of one-count axis-4
    moves: 0.467 counts per move. Carried, the drift stays within half a count."""
    drift = {}
    for carried in (False, True):
        true_e, carry = 0.0, 0.0
        for d_now in range(100):
            corr = axis45_compensation(d_now + 1, 0, d_now, carry=carry if carried else 0.0)
            # the encoder read 0 before the move (the reset to the target 0 after each)
            true_e += int(corr.axis5_command) + AXIS4_TO_5_COUPLING
            carry = float(corr.residual)
        drift[carried] = abs(true_e)
    assert drift[False] > 40 and drift[True] <= 0.5


def test_axis45_carry_beyond_half_a_count_is_refused():
    with pytest.raises(InputError, match="carry"):
        axis45_compensation(1, 0, 0, carry=0.7)


def test_axis45_batched():
    out = axis45_compensation(np.array([100, 200]), np.array([0, 0]), np.array([0, 0]))
    assert out.axis5_command.shape == (2,)


def test_thesis_move_plan():
    cur = np.array([0, 0, 0, 0, 0, 0])
    tgt = np.array([100000, 2, -40, 3, 3194 * 8, 0])
    plan = thesis_move_plan(cur, tgt)
    assert plan.speed.tolist() == [8000, 10, 10, 10, THESIS_SPEED_MAX[4], 10]
    assert plan.target.tolist() == [100000, 7, -40, 8, 3194 * 8, 5]  # +5 nudges
    assert plan.accel.tolist() == list(THESIS_ACCEL) == plan.decel.tolist()
    assert thesis_move_plan(cur, tgt, nudge=False).target.tolist() == tgt.tolist()


# ----------------------------------------------------------------------------- reply parsing


@pytest.mark.parametrize("text", ["?", "", "  ", "abc", "nan", "1.0?", ":"])
def test_parse_number_refuses_non_numbers(text):
    with pytest.raises(ProtocolError):
        parse_number(text, "MG _TPA")


def test_parse_numbers():
    assert parse_numbers(" 1, -2, 3", 3) == [1, -2, 3]
    with pytest.raises(ProtocolError):
        parse_numbers("1, 2", 3)


# ----------------------------------------------------------------------------- client




def test_move_completes_with_trapezoidal_profile(sim, client):
    target = [20000, -15000, 3000, 0, 800, -7]
    speed, accel = [8000, 6000, 2000, 1000, 500, 100], 40000
    client.move_absolute(target, speed, accel, decel=20000)
    assert client.is_moving()
    final = client.wait_motion_complete(timeout=10, poll_interval=0)
    assert list(final) == target
    assert not client.is_moving()
    for axis in range(6):
        hist = np.array(sim.controller.history(axis))
        t, x, v = hist.T
        assert np.all(np.abs(v) <= speed[axis] * (1 + 1e-9))
        dv = np.diff(v) / np.maximum(np.diff(t), 1e-12)
        assert np.all(np.abs(dv) <= 40000 * (1 + 1e-6))
        assert np.all(np.diff(x) * np.sign(target[axis] or 1) >= -1e-9)  # monotone
    # the long move reached its cruise speed
    assert np.max(np.abs(np.array(sim.controller.history(0))[:, 2])) == pytest.approx(8000)


def test_position_queries_agree(sim, client):
    client.define_position([1, -2, 3, -4, 5, -6])
    assert client.position_counts() == (1, -2, 3, -4, 5, -6)
    assert [client.axis_position(a) for a in "ABCDEF"] == [1, -2, 3, -4, 5, -6]
    client.define_position({"E": 77})
    assert client.position_counts() == (1, -2, 3, -4, 77, -6)


def test_rejected_command_raises_with_tc1(sim, client):
    with pytest.raises(GalilCommandError) as exc:
        client.command("XQ")
    assert exc.value.code == 1 and exc.value.message == "Unrecognized command"
    sim.reject_next("PA", code=7)
    with pytest.raises(GalilCommandError, match="Command not valid while running") as exc:
        client.move_absolute([1] * 6, 100, 1000)
    assert exc.value.command.startswith("PA") and exc.value.code == 7
    client.motor_off()
    with pytest.raises(GalilCommandError) as exc:
        client.command("BG")
    assert exc.value.code == 20
    client.servo_here()
    client.command("BG")


def test_question_mark_is_never_a_number(sim, client):
    sim.reject_next("MG _BGA", code=1)
    with pytest.raises(GalilCommandError):
        client.is_moving()
    sim.reject_next("TP", code=1)
    with pytest.raises(GalilCommandError):
        client.position_counts()


def test_closed_link_raises(sim, client):
    assert client.position_counts() == (0,) * 6
    sim.drop_link()
    with pytest.raises(DeviceError):
        client.position_counts()
    assert not client.connected
    with pytest.raises(DeviceError, match="not connected"):
        client.position_counts()
    client.connect()
    assert client.position_counts() == (0,) * 6


def test_timeout_raises_and_closes(sim):
    with GalilClient("127.0.0.1", sim.port, timeout=0.15) as g:
        sim.silence_next("TP")
        with pytest.raises(DeviceError, match="did not answer"):
            g.position_counts()
        assert not g.connected


def test_wait_motion_complete_timeout(sim, client):
    client.command("JG 1000")
    client.command("BG A")
    with pytest.raises(DeviceError, match="not complete"):
        client.wait_motion_complete(timeout=0.05, poll_interval=0)
    client.stop()
    client.wait_motion_complete(timeout=5, poll_interval=0)


def test_connect_refused():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    with pytest.raises(DeviceError, match="cannot connect"):
        GalilClient("127.0.0.1", port, timeout=0.5).connect()


def test_client_argument_checks(client):
    for bad in ["", "SP 1;BG", "TP\r"]:
        with pytest.raises(InputError):
            client.command(bad)
    with pytest.raises(InputError):
        client.move_absolute([1.5] * 6, 100, 100)
    with pytest.raises(InputError):
        client.move_absolute([1] * 6, 0, 100)
    with pytest.raises(InputError):
        client.move_absolute([1] * 5, 100, 100)
    with pytest.raises(InputError):
        GalilClient(timeout=0)


def test_compensated_move_puts_true_axis5_where_commanded(sim, client):
    target = [0, 0, 0, 30000, 2500, 0]
    final = client.move_compensated(target, speed=20000, accel=200000, poll_interval=0)
    true = sim.true_axis_counts()
    assert abs(true[4] - 2500) <= 1.0
    assert final[4] == 2500 and final[3] == 30000
    # a second move back: still exact, both for the encoder and the true position
    final = client.move_compensated([0, 0, 0, -12000, -400, 0], 20000, 200000, poll_interval=0)
    assert abs(sim.true_axis_counts()[4] + 400) <= 1.0 and final[4] == -400


def test_uncompensated_move_shows_the_coupling(sim, client):
    client.move_absolute([0, 0, 0, 30000, 2500, 0], 20000, 200000)
    final = client.wait_motion_complete(poll_interval=0)
    assert final[4] == 2500  # the encoder does not see it ...
    assert sim.true_axis_counts()[4] == pytest.approx(2500 + AXIS4_TO_5_COUPLING * 30000)


class _QuietReader:
    """A sensor stream with nothing to read (DeviceIO.move only polls it while moving)."""

    def poll(self) -> None:
        pass


@pytest.mark.parametrize("through", ["client", "device_io"])
def test_many_small_axis4_moves_leave_true_axis5_on_its_encoder(sim, client, through):
    """Sixty one-count moves of axis 4 with axis 5 held (the wrist turning slowly, as in a
    follow run): on the simulated Galil, whose axis 5 physically carries the coupling, the
    true axis 5 stays within half a count of its encoder after every move. (Discarding each
    move's residual, as the thesis's recipe did, drifts 0.467 counts per move here.)"""
    io = DeviceIO(client, _QuietReader(), settle=0.0) if through == "device_io" else None
    carry = 0.0
    for k in range(1, 61):
        target = [0, 0, 0, k, 0, 0]
        if io is not None:
            io.move(np.array(target))
        else:
            client.move_compensated(target, 20000, 200000, poll_interval=0, carry=carry)
            carry = client.axis5_residual
        enc = client.position_counts()
        assert enc[3] == k and enc[4] == 0
        assert abs(sim.true_axis_counts()[4] - enc[4]) <= 0.5 + 1e-9, k


# ----------------------------------------------------------------------------- fake servers


def one_shot_server(replies: dict[bytes, bytes]):
    """A TCP server answering fixed replies to fixed commands (for malformed-reply tests)."""
    lst = socket.socket()
    lst.bind(("127.0.0.1", 0))
    lst.listen(1)
    lst.settimeout(5)

    def run():
        try:
            conn, _ = lst.accept()
        except OSError:
            return
        conn.settimeout(5)
        buf = b""
        with conn:
            while True:
                try:
                    chunk = conn.recv(1024)
                except OSError:
                    return
                if not chunk:
                    return
                buf += chunk
                while b"\r" in buf:
                    cmd, buf = buf.split(b"\r", 1)
                    reply = replies.get(cmd, b"?")
                    for i in range(len(reply)):  # byte by byte: replies arrive in pieces
                        conn.sendall(reply[i:i + 1])

    t = threading.Thread(target=run, daemon=True)
    t.start()
    return lst, t


def test_client_against_scripted_replies():
    lst, t = one_shot_server({b"MG _TPA": b"garbage\r\n:", b"MG _TPB": b" -42.0000\r\n:",
                              b"TC1": b"4 Operand error\r\n:", b"SH": b":"})
    try:
        with GalilClient("127.0.0.1", lst.getsockname()[1], timeout=2) as g:
            with pytest.raises(ProtocolError):
                g.axis_position("A")
            assert g.axis_position("B") == -42
            g.servo_here()
            with pytest.raises(GalilCommandError) as exc:
                g.command("PA 1")
            assert exc.value.code == 4 and "Operand error" in str(exc.value)
    finally:
        lst.close()
        t.join(5)
