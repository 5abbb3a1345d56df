"""Leg encoders re-zero on their index pulse (Vibhute 2011 §3.2.2, issue 42): the stream's
``I`` field, the box (the simulated emitter), the reader and the calibration's index counts,
with a leg whose count drifts (missed counts) and is re-zeroed when it passes its index."""

from __future__ import annotations

import time

import numpy as np
import pytest

from kinestat.devices.encoder_stream import EncoderReader
from kinestat.errors import ProtocolError
from kinestat.hardware.encoder_packets import (
    crc16_ccitt,
    decode_packet,
    encode_packet,
    index_mask_to_legs,
    legs_to_index_mask,
)
from kinestat.hardware.leg_calibration import THESIS_CALIBRATION, counts_to_lengths
from kinestat.hardware.leg_law import rescale_counts
from kinestat.io.calibration_toml import loads_calibration
from kinestat.sim.encoder_emitter import EncoderEmitter
from kinestat.sim.sensor import ideal_calibration


class Legs:
    """True leg counts (legs 1..6) that a test moves."""

    def __init__(self, counts):
        self.counts = np.asarray(counts, dtype=float)

    def __call__(self):
        return self.counts.copy()


def _frame(em: EncoderEmitter):
    return decode_packet(em.next_frame())


def test_the_index_field_round_trips_and_old_frames_still_decode():
    f = encode_packet(7, [1, -2, 3, 4, 5, 6], index_mask=0b100010)
    assert len(f) == 79 and decode_packet(f).index_mask == 0b100010
    assert decode_packet(encode_packet(7, [1, 2, 3, 4, 5, 6])).index_mask is None
    for flags in np.eye(6, dtype=bool):
        np.testing.assert_array_equal(index_mask_to_legs(legs_to_index_mask(flags)), flags)
    body = b"KS,0007,A00000001,B00000002,C00000003,D00000004,E00000005,F00000006,I40"
    with pytest.raises(ProtocolError, match="beyond channel F"):
        decode_packet(b"$" + body + b"*" + f"{crc16_ccitt(body):04X}".encode() + b"\r\n")


def test_a_drifting_leg_is_re_zeroed_at_its_index():
    """Leg 1 loses 7 counts (it reads 7 low, its length 7 counts' worth long); a leg that does
    not pass its index keeps its drift; leg 1 reads true again once it passes its index."""
    legs = Legs([120, 300, 300, 300, 300, 300])
    em = EncoderEmitter(legs, index_counts=[0, 0, 0, 0, 0, 0])
    assert _frame(em).counts[1] == 120  # channel B carries leg 1 (thesis wiring)
    em.miss(1, 7)
    em.miss(2, -4)
    p = _frame(em)
    assert p.counts[1] == 113 and p.counts[0] == 304 and p.index_mask == 0
    # the calibration turns the drift into a length error of 7 counts times the map's slope
    lengths = counts_to_lengths(np.array([[120, 300, 300, 300, 300, 300],
                                          [113, 304, 300, 300, 300, 300]], float),
                                THESIS_CALIBRATION)
    slope = THESIS_CALIBRATION.length_coeffs[0, 1]
    assert lengths[1, 0] - lengths[0, 0] == pytest.approx(-7 * slope)
    legs.counts[0] = -15  # leg 1 passes its index mark (count 0)
    p = _frame(em)
    assert p.counts[1] == -15 and p.index_mask == legs_to_index_mask([1, 0, 0, 0, 0, 0])
    legs.counts[0] = 120
    p = _frame(em)
    assert p.counts[1] == 120 and p.index_mask == legs_to_index_mask([1, 0, 0, 0, 0, 0])
    assert p.counts[0] == 304  # leg 2 never passed its index: still 4 counts high
    assert _frame(em).index_mask == 0  # resting: no more pulses


def test_without_an_index_model_the_drift_stays():
    legs = Legs([120, 300, 300, 300, 300, 300])
    em = EncoderEmitter(legs)
    em.miss(1, 7)
    legs.counts[0] = -15
    p = _frame(em)
    assert p.counts[1] == -22 and p.index_mask is None


def test_the_reader_reports_the_pulse_and_the_referenced_legs():
    legs = Legs([120, 300, 300, 300, 300, 300])
    with EncoderEmitter(legs, rate_hz=200, index_counts=np.zeros(6)) as em, \
            EncoderReader(em.path, stale_after=1.0) as reader:
        r = reader.read()
        assert r.referenced == (False,) * 6 and r.index_legs == ()
        em.miss(1, 7)
        time.sleep(0.05)
        assert reader.read().counts[0] == 113
        legs.counts[0] = -15
        t_end = time.monotonic() + 2.0
        hit: set[int] = set()
        while time.monotonic() < t_end:
            r = reader.read()
            hit |= set(r.index_legs)
            if r.counts[0] == -15:
                break
        assert r.counts[0] == -15 and hit == {1}
        assert r.referenced == (True, False, False, False, False, False)
        assert reader.stats.index_pulses == 1


def test_the_calibrations_index_stays_at_its_length_on_other_counts():
    """The index mark is a place on the strip: counted in other counts (:func:`rescale_counts`,
    the ideal sensor) it is at the same leg length; the thesis's maps put it at ``l = b``."""
    def at(cal):
        return cal.length_coeffs[:, 0] + cal.length_coeffs[:, 1] * cal.index_counts

    np.testing.assert_allclose(at(THESIS_CALIBRATION), THESIS_CALIBRATION.length_coeffs[:, 0])
    inside = type(THESIS_CALIBRATION)(THESIS_CALIBRATION.length_coeffs,
                                      THESIS_CALIBRATION.force_coeffs,
                                      index_counts=np.full(6, 478.0))
    for cal in (THESIS_CALIBRATION, inside):
        for other in (rescale_counts(cal, 1e-3 / 0.0255), ideal_calibration(cal)):
            np.testing.assert_allclose(at(other), at(cal), rtol=0, atol=1e-9)
    # and the reader's counts, through the maps, give that length there
    np.testing.assert_allclose(
        counts_to_lengths(inside.index_counts, inside, inside.leg_names), at(inside))


def test_a_calibration_file_gives_each_legs_index_count():
    legs = "".join(f'[[legs]]\nleg = "{n}"\nlength = [80.0, -0.0254]\nforce = [1.0, -0.03]\n'
                   f"index_count = {10 * k}\n" for k, n in enumerate("OSPTQR"))
    f = loads_calibration('length_unit = "mm"\nforce_unit = "N"\n' + legs)
    np.testing.assert_array_equal(f.calibration.index_counts, [0, 10, 20, 30, 40, 50])
