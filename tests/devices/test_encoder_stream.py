"""Encoder stream: codec, incremental parser, sequence tracking, reader (loop:// and fake clock)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.devices.encoder_stream import (
    COUNT_MAX,
    COUNT_MIN,
    THESIS_WIRING,
    EncoderReader,
    Packet,
    StaleDataError,
    StreamFault,
    StreamParser,
    channels_to_legs,
    crc16_ccitt,
    decode_legacy_line,
    decode_packet,
    encode_legacy_line,
    encode_packet,
    legs_to_channels,
    unwrap16,
)
from kinestat.errors import DeviceError, InputError, KinestatError, ProtocolError

counts32 = st.lists(st.integers(COUNT_MIN, COUNT_MAX), min_size=6, max_size=6)
counts16 = st.lists(st.integers(0, 0xFFFF), min_size=6, max_size=6)
seqs = st.integers(0, 0xFFFF)


def crc16_bitwise(data: bytes) -> int:
    """Independent bit-by-bit CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF)."""
    crc = 0xFFFF
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


# ----------------------------------------------------------------------------- codec


def test_crc_check_value():
    # the catalogue check value of CRC-16/CCITT-FALSE
    assert crc16_ccitt(b"123456789") == 0x29B1
    assert crc16_bitwise(b"123456789") == 0x29B1


@given(seqs, counts32)
def test_ks_round_trip(seq, counts):
    frame = encode_packet(seq, counts)
    assert len(frame) == 75 and frame.startswith(b"$KS,") and frame.endswith(b"\r\n")
    pkt = decode_packet(frame)
    assert pkt == Packet(seq=seq, counts=tuple(counts), fmt="ks")


@given(seqs, counts32)
def test_ks_frame_read_by_hand(seq, counts):
    """Decode the frame with the documented layout and an independent CRC."""
    frame = encode_packet(seq, counts).decode("ascii")
    body, crc = frame[1:-2].split("*")
    assert int(crc, 16) == crc16_bitwise(body.encode())
    fields = body.split(",")
    assert fields[0] == "KS" and int(fields[1], 16) == seq
    for tag, f, c in zip("ABCDEF", fields[2:], counts, strict=True):
        assert f[0] == tag and len(f) == 9
        u = int(f[1:], 16)
        assert (u - (1 << 32) if u >= 1 << 31 else u) == c


@given(seqs, counts32, st.data())
def test_single_byte_corruption_detected(seq, counts, data):
    frame = bytearray(encode_packet(seq, counts))
    i = data.draw(st.integers(0, len(frame) - 3), label="index")
    x = data.draw(st.integers(1, 255), label="xor")
    frame[i] ^= x
    with pytest.raises(ProtocolError):
        decode_packet(bytes(frame))


@pytest.mark.parametrize(
    "seq, counts",
    [(-1, [0] * 6), (65536, [0] * 6), (1.5, [0] * 6), (0, [0] * 5), (0, [0] * 7),
     (0, [0.5, 0, 0, 0, 0, 0]), (0, [float("nan")] + [0] * 5), (0, [2**31] + [0] * 5),
     (0, ["x", 0, 0, 0, 0, 0]), (0, None)],
)
def test_encode_rejects_bad_input(seq, counts):
    with pytest.raises(InputError):
        encode_packet(seq, counts)


@pytest.mark.parametrize("frame", [b"", b"KS,0000", b"$KS,0000*FFFF", b"$KS,zzzz*12",
                                   b"$KS,0001,A00000000*XYZW\r\n"])
def test_decode_rejects_malformed(frame):
    with pytest.raises(ProtocolError):
        decode_packet(frame)


def test_decode_rejects_lower_case_hex_with_valid_crc():
    body = b"KS,000a,A00000000,B00000000,C00000000,D00000000,E00000000,F00000000"
    frame = b"$" + body + b"*" + f"{crc16_bitwise(body):04X}".encode() + b"\r\n"
    with pytest.raises(ProtocolError, match="upper-case"):
        decode_packet(frame)


@given(st.binary(max_size=120))
def test_decoders_fuzz_only_protocol_errors(blob):
    for decode in (decode_packet, decode_legacy_line):
        try:
            pkt = decode(blob)
        except ProtocolError:
            continue
        assert isinstance(pkt, Packet)


# ----------------------------------------------------------------------------- legacy


def serialdaq_plat(line: bytes) -> list[int]:
    """Vibhute App. D.6 ``serialdaq_plat.m`` transcribed: legs 1..6 from a 23-byte line."""
    X = [f"{b:02X}" for b in line]  # dec2hex(unicode2native(data_raw)), row k = byte k+1
    assert len(X) == 23
    tags = [X[3], X[6], X[9], X[12], X[15], X[18]]  # X(4,:), X(7,:), ... (1-based)
    assert tags == ["41", "42", "43", "44", "45", "46"]

    def h(r):  # [X(r,1),X(r,2),X(r+1,1),X(r+1,2)] with 1-based r
        return int(X[r - 1] + X[r], 16)

    leg2, leg1, leg6, leg5, leg4, leg3 = h(5), h(8), h(11), h(14), h(17), h(20)
    return [leg1, leg2, leg3, leg4, leg5, leg6]


@given(counts16)
def test_legacy_layout_matches_thesis_matlab(legs):
    channels = legs_to_channels(legs).tolist()
    line = encode_legacy_line(channels)
    assert len(line) == 24 and line.endswith(b"\n")
    assert serialdaq_plat(line[:-1]) == legs
    pkt = decode_legacy_line(line)
    assert pkt.seq is None and pkt.counts == tuple(channels)
    assert channels_to_legs(pkt.counts).tolist() == legs


def test_thesis_wiring():
    # A carries leg 2, B leg 1, C leg 6, D leg 5, E leg 4, F leg 3
    assert THESIS_WIRING == (2, 1, 6, 5, 4, 3)
    legs = np.array([10, 20, 30, 40, 50, 60])
    assert legs_to_channels(legs).tolist() == [20, 10, 60, 50, 40, 30]
    with pytest.raises(InputError):
        channels_to_legs(legs, wiring=(1, 1, 2, 3, 4, 5))


@given(st.lists(counts16, min_size=1, max_size=4), st.permutations(range(1, 7)))
def test_wiring_round_trip_batched(rows, wiring):
    c = np.array(rows)
    assert np.array_equal(channels_to_legs(legs_to_channels(c, wiring), wiring), c)


@pytest.mark.parametrize("line", [b"", b"x" * 22, b"x" * 24,
                                  b"ENCB\x00\x00A\x00\x00C\x00\x00D\x00\x00E\x00\x00F\x00\x00 \r"])
def test_legacy_decode_rejects(line):
    with pytest.raises(ProtocolError):
        decode_legacy_line(line)


@given(st.integers(-30000, 30000), st.lists(st.integers(-32767, 32767), max_size=30))
def test_unwrap16_recovers_a_walk(start, steps):
    true = np.cumsum([start, *steps])
    prev = None
    for t in true:
        prev = unwrap16(prev, [t & 0xFFFF] * 6)
        assert np.all(prev == t)


# ----------------------------------------------------------------------------- parser


def frames(n, start=0, rng=None):
    rng = rng or np.random.default_rng(1)
    cs = rng.integers(-(2**20), 2**20, size=(n, 6))
    return [encode_packet((start + k) % 65536, cs[k].tolist()) for k in range(n)], cs


def split_feed(parser, data: bytes, cuts):
    events = []
    pos = 0
    for c in sorted(set(cuts)):
        events += parser.feed(data[pos:c])
        pos = c
    events += parser.feed(data[pos:])
    return events


@settings(max_examples=40)
@given(st.lists(st.binary(max_size=40), min_size=6, max_size=6),
       st.lists(st.integers(0, 600), max_size=20))
def test_parser_resyncs_after_garbage_between_frames(garbage, cuts):
    fs, cs = frames(5)
    stream = garbage[0] + b"".join(f + g for f, g in zip(fs, garbage[1:], strict=True))
    ev = split_feed(StreamParser(), stream, cuts)
    pkts = [e for e in ev if isinstance(e, Packet)]
    assert [p.counts for p in pkts] == [tuple(c) for c in cs.tolist()]
    assert all(isinstance(e, (Packet, StreamFault)) for e in ev)


@settings(max_examples=40)
@given(st.data())
def test_parser_single_byte_damage_never_yields_a_false_packet(data):
    fs, cs = frames(6)
    stream = bytearray(b"".join(fs))
    i = data.draw(st.integers(0, len(stream) - 1))
    op = data.draw(st.sampled_from(["sub", "ins", "del"]))
    b = data.draw(st.integers(0, 255))
    if op == "sub":
        stream[i] = b if b != stream[i] else b ^ 1
    elif op == "ins":
        stream.insert(i, b)
    else:
        del stream[i]
    cuts = data.draw(st.lists(st.integers(0, len(stream)), max_size=10))
    ev = split_feed(StreamParser(), bytes(stream), cuts)
    pkts = [e for e in ev if isinstance(e, Packet)]
    originals = {(k, tuple(c)) for k, c in enumerate(cs.tolist())}
    assert all((p.seq, p.counts) in originals for p in pkts)
    assert len(pkts) >= 5


@settings(max_examples=60)
@given(st.binary(max_size=400), st.lists(st.integers(0, 400), max_size=10),
       st.sampled_from(["ks", "legacy"]))
def test_parser_fuzz_only_events(blob, cuts, fmt):
    parser = StreamParser(fmt)
    try:
        ev = split_feed(parser, blob, cuts)
    except KinestatError:  # pragma: no cover - the parser reports, it should not raise
        pytest.fail("the parser raised on stream content")
    assert all(isinstance(e, (Packet, StreamFault)) for e in ev)
    # and it still decodes a good frame afterwards
    good = encode_packet(7, [1, 2, 3, 4, 5, 6]) if fmt == "ks" else encode_legacy_line([1] * 6)
    after = parser.feed(b"\n" + good)
    assert any(isinstance(e, Packet) for e in after)


def test_parser_bounded_buffer_on_endless_garbage():
    p = StreamParser()
    for _ in range(100):
        p.feed(b"\x00" * 100)
    assert len(p._buf) <= 200
    p.feed(b"$" + b"A" * 1000)
    assert len(p._buf) <= 200


def kinds(events):
    return [e.kind if isinstance(e, StreamFault) else "pkt" for e in events]


def test_sequence_gap_duplicate_out_of_order():
    fs, _ = frames(10)
    p = StreamParser()
    assert kinds(p.feed(fs[0] + fs[1])) == ["pkt", "pkt"]
    ev = p.feed(fs[4])  # 2 and 3 lost
    assert kinds(ev) == ["gap", "pkt"] and ev[0].lost == 2
    assert kinds(p.feed(fs[4])) == ["duplicate"]  # frozen sensor
    assert kinds(p.feed(fs[2])) == ["out_of_order"]  # stale, dropped
    assert kinds(p.feed(fs[5])) == ["pkt"]
    assert p.stats.lost == 2 and p.stats.duplicates == 1 and p.stats.out_of_order == 1
    assert p.stats.packets == 4


def test_sequence_wraps_without_gap():
    fs, _ = frames(4, start=65534)
    p = StreamParser()
    assert kinds(p.feed(b"".join(fs))) == ["pkt"] * 4
    assert p.stats.lost == 0


def test_sender_restart_is_followed():
    hi, _ = frames(3, start=5000)
    lo, _ = frames(3, start=0)
    p = StreamParser()
    p.feed(b"".join(hi))
    assert kinds(p.feed(lo[0])) == ["out_of_order"]
    assert kinds(p.feed(lo[1])) == ["restart", "pkt"]
    assert kinds(p.feed(lo[2])) == ["pkt"]


def test_checksum_fault_reported():
    fs, _ = frames(3)
    bad = bytearray(fs[1])
    bad[20] ^= 0x01
    ev = StreamParser().feed(fs[0] + bytes(bad) + fs[2])
    assert kinds(ev) == ["pkt", "checksum", "gap", "pkt"]


def test_parser_rejects_bad_arguments():
    with pytest.raises(InputError):
        StreamParser("nmea")
    with pytest.raises(InputError):
        StreamParser().feed("text")


# ----------------------------------------------------------------------------- reader


class FakeClock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


def test_reader_over_loop_url_and_staleness():
    clock = FakeClock()
    r = EncoderReader("loop://", stale_after=0.5, read_timeout=0, clock=clock)
    with r:
        with pytest.raises(StaleDataError) as exc:
            r.latest()
        assert exc.value.age == float("inf") and exc.value.last_seq is None
        legs = [11, 22, 33, 44, 55, 66]
        r._ser.write(encode_packet(9, legs_to_channels(legs).tolist()))
        got = r.latest()
        assert got.seq == 9 and got.counts.tolist() == legs and got.age == 0
        clock.t += 0.4
        assert r.latest().age == pytest.approx(0.4)
        r._ser.write(encode_packet(9, legs_to_channels(legs).tolist()))  # frozen: same seq
        clock.t += 0.2
        with pytest.raises(StaleDataError, match="0.600 s old") as exc:
            r.latest()
        assert exc.value.last_seq == 9
        assert r.stats.duplicates == 1
        r._ser.write(encode_packet(10, [0] * 6))
        assert r.latest().seq == 10


def test_reader_read_times_out_with_stale_error():
    r = EncoderReader("loop://", stale_after=0.05, read_timeout=0.01)
    with r, pytest.raises(StaleDataError, match="no valid encoder packet"):
        r.read()


def test_reader_read_returns_each_packet_once():
    with EncoderReader("loop://", stale_after=0.05, read_timeout=0.01) as r:
        r._ser.write(encode_packet(1, [1] * 6))
        assert r.read().seq == 1
        with pytest.raises(StaleDataError):
            r.read()


def test_reader_legacy_unwraps():
    with EncoderReader("loop://", fmt="legacy", read_timeout=0) as r:
        r._ser.write(encode_legacy_line([0xFFFE, 1, 2, 3, 4, 5]))
        assert r.latest().counts[1] == -2  # channel A is leg 2
        r._ser.write(encode_legacy_line([3, 1, 2, 3, 4, 5]))
        assert r.latest().counts[1] == 3
    with EncoderReader("loop://", fmt="legacy", read_timeout=0, legacy_unwrap=False) as r:
        r._ser.write(encode_legacy_line([0xFFFE, 1, 2, 3, 4, 5]))
        assert r.latest().counts[1] == 0xFFFE


def test_reader_errors():
    with pytest.raises(InputError):
        EncoderReader("loop://", stale_after=0)
    with pytest.raises(InputError):
        EncoderReader("loop://", fmt="csv")
    with pytest.raises(DeviceError, match="cannot open"):
        EncoderReader("/dev/does-not-exist-kinestat").open()
