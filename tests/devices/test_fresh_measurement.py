"""A measurement after a move comes from packets SAMPLED after the motion ended, not merely
received after it (the device path under CPU load, docs/devices.md *Measurements after a move*).

The encoder box here reports the robot's true axis counts as its six "leg" counts, so a packet
tells exactly where the robot was when it was sampled. A packet sampled while the axes move is
held back until well after the motion ended (a descheduled emitter thread, or a packet left in
the serial buffer): deterministic, no machine load needed. Before the rule, that packet arrived
after the settle time and was taken as the measurement of the final pose.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from kinestat.devices.cell_io import DeviceIO, MotionProfile
from kinestat.devices.encoder_stream import EncoderReader, Reading, StreamMark, sampled_after
from kinestat.devices.galil import GalilClient
from kinestat.sim.dmc import DmcSimulator
from kinestat.sim.encoder_emitter import EncoderEmitter
from kinestat.sim.galil_server import GalilSimServer

HOLD = 0.2
"""How long (s) after the end of the motion a packet sampled during it is delivered: far
beyond the settle time (12.5 ms)."""

GAP = 0.05
"""The next packet's delay (s) after the late one."""

FAST = MotionProfile(speed=(80000.0,) * 6, accel=(800000.0,) * 6)


def _late_mid_motion_packets(ctrl: DmcSimulator, server: GalilSimServer, held: list):
    """counts_now for the emitter: the true axis counts; when sampled mid-motion, returned
    only ``HOLD`` s after the motion ended (the emitter thread blocks meanwhile), and the next
    packet ``GAP`` s after that (so that the reader takes the late packet on its own)."""
    after_hold = [False]

    def counts_now() -> np.ndarray:
        if after_hold[0]:
            after_hold[0] = False
            time.sleep(GAP)
        c = np.asarray(server.true_axis_counts(), dtype=float)
        if any(ctrl.moving()):
            while any(ctrl.moving()):
                time.sleep(0.001)
            time.sleep(HOLD)
            held.append(c.copy())
            after_hold[0] = True
        return c
    return counts_now


@pytest.mark.parametrize("fmt", ["ks", "legacy"])
@pytest.mark.parametrize("samples", [1, 3])
def test_a_packet_sampled_mid_motion_but_received_late_is_not_the_measurement(fmt, samples):
    ctrl = DmcSimulator(coupling=0.0)
    ctrl.variables["HOMED"] = 1.0
    held: list[np.ndarray] = []
    with GalilSimServer(controller=ctrl) as server, \
            EncoderEmitter(_late_mid_motion_packets(ctrl, server, held), rate_hz=200.0,
                           fmt=fmt) as emitter, \
            EncoderReader(emitter.path, fmt=fmt, stale_after=1.0) as reader:
        client = GalilClient("127.0.0.1", server.port, timeout=1.0).connect()
        try:
            io = DeviceIO(client, reader, profile=FAST, settle=2.5 / 200.0, samples=samples,
                          coupling=0.0)
            for target in ([3000, 0, 0, 0, 0, 0], [3000, -2000, 0, 0, 0, 0]):
                n_held = len(held)
                io.move(np.array(target))
                s = io.sensor()
                final = np.asarray(server.true_axis_counts(), dtype=float)
                assert final.tolist() == [float(v) for v in target]
                assert len(held) > n_held  # the stale packet was there to be (mis)taken
                assert not np.allclose(held[-1], final)
                np.testing.assert_array_equal(s.counts, final)
        finally:
            client.close()


def _reading(seq, index):
    return Reading(seq, np.zeros(6), (0,) * 6, received_at=0.0, age=0.0, index=index)


def test_sampled_after_counts_packets_and_sequence_numbers():
    mark = StreamMark(index=10, seq=0xFFFE)
    # by count (both formats): the first packet after the mark may be old, the second is not
    assert not sampled_after(_reading(None, 11), StreamMark(index=10))
    assert sampled_after(_reading(None, 12), StreamMark(index=10))
    # by sequence number across the 16-bit wrap: 0xFFFF is next, 0x0000 the one after
    assert not sampled_after(_reading(0xFFFF, 11), mark)
    assert sampled_after(_reading(0x0000, 11), mark)  # one lost on air: still after
    assert not sampled_after(_reading(0x0005, 11), StreamMark(index=10, seq=0x0010))  # behind
    assert sampled_after(_reading(0x0005, 12), StreamMark(index=10, seq=0x0010))  # a restart
    assert not sampled_after(_reading(3, 13), StreamMark(index=10, seq=0), skip=3)
    assert sampled_after(_reading(4, 12), StreamMark(index=10, seq=0), skip=3)


def test_drain_takes_what_is_buffered_without_waiting():
    counts = np.arange(6.0)
    with EncoderEmitter(lambda: counts, rate_hz=200.0) as emitter, \
            EncoderReader(emitter.path, stale_after=1.0, read_timeout=0.5) as reader:
        time.sleep(0.1)  # ~20 packets wait in the pty
        t0 = time.monotonic()
        mark = reader.drain()
        took = time.monotonic() - t0
        assert mark.index >= 5 and mark.seq is not None
        assert took < 0.25  # never waits read_timeout for more
        r = reader.read()  # the drained packet itself: not returned yet
        assert r.index == mark.index and r.seq == mark.seq
        r = reader.read()
        assert r.index > mark.index and r.seq != mark.seq
