"""The platform's encoder box on the wire: packet formats and channel wiring (pure codec).

Two wire formats (see ``docs/devices.md`` for the full specification):

``ks`` — kinestat's framed ASCII line::

    $KS,<seq:4 hex>,A<count:8 hex>,B<...>,C<...>,D<...>,E<...>,F<...>*<crc:4 hex>\\r\\n

  ``seq`` is a 16-bit sequence number that wraps 0xFFFF -> 0x0000; each count is a signed
  32-bit integer in two's complement; the CRC is CRC-16/CCITT-FALSE (polynomial 0x1021,
  initial value 0xFFFF) over every byte between ``$`` and ``*``. A frame is 75 bytes.
  A box that reports its legs' index pulses adds ``,I<mask:2 hex>`` before the ``*`` (79
  bytes): bit k set when channel k's index pulse passed since the previous frame, and with it
  the box re-zeroed that channel's counter (Vibhute 2011 §3.2.2: "every time an index pulse
  shows up, the sensor is supposed to zero its position"), so the counts already start again
  from the index. Frames without the field say nothing about index pulses.

``legacy`` — the thesis's 23-byte line (Vibhute 2011 §3.2.3 and App. D.6
  ``serialdaq_plat.m``): bytes 4, 7, 10, 13, 16, 19 (1-based) are the tags ``A``..``F``, each
  followed by ONE 16-bit count as two raw bytes, high byte first; the line ends with LF.

Packets carry counts in channel order A..F; the thesis's FPGA wiring (:data:`THESIS_WIRING`)
maps channels to legs. Shared by the reader (:mod:`kinestat.devices.encoder_stream`) and the
emitter (:mod:`kinestat.sim.encoder_emitter`).
"""

from __future__ import annotations

import binascii
import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from kinestat.errors import InputError, ProtocolError

__all__ = [
    "CHANNELS",
    "THESIS_WIRING",
    "SEQ_MODULUS",
    "COUNT_MIN",
    "COUNT_MAX",
    "LEGACY_LINE_LENGTH",
    "LEGACY_TAG_OFFSETS",
    "Format",
    "Packet",
    "crc16_ccitt",
    "encode_packet",
    "decode_packet",
    "encode_legacy_line",
    "index_mask_to_legs",
    "legs_to_index_mask",
    "decode_legacy_line",
    "unwrap16",
    "channels_to_legs",
    "legs_to_channels",
    "check_wiring",
]

CHANNELS = "ABCDEF"
"""Channel tags in packet order."""

THESIS_WIRING: tuple[int, ...] = (2, 1, 6, 5, 4, 3)
"""Leg number (1-based) carried by channels A..F (Vibhute App. D.6 ``serialdaq_plat.m``)."""

SEQ_MODULUS = 1 << 16
"""Sequence numbers are 16-bit and wrap around."""

COUNT_MIN = -(1 << 31)
COUNT_MAX = (1 << 31) - 1
"""Range of a count in the ``ks`` format (signed 32-bit)."""

LEGACY_LINE_LENGTH = 23
"""Bytes in a legacy line without its LF terminator (``serialdaq_plat.m``: ``m==23``)."""

LEGACY_TAG_OFFSETS = (3, 6, 9, 12, 15, 18)
"""0-based offsets of the tags 'A'..'F' in a legacy line (1-based 4, 7, ..., 19)."""

_KS_BODY = re.compile(
    rb"KS,([0-9A-F]{4}),A([0-9A-F]{8}),B([0-9A-F]{8}),C([0-9A-F]{8}),"
    rb"D([0-9A-F]{8}),E([0-9A-F]{8}),F([0-9A-F]{8})(?:,I([0-9A-F]{2}))?"
)

Format = Literal["ks", "legacy"]


@dataclass(frozen=True)
class Packet:
    """One decoded packet: ``counts`` in channel order A..F; ``seq`` is None for legacy lines;
    ``index_mask`` the channels whose index pulse re-zeroed them since the previous frame (bit
    k: channel k), None when the frame does not say (legacy lines, ``ks`` without the field)."""

    seq: int | None
    counts: tuple[int, ...]
    fmt: Format = "ks"
    index_mask: int | None = None




def crc16_ccitt(data: bytes) -> int:
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection); check value 0x29B1."""
    return binascii.crc_hqx(data, 0xFFFF)


def _check_counts(counts: Iterable[Any], lo: int, hi: int, what: str) -> tuple[int, ...]:
    try:
        vals = list(counts)
    except TypeError as exc:
        raise InputError(f"{what}: expected 6 integer counts, got {counts!r}") from exc
    if len(vals) != 6:
        raise InputError(f"{what}: expected 6 counts (channels A..F), got {len(vals)}")
    out = []
    for ch, v in zip(CHANNELS, vals, strict=True):
        try:
            f = float(v)
        except (TypeError, ValueError) as exc:
            raise InputError(f"{what}: channel {ch} count {v!r} is not a number") from exc
        if not math.isfinite(f) or f != math.floor(f):
            raise InputError(f"{what}: channel {ch} count {v!r} is not a finite integer")
        i = int(f) if not isinstance(v, (int, np.integer)) else int(v)
        if not lo <= i <= hi:
            raise InputError(f"{what}: channel {ch} count {i} is outside [{lo}, {hi}]")
        out.append(i)
    return tuple(out)


def encode_packet(seq: int, counts: Sequence[int], index_mask: int | None = None) -> bytes:
    """Encode one ``ks`` frame: sequence number 0..65535 and six signed 32-bit counts (A..F);
    with ``index_mask`` (0..63, bit k: channel k re-zeroed at its index) the ``I`` field."""
    if isinstance(seq, bool) or not isinstance(seq, (int, np.integer)):
        raise InputError(f"encode_packet: sequence number must be an integer, got {seq!r}")
    if not 0 <= int(seq) < SEQ_MODULUS:
        raise InputError(f"encode_packet: sequence number {seq} outside 0..65535 (wrap it)")
    vals = _check_counts(counts, COUNT_MIN, COUNT_MAX, "encode_packet")
    body = f"KS,{int(seq):04X}," + ",".join(
        f"{ch}{v & 0xFFFFFFFF:08X}" for ch, v in zip(CHANNELS, vals, strict=True)
    )
    if index_mask is not None:
        if isinstance(index_mask, bool) or not isinstance(index_mask, (int, np.integer)) \
                or not 0 <= int(index_mask) < 64:
            raise InputError(f"encode_packet: index_mask must be an integer in 0..63 (one bit "
                             f"per channel A..F), got {index_mask!r}")
        body += f",I{int(index_mask):02X}"
    raw = body.encode("ascii")
    return b"$" + raw + b"*" + f"{crc16_ccitt(raw):04X}".encode("ascii") + b"\r\n"


def _signed32(u: int) -> int:
    return u - (1 << 32) if u & 0x80000000 else u


def decode_packet(data: bytes) -> Packet:
    """Decode one ``ks`` frame (with or without its CR LF); raises :class:`ProtocolError`."""
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise InputError(f"decode_packet: expected bytes, got {type(data).__name__}")
    frame = bytes(data).rstrip(b"\r\n")
    if not frame.startswith(b"$"):
        raise ProtocolError(f"encoder packet does not start with '$': {frame[:20]!r}")
    star = frame.rfind(b"*")
    if star < 0 or len(frame) - star != 5:
        raise ProtocolError(f"encoder packet has no '*<crc:4 hex>' trailer: {frame[-12:]!r}")
    body, crc_txt = frame[1:star], frame[star + 1 :]
    if not re.fullmatch(rb"[0-9A-F]{4}", crc_txt):
        raise ProtocolError(f"encoder packet checksum field {crc_txt!r} is not 4 hex digits")
    want, got = int(crc_txt, 16), crc16_ccitt(body)
    if want != got:
        raise ProtocolError(
            f"encoder packet checksum mismatch (frame says {want:04X}, data gives {got:04X}): "
            "the packet was corrupted in transit; discard it"
        )
    m = _KS_BODY.fullmatch(body)
    if m is None:
        raise ProtocolError(
            f"encoder packet body {body[:40]!r}... does not follow "
            "'KS,<seq4>,A<hex8>,...,F<hex8>' (upper-case hex)"
        )
    seq = int(m.group(1), 16)
    counts = tuple(_signed32(int(g, 16)) for g in m.groups()[1:7])
    mask = None if m.group(8) is None else int(m.group(8), 16)
    if mask is not None and mask >= 64:
        raise ProtocolError(f"encoder packet index field I{m.group(8).decode()} sets a bit "
                            "beyond channel F")
    return Packet(seq=seq, counts=counts, fmt="ks", index_mask=mask)


def encode_legacy_line(
    counts: Sequence[int], header: bytes = b"ENC", trailer: bytes = b" \r"
) -> bytes:
    """Encode a thesis-style 23-byte line plus LF: 16-bit unsigned counts, high byte first.

    ``header`` (3 bytes) and ``trailer`` (2 bytes) fill the positions the thesis code does not
    read; their real content is not recorded in the thesis (our choice, see docs/devices.md).
    A count whose bytes include 0x0A (LF) produces a line that a reader will split: the legacy
    format cannot protect against that, which is one reason for the ``ks`` format.
    """
    if len(header) != 3 or len(trailer) != 2:
        raise InputError("encode_legacy_line: header must be 3 bytes and trailer 2 bytes")
    vals = _check_counts(counts, 0, 0xFFFF, "encode_legacy_line")
    body = b"".join(ch.encode() + v.to_bytes(2, "big") for ch, v in zip(CHANNELS, vals,
                                                                          strict=True))
    return header + body + trailer + b"\n"


def decode_legacy_line(line: bytes) -> Packet:
    """Decode a thesis-style line (23 bytes, LF already stripped or not); :class:`ProtocolError`.

    Counts are returned raw (0..65535); see :func:`unwrap16` for counters that cross zero.
    """
    if not isinstance(line, (bytes, bytearray, memoryview)):
        raise InputError(f"decode_legacy_line: expected bytes, got {type(line).__name__}")
    b = bytes(line)
    if b.endswith(b"\n"):
        b = b[:-1]
    if len(b) != LEGACY_LINE_LENGTH:
        raise ProtocolError(
            f"legacy encoder line has {len(b)} bytes, expected {LEGACY_LINE_LENGTH} "
            "(a count byte equal to LF splits the line; discard it)"
        )
    for ch, off in zip(CHANNELS, LEGACY_TAG_OFFSETS, strict=True):
        if b[off] != ord(ch):
            raise ProtocolError(
                f"legacy encoder line: byte {off + 1} is 0x{b[off]:02X}, expected tag "
                f"'{ch}' (0x{ord(ch):02X})"
            )
    counts = tuple(int.from_bytes(b[off + 1 : off + 3], "big") for off in LEGACY_TAG_OFFSETS)
    return Packet(seq=None, counts=counts, fmt="legacy")


def unwrap16(previous: np.ndarray | Sequence[int] | None, raw: Sequence[int]) -> np.ndarray:
    """Unwrap 16-bit counter values against the previous unwrapped values.

    Each channel moves to the value congruent to ``raw`` modulo 65536 nearest ``previous``
    (valid while a leg moves less than 32768 counts between packets: 832 mm at 0.0254
    mm/count). With no previous value, ``raw`` is read as signed 16-bit (two's complement).
    """
    r = np.asarray(raw, dtype=np.int64) & 0xFFFF
    if previous is None:
        return np.where(r >= 0x8000, r - 0x10000, r)
    p = np.asarray(previous, dtype=np.int64)
    delta = (r - p) & 0xFFFF
    delta = np.where(delta >= 0x8000, delta - 0x10000, delta)
    return p + delta


def channels_to_legs(channel_counts: Sequence[int], wiring: Sequence[int] = THESIS_WIRING
                     ) -> np.ndarray:
    """Reorder counts from channels A..F to legs 1..6 (``wiring[k]`` = leg on channel k)."""
    w = check_wiring(wiring)
    c = np.asarray(channel_counts, dtype=np.int64)
    out = np.empty(c.shape, dtype=np.int64)
    out[..., np.asarray(w) - 1] = c
    return out


def legs_to_channels(leg_counts: Sequence[int], wiring: Sequence[int] = THESIS_WIRING
                     ) -> np.ndarray:
    """Reorder counts from legs 1..6 to channels A..F (inverse of :func:`channels_to_legs`)."""
    w = check_wiring(wiring)
    c = np.asarray(leg_counts, dtype=np.int64)
    return c[..., np.asarray(w) - 1]


def index_mask_to_legs(mask: int, wiring: Sequence[int] = THESIS_WIRING) -> np.ndarray:
    """A channel bit mask (bit k: channel k) as six flags in leg order 1..6.

    >>> index_mask_to_legs(0b000010).tolist()  # channel B carries leg 1 (thesis wiring)
    [True, False, False, False, False, False]
    """
    bits = np.array([(int(mask) >> k) & 1 for k in range(6)], dtype=bool)
    return channels_to_legs(bits, wiring).astype(bool)


def legs_to_index_mask(flags: Sequence[bool], wiring: Sequence[int] = THESIS_WIRING) -> int:
    """Six flags in leg order 1..6 as a channel bit mask (inverse of
    :func:`index_mask_to_legs`)."""
    ch = legs_to_channels(np.asarray(flags, dtype=bool).astype(np.int64), wiring)
    return int(sum(int(b) << k for k, b in enumerate(ch.tolist())))


def check_wiring(wiring: Sequence[int]) -> tuple[int, ...]:
    w = tuple(int(x) for x in wiring)
    if sorted(w) != [1, 2, 3, 4, 5, 6]:
        raise InputError(f"wiring must be a permutation of legs 1..6 for channels A..F, got {w}")
    return w
