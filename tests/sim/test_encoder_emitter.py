"""The encoder emitter on a real pty, read back by the EncoderReader, with injected faults."""

from __future__ import annotations

import itertools
import os
import time

import numpy as np
import pytest

from kinestat.devices.encoder_stream import (
    EncoderReader,
    StaleDataError,
    StreamParser,
    decode_packet,
    legs_to_channels,
)
from kinestat.errors import DeviceError, InputError
from kinestat.sim.encoder_emitter import EncoderEmitter, constant_counts

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs a pseudo-terminal")

LEGS = [101, -202, 303, 40404, -5, 66000]


def read_until(reader, predicate, timeout=2.0):
    """Read fresh packets until ``predicate(reading)``; bounded."""
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        r = reader.read(timeout=0.5)
        if predicate(r):
            return r
    pytest.fail("condition not met in time")


def test_next_frame_without_pty():
    em = EncoderEmitter(constant_counts(LEGS), start_seq=65535)
    p1, p2 = decode_packet(em.next_frame()), decode_packet(em.next_frame())
    assert (p1.seq, p2.seq) == (65535, 0)
    assert p1.counts == tuple(legs_to_channels(LEGS).tolist())
    em.drop(1)
    em.corrupt(1)
    assert em.next_frame() == b""  # dropped (seq 1 used up)
    parser = StreamParser()
    parser.feed(em.next_frame())  # seq 2, corrupted
    assert parser.stats.checksum == 1 and em.dropped == 1 and em.corrupted == 1
    em.freeze()
    a, b = em.next_frame(), em.next_frame()
    assert a == b and decode_packet(a).seq == 2  # the last packet built, repeated
    em.freeze(False)
    em.silence()
    assert em.next_frame() == b""
    em.silence(False)
    em.inject(b"junk")
    assert em.next_frame().startswith(b"junk$KS,0003")


def test_reader_gets_counts_in_leg_order():
    counter = itertools.count()

    def counts_now():  # a moving platform: leg k = 10*k + packet number
        n = next(counter)
        return [10 * k + n for k in range(1, 7)]

    with EncoderEmitter(counts_now, rate_hz=400) as em, \
            EncoderReader(em.path, stale_after=0.5) as rd:
        readings = [rd.read() for _ in range(5)]
    seqs = [r.seq for r in readings]
    assert seqs == sorted(seqs) and len(set(seqs)) == 5
    for r in readings:
        d = r.counts - 10 * np.arange(1, 7)
        assert np.all(d == d[0])  # same packet number on every leg: the wiring is undone
        assert r.age < 0.5


def test_faults_seen_by_reader():
    with EncoderEmitter(constant_counts(LEGS), rate_hz=400) as em, \
            EncoderReader(em.path, stale_after=0.3) as rd:
        first = rd.read()
        assert first.counts.tolist() == LEGS
        em.drop(3)
        read_until(rd, lambda r: any(f.kind == "gap" and f.lost == 3 for f in r.faults))
        em.corrupt(2)
        read_until(rd, lambda r: rd.stats.checksum >= 2)
        em.inject(b"\x00\xffnoise\r\n$KS,12")
        read_until(rd, lambda r: rd.stats.framing >= 1)
        assert rd.read().counts.tolist() == LEGS  # resynchronised

        # frozen sensor: the same packet again and again -> stale, with duplicates counted
        em.freeze()
        t0 = time.monotonic()
        with pytest.raises(StaleDataError) as exc:
            for _ in range(100):
                rd.read()
        assert time.monotonic() - t0 < 1.5
        assert rd.stats.duplicates > 0 and exc.value.last_seq is not None
        em.freeze(False)
        after = rd.read()  # fresh again; read() returns the newest, maybe skipping some
        assert 1 <= (after.seq - exc.value.last_seq) % 65536 < 100
        assert not any(f.kind == "gap" for f in after.faults)

        # silence: no packets at all -> stale; latest() refuses old data too
        em.silence()
        time.sleep(0.1)
        rd.latest(max_age=10)  # drain what was already on the line
        with pytest.raises(StaleDataError):
            rd.read(timeout=0.2)
        with pytest.raises(StaleDataError):
            rd.latest(max_age=0.1)
        em.silence(False)
        assert rd.read().counts.tolist() == LEGS


def test_legacy_format_over_pty():
    legs = [5, 6000, 65535, 0, 1234, 77]
    with EncoderEmitter(constant_counts(legs), rate_hz=300, fmt="legacy") as em, \
            EncoderReader(em.path, fmt="legacy", legacy_unwrap=False) as rd:
        r = rd.read()
        assert r.seq is None and r.fmt == "legacy"
        assert r.counts.tolist() == legs


def test_emitter_stop_makes_reader_fail_cleanly():
    em = EncoderEmitter(constant_counts(LEGS), rate_hz=200).start()
    rd = EncoderReader(em.path, stale_after=0.3).open()
    try:
        rd.read()
        em.stop()
        with pytest.raises((DeviceError, StaleDataError)):
            for _ in range(50):
                rd.read()
    finally:
        rd.close()
        em.stop()


def test_dead_callback_stops_the_stream():
    def broken():
        raise RuntimeError("cell crashed")

    with EncoderEmitter(broken, rate_hz=200) as em, EncoderReader(em.path) as rd:
        with pytest.raises(StaleDataError):
            rd.read(timeout=0.2)
        assert isinstance(em.error, RuntimeError)


def test_emitter_argument_checks():
    with pytest.raises(InputError):
        EncoderEmitter(constant_counts(LEGS), rate_hz=0)
    with pytest.raises(InputError):
        EncoderEmitter(constant_counts(LEGS), fmt="xml")
    with pytest.raises(InputError):
        EncoderEmitter(constant_counts(LEGS), drop_rate=2)
    with pytest.raises(InputError):
        EncoderEmitter(42)
    with pytest.raises(InputError):
        constant_counts([1, 2, 3])
    with pytest.raises(DeviceError):
        _ = EncoderEmitter(constant_counts(LEGS)).path


def test_random_faults_are_counted():
    em = EncoderEmitter(constant_counts(LEGS), drop_rate=0.2, corrupt_rate=0.2, seed=3)
    parser = StreamParser()
    for _ in range(300):
        parser.feed(em.next_frame())
    assert parser.stats.checksum == em.corrupted > 0
    assert parser.stats.packets == em.sent - em.corrupted
    # every dropped or corrupted packet shows up as lost (except a trailing one)
    assert em.dropped + em.corrupted - parser.stats.lost in (0, 1)
