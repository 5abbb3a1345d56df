"""The platform's encoder stream: incremental parser and serial reader.

The packet codec and the channel wiring are :mod:`kinestat.hardware.encoder_packets`.

Two wire formats are understood (see ``docs/devices.md`` for the full specification):

``ks`` — kinestat's framed ASCII line (written and read)::

    $KS,<seq:4 hex>,A<count:8 hex>,B<...>,C<...>,D<...>,E<...>,F<...>*<crc:4 hex>\\r\\n

  ``seq`` is a 16-bit sequence number that wraps 0xFFFF -> 0x0000; each count is a signed
  32-bit integer in two's complement; the CRC is CRC-16/CCITT-FALSE (polynomial 0x1021,
  initial value 0xFFFF) over every byte between ``$`` and ``*``. A frame is 75 bytes.

``legacy`` — the thesis's 23-byte line (read; the emitter can also write it)
  (Vibhute 2011 §3.2.3 and App. D.6 ``serialdaq_plat.m``): bytes 4, 7, 10, 13, 16, 19 (1-based)
  are the tags ``A``..``F``, each followed by ONE 16-bit count as two raw bytes, high byte
  first; the line ends with LF (which MATLAB's ``fgetl`` strips). Bytes 1-3 and 22-23 are not
  interpreted. No sequence number, no checksum.

Packets carry counts in channel order A..F. The thesis's FPGA wiring puts leg 2 on A, leg 1 on
B, leg 6 on C, leg 5 on D, leg 4 on E and leg 3 on F (:data:`THESIS_WIRING`); the reader maps
channels to legs 1..6 with that wiring unless told otherwise.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from kinestat.errors import DeviceError, InputError, ProtocolError
from kinestat.hardware.encoder_packets import (
    CHANNELS,
    COUNT_MAX,
    COUNT_MIN,
    SEQ_MODULUS,
    THESIS_WIRING,
    Format,
    Packet,
    channels_to_legs,
    check_wiring,
    crc16_ccitt,
    decode_legacy_line,
    decode_packet,
    encode_legacy_line,
    encode_packet,
    index_mask_to_legs,
    legs_to_channels,
    unwrap16,
)

__all__ = [
    "TooManyFaultsError",
    # re-exported from kinestat.hardware.encoder_packets (documented in docs/devices.md)
    "CHANNELS",
    "COUNT_MAX",
    "COUNT_MIN",
    "SEQ_MODULUS",
    "THESIS_WIRING",
    "Format",
    "Packet",
    "channels_to_legs",
    "crc16_ccitt",
    "decode_legacy_line",
    "decode_packet",
    "encode_legacy_line",
    "encode_packet",
    "index_mask_to_legs",
    "legs_to_channels",
    "unwrap16",
    # the stream
    "DEFAULT_BAUDRATE",
    "MAX_FRAME",
    "FaultKind",
    "StreamFault",
    "Event",
    "StreamStats",
    "StreamParser",
    "StaleDataError",
    "Reading",
    "StreamMark",
    "sampled_after",
    "EncoderReader",
]

DEFAULT_BAUDRATE = 115200
"""The XBee link's rate (Vibhute App. D.6)."""

MAX_FRAME = 128
"""A ``ks`` frame longer than this without its LF is declared broken (the real one is 75)."""

FaultKind = Literal["framing", "checksum", "gap", "duplicate", "out_of_order", "restart"]
"""What a :class:`StreamFault` is about."""


@dataclass(frozen=True)
class StreamFault:
    """A problem found in the stream, reported in order with the packets.

    ``kind`` is one of ``"framing"`` (garbage, truncated or over-long frame), ``"checksum"``,
    ``"gap"`` (``lost`` packets are missing before ``seq``), ``"duplicate"`` (``seq`` repeated:
    a frozen sensor), ``"out_of_order"`` (``seq`` behind the last accepted one; dropped) or
    ``"restart"`` (the sender's sequence restarted; accepted).
    """

    kind: FaultKind
    message: str
    seq: int | None = None
    lost: int = 0


Event = Packet | StreamFault



# --------------------------------------------------------------------------- parser


@dataclass
class StreamStats:
    """Counters kept by a :class:`StreamParser` over its lifetime."""

    packets: int = 0
    lost: int = 0
    checksum: int = 0
    framing: int = 0
    duplicates: int = 0
    out_of_order: int = 0
    restarts: int = 0
    index_pulses: int = 0


class StreamParser:
    """Incremental parser: feed it byte chunks of any size, get packets and faults in order.

    It never raises on stream content: garbage is skipped up to the next frame start and
    reported once per run as a ``framing`` fault. In the ``ks`` format it also tracks the
    sequence: a gap reports the number of lost packets (the packet itself is delivered), a
    repeated sequence number is a ``duplicate`` (dropped), a sequence number behind the last
    one is ``out_of_order`` (dropped) unless two consecutive such packets show that the sender
    restarted, which is reported as ``restart`` and followed.
    """

    def __init__(self, fmt: Format = "ks") -> None:
        if fmt not in ("ks", "legacy"):
            raise InputError(f"unknown encoder stream format {fmt!r}; use 'ks' or 'legacy'")
        self.fmt: Format = fmt
        self.stats = StreamStats()
        self._buf = bytearray()
        self._last_seq: int | None = None
        self._behind: int | None = None  # seq of the last out-of-order packet

    def reset(self) -> None:
        """Forget buffered bytes and the sequence history (counters are kept)."""
        self._buf.clear()
        self._last_seq = None
        self._behind = None

    def feed(self, chunk: bytes) -> list[Event]:
        """Consume ``chunk``; return the packets and faults completed by it, in stream order."""
        if not isinstance(chunk, (bytes, bytearray, memoryview)):
            raise InputError(f"StreamParser.feed expects bytes, got {type(chunk).__name__}")
        self._buf += chunk
        return self._drain_ks() if self.fmt == "ks" else self._drain_legacy()

    # -- ks
    def _framing(self, message: str) -> StreamFault:
        self.stats.framing += 1
        return StreamFault("framing", message)

    def _drain_ks(self) -> list[Event]:
        out: list[Event] = []
        buf = self._buf
        while buf:
            start = buf.find(b"$")
            if start < 0:
                junk = bytes(buf).strip(b"\r\n")
                if len(buf) > MAX_FRAME or b"\n" in buf:
                    if junk:
                        out.append(self._framing(f"{len(junk)} bytes of garbage skipped"))
                    buf.clear()
                break
            if start > 0:
                junk = bytes(buf[:start]).strip(b"\r\n")
                if junk:
                    out.append(self._framing(f"{len(junk)} bytes of garbage before '$' skipped"))
                del buf[:start]
            nl = buf.find(b"\n")
            nxt = buf.find(b"$", 1)
            if nxt >= 0 and (nl < 0 or nxt < nl):
                out.append(self._framing("truncated frame (a new '$' before its end) dropped"))
                del buf[:nxt]
                continue
            if nl < 0:
                if len(buf) > MAX_FRAME:
                    out.append(self._framing(f"no end of frame within {MAX_FRAME} bytes"))
                    del buf[:1]
                    continue
                break
            frame = bytes(buf[: nl + 1])
            del buf[: nl + 1]
            if len(frame) > MAX_FRAME + 1:
                out.append(self._framing(f"frame of {len(frame)} bytes is too long"))
                continue
            try:
                pkt = decode_packet(frame)
            except ProtocolError as exc:
                if "checksum mismatch" in str(exc):
                    self.stats.checksum += 1
                    out.append(StreamFault("checksum", str(exc)))
                else:
                    out.append(self._framing(str(exc)))
                continue
            out.extend(self._sequence(pkt))
        return out

    def _sequence(self, pkt: Packet) -> list[Event]:
        seq = pkt.seq
        assert seq is not None
        last = self._last_seq
        if last is None:
            self._accept(pkt)
            return [pkt]
        d = (seq - last) % SEQ_MODULUS
        if d == 1:
            self._accept(pkt)
            return [pkt]
        if d == 0:
            self.stats.duplicates += 1
            return [StreamFault("duplicate", f"sequence {seq:04X} repeated (frozen sensor?)",
                                seq=seq)]
        if d < SEQ_MODULUS // 2:
            lost = d - 1
            self.stats.lost += lost
            self._accept(pkt)
            return [StreamFault("gap", f"{lost} packet(s) lost before sequence {seq:04X}",
                                seq=seq, lost=lost), pkt]
        # behind the last accepted packet
        if self._behind is not None and (seq - self._behind) % SEQ_MODULUS == 1:
            self.stats.restarts += 1
            self._accept(pkt)
            return [StreamFault("restart", f"sender sequence restarted at {seq:04X}", seq=seq),
                    pkt]
        self._behind = seq
        self.stats.out_of_order += 1
        return [StreamFault("out_of_order",
                            f"sequence {seq:04X} is behind the last one {last:04X}; dropped",
                            seq=seq)]

    def _accept(self, pkt: Packet) -> None:
        self._last_seq = pkt.seq
        self._behind = None
        self.stats.packets += 1

    # -- legacy
    def _drain_legacy(self) -> list[Event]:
        out: list[Event] = []
        buf = self._buf
        while True:
            nl = buf.find(b"\n")
            if nl < 0:
                if len(buf) > MAX_FRAME:
                    out.append(self._framing(f"no LF within {MAX_FRAME} bytes; buffer dropped"))
                    buf.clear()
                break
            line = bytes(buf[:nl])
            del buf[: nl + 1]
            if not line:
                continue
            try:
                pkt = decode_legacy_line(line)
            except ProtocolError as exc:
                out.append(self._framing(str(exc)))
                continue
            self.stats.packets += 1
            out.append(pkt)
        return out


# --------------------------------------------------------------------------- reader


class StaleDataError(ProtocolError):
    """No fresh valid encoder packet within the allowed time (no packets, or a frozen sequence).

    ``age`` is the time since the last fresh packet (``inf`` if none ever arrived) and
    ``last_seq`` its sequence number (None if none, or in the legacy format).
    """

    def __init__(self, message: str, *, age: float, last_seq: int | None) -> None:
        self.age = age
        self.last_seq = last_seq
        super().__init__(message)


class TooManyFaultsError(ProtocolError):
    """More stream faults than allowed arrived while waiting for a fresh packet
    (:meth:`EncoderReader.read` with ``max_faults``); ``faults`` are those faults."""

    def __init__(self, message: str, *, faults: tuple[StreamFault, ...]) -> None:
        self.faults = faults
        super().__init__(message)


@dataclass(frozen=True)
class Reading:
    """The latest valid counts: ``counts`` per leg 1..6, ``channel_counts`` per channel A..F.

    ``age`` is the time in seconds between its arrival and the call that returned it;
    ``received_at`` is when the READER took it off the line, not when the box sampled it.
    ``index`` is the packet's ordinal in the reader (1 for the first packet it took).
    ``index_legs``: the legs (1..6) whose index pulse re-zeroed their count since the previous
    reading returned (over every packet taken since, so none is missed); ``referenced``: six
    flags, the legs that have passed their index since the reader opened (their counts count
    from the index, as the calibration's do; before that, from wherever the box powered up);
    None when the stream does not report index pulses (legacy lines, ``ks`` without the
    ``I`` field).
    """

    seq: int | None
    counts: np.ndarray
    channel_counts: tuple[int, ...]
    received_at: float
    age: float
    fmt: Format = "ks"
    faults: tuple[StreamFault, ...] = field(default=())
    index: int = 0
    index_legs: tuple[int, ...] = ()
    referenced: tuple[bool, ...] | None = None


@dataclass(frozen=True)
class StreamMark:
    """Where a drained stream stood (:meth:`EncoderReader.drain`): ``index`` packets taken so
    far and the last one's sequence number ``seq`` (None if none, or in the legacy format)."""

    index: int
    seq: int | None = None


def sampled_after(reading: Reading, mark: StreamMark, skip: int = 1) -> bool:
    """True when ``reading`` comes more than ``skip`` packets after ``mark``: then it was
    SAMPLED after the drain that made the mark, whatever its arrival time.

    The packet following the mark may have been sampled before the drain and been on its way
    (in the box, on air, in the receiver's buffer) during it; with a box that samples at a
    fixed rate and delivers each packet within ``skip`` periods, the ones after it were
    sampled after the drain. Packets are counted by the reader (``index``: works for both
    formats, and packets lost on air only make it wait longer); in the ``ks`` format a
    sequence number advanced by more than ``skip`` (lost packets included, a restart
    excluded) also counts.

    >>> m = StreamMark(index=10, seq=0xFFFF)
    >>> def r(seq, index):
    ...     return Reading(seq, np.zeros(6), (0,) * 6, received_at=0.0, age=0.0, index=index)
    >>> sampled_after(r(0, 11), m), sampled_after(r(1, 11), m), sampled_after(r(None, 12), m)
    (False, True, True)
    """
    if reading.index - mark.index > skip:
        return True
    if reading.seq is None or mark.seq is None:
        return False
    return skip < (reading.seq - mark.seq) % SEQ_MODULUS < SEQ_MODULUS // 2


class EncoderReader:
    """Read the platform's encoder stream from a serial device or pyserial URL.

    ``port`` is a device path (``/dev/ttyUSB0``, the emitter's pty) or any pyserial URL
    (``loop://``, ``socket://host:port``, ...). ``stale_after`` (s) is how old the last fresh
    packet may be before :meth:`latest` / :meth:`read` raise :class:`StaleDataError`. A packet
    is fresh when its sequence number advances; repeated sequence numbers (a frozen sensor)
    do not refresh. In the legacy format, without sequence numbers, every valid line is fresh,
    so a frozen sensor cannot be told from a platform at rest — only silence is detected.
    Legacy counts are unwrapped from 16 bits (:func:`unwrap16`) unless ``legacy_unwrap=False``.
    """

    def __init__(
        self,
        port: str,
        *,
        fmt: Format = "ks",
        baudrate: int = DEFAULT_BAUDRATE,
        stale_after: float = 0.25,
        read_timeout: float = 0.02,
        wiring: Sequence[int] = THESIS_WIRING,
        legacy_unwrap: bool = True,
        clock: Callable[[], float] = time.monotonic,
        serial_factory: Callable[..., Any] | None = None,
    ) -> None:
        if not (isinstance(stale_after, (int, float)) and stale_after > 0
                and math.isfinite(stale_after)):
            raise InputError(f"stale_after must be a positive number of seconds, got "
                             f"{stale_after!r}")
        if not (isinstance(read_timeout, (int, float)) and read_timeout >= 0):
            raise InputError(f"read_timeout must be >= 0 seconds, got {read_timeout!r}")
        self.port = port
        self.fmt: Format = fmt
        self.baudrate = baudrate
        self.stale_after = float(stale_after)
        self.read_timeout = float(read_timeout)
        self.wiring = check_wiring(wiring)
        self.legacy_unwrap = legacy_unwrap
        self._clock = clock
        self._factory = serial_factory
        self.parser = StreamParser(fmt)
        self._ser: Any = None
        self._latest: Packet | None = None
        self._latest_legs: np.ndarray | None = None
        self._latest_t: float | None = None
        self._latest_id = 0
        self._returned_id = 0
        self._pending_faults: list[StreamFault] = []
        self._index_since = np.zeros(6, dtype=bool)
        self._referenced: np.ndarray | None = None

    # -- life cycle
    def open(self) -> EncoderReader:
        """Open the serial port (idempotent); raises :class:`DeviceError` if it cannot."""
        if self._ser is not None:
            return self
        import serial  # lazy: pyserial is loaded only when a port is used

        factory = self._factory or serial.serial_for_url
        try:
            self._ser = factory(self.port, baudrate=self.baudrate, timeout=self.read_timeout)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise DeviceError(
                f"cannot open encoder stream {self.port!r}: {exc}. Check the device path or "
                "URL and that the emitter/receiver is running"
            ) from exc
        return self

    def close(self) -> None:
        """Close the port (idempotent)."""
        ser, self._ser = self._ser, None
        if ser is not None:
            try:
                ser.close()
            except Exception:
                pass

    def __enter__(self) -> EncoderReader:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def stats(self) -> StreamStats:
        """Stream counters (packets, lost, checksum, framing, duplicates, ...)."""
        return self.parser.stats

    # -- I/O
    def poll(self) -> list[Event]:
        """Read what has arrived (waiting at most ``read_timeout``); return its events."""
        return self._consume(self._read_chunk(wait=True))

    def drain(self, max_chunks: int = 64) -> StreamMark:
        """Take in every byte already waiting, without waiting for more (at most
        ``max_chunks`` reads), and return where the stream now stands: the mark from which
        :func:`sampled_after` tells packets sampled after this moment."""
        for _ in range(max_chunks):
            data = self._read_chunk(wait=False)
            if not data:
                break
            self._consume(data)
        return StreamMark(index=self._latest_id,
                          seq=None if self._latest is None else self._latest.seq)

    def _read_chunk(self, *, wait: bool) -> bytes:
        import serial  # lazy: pyserial is loaded only when a port is used

        if self._ser is None:
            self.open()
        try:
            waiting = self._ser.in_waiting
            if not waiting and not wait:
                return b""
            return self._ser.read(max(1, waiting))
        except (serial.SerialException, OSError) as exc:
            raise DeviceError(f"encoder stream {self.port!r} failed while reading: {exc}. "
                              "The device was unplugged or the emitter stopped") from exc

    def _consume(self, data: bytes) -> list[Event]:
        if not data:
            return []
        now = self._clock()
        events = self.parser.feed(data)
        for ev in events:
            if isinstance(ev, Packet):
                self._take(ev, now)
            else:
                self._pending_faults.append(ev)
        return events

    def _take(self, pkt: Packet, now: float) -> None:
        legs = channels_to_legs(pkt.counts, self.wiring)
        if pkt.fmt == "legacy" and self.legacy_unwrap:
            legs = unwrap16(self._latest_legs, legs)
        self._latest, self._latest_legs, self._latest_t = pkt, legs, now
        self._latest_id += 1
        if pkt.index_mask is not None:  # the box re-zeroed these legs at their index pulse
            hit = index_mask_to_legs(pkt.index_mask, self.wiring)
            self.parser.stats.index_pulses += int(hit.sum())
            self._index_since |= hit
            self._referenced = hit if self._referenced is None else self._referenced | hit

    def _reading(self, now: float) -> Reading:
        assert self._latest is not None and self._latest_t is not None
        assert self._latest_legs is not None
        faults, self._pending_faults = tuple(self._pending_faults), []
        hit, self._index_since = self._index_since, np.zeros(6, dtype=bool)
        ref = None if self._referenced is None else tuple(bool(b) for b in self._referenced)
        return Reading(seq=self._latest.seq, counts=self._latest_legs.copy(),
                       channel_counts=self._latest.counts, received_at=self._latest_t,
                       age=now - self._latest_t, fmt=self._latest.fmt, faults=faults,
                       index=self._latest_id,
                       index_legs=tuple(int(k) + 1 for k in np.flatnonzero(hit)),
                       referenced=ref)

    def _stale(self, now: float, why: str) -> StaleDataError:
        age = math.inf if self._latest_t is None else now - self._latest_t
        seq = None if self._latest is None else self._latest.seq
        st = self.parser.stats
        if self._latest_t is None:
            what = "no valid encoder packet has arrived"
        else:
            what = f"the last fresh encoder packet (seq {seq}) is {age:.3f} s old"
        return StaleDataError(
            f"stale encoder data on {self.port!r}: {what} ({why}; {st.duplicates} duplicate, "
            f"{st.checksum} corrupt, {st.framing} framing faults so far). Check the sensor "
            "link; do not act on old counts",
            age=age, last_seq=seq)

    def latest(self, max_age: float | None = None) -> Reading:
        """The latest valid counts after one :meth:`poll` (at most ``read_timeout``).

        Raises :class:`StaleDataError` if the last fresh packet is older than ``max_age``
        (default ``stale_after``) or none has arrived.
        """
        self.poll()
        now = self._clock()
        limit = self.stale_after if max_age is None else float(max_age)
        if self._latest_t is None or now - self._latest_t > limit:
            raise self._stale(now, f"limit {limit:.3f} s")
        self._returned_id = self._latest_id
        return self._reading(now)

    def read(self, timeout: float | None = None, *, max_faults: int | None = None) -> Reading:
        """Wait for a packet newer than the last one returned (by :meth:`read` or
        :meth:`latest`); :class:`StaleDataError` if none arrives in time.

        ``timeout`` defaults to ``stale_after``. With ``max_faults``, more stream faults than
        that while waiting raise :class:`TooManyFaultsError` at once (carrying them), so a
        burst of corrupt packets is reported as such however slowly it arrives. Repeated
        packets (``duplicate``) do not count there: a frozen sensor is a staleness, reported
        by the stale timer.
        """
        limit = self.stale_after if timeout is None else float(timeout)
        t_end = self._clock() + limit
        while True:
            self.poll()
            now = self._clock()
            if self._latest_id != self._returned_id:
                self._returned_id = self._latest_id
                return self._reading(now)
            if max_faults is not None and sum(
                    f.kind != "duplicate" for f in self._pending_faults) > max_faults:
                faults, self._pending_faults = tuple(self._pending_faults), []
                raise TooManyFaultsError(f"encoder stream {self.port!r}: {len(faults)} stream "
                                         f"faults while waiting for a packet (limit "
                                         f"{max_faults})", faults=faults)
            if now >= t_end:
                raise self._stale(now, f"no new packet within {limit:.3f} s")
