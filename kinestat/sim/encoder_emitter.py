"""A simulated encoder box: streams the platform's leg counts onto a pseudo-terminal.

It stands in for the thesis's FPGA + microcontroller + XBee link (Vibhute 2011 §3.2.3): at a
fixed rate it asks a callback for the six leg counts (legs 1..6), puts them on channels A..F
with the FPGA wiring, and writes one packet (``ks`` or ``legacy`` format, see
:mod:`kinestat.devices.encoder_stream`) to the master side of a pty. Open
:attr:`EncoderEmitter.path` (the slave side) with
:class:`~kinestat.devices.encoder_stream.EncoderReader` as if it were the USB serial receiver.

Fault injection: :meth:`~EncoderEmitter.drop` (packets lost on air: sequence numbers are
consumed), :meth:`~EncoderEmitter.corrupt` (one byte changed), :meth:`~EncoderEmitter.freeze`
(the same packet repeated: a frozen sensor), :meth:`~EncoderEmitter.silence` (nothing sent),
:meth:`~EncoderEmitter.inject` (raw bytes), and random ``drop_rate`` / ``corrupt_rate``.

Index pulses (Vibhute §3.2.2): with ``index_counts`` (each leg's count at its strip's index
mark, in the counts ``counts_now`` gives) the box keeps a counter per leg that follows the leg
but can lose counts (:meth:`~EncoderEmitter.miss`: a drift), and re-zeroes it when the leg
passes its index mark — the counter then reads the true count again — reporting the pulse in
the next ``ks`` frame's ``I`` field (:mod:`kinestat.hardware.encoder_packets`).
"""

from __future__ import annotations

import contextlib
import math
import os
import threading
import time
import tty
from collections.abc import Callable, Sequence

import numpy as np

from kinestat.errors import DeviceError, InputError, KinestatError
from kinestat.hardware.encoder_packets import (
    SEQ_MODULUS,
    THESIS_WIRING,
    Format,
    encode_legacy_line,
    encode_packet,
    legs_to_channels,
    legs_to_index_mask,
)


def constant_counts(counts: Sequence[float]) -> Callable[[], np.ndarray]:
    """A ``counts_now`` callback that always returns the same six leg counts."""
    c = np.asarray(counts, dtype=float)
    if c.shape != (6,) or not np.all(np.isfinite(c)):
        raise InputError(f"constant_counts: expected 6 finite leg counts, got {counts!r}")
    c = c.copy()
    return lambda: c


MAX_RATE_HZ = 5000.0
"""Fastest packet rate the emitter serves (Hz): a 34-byte frame at 115200 baud takes ~3 ms, so
beyond a few hundred Hz the pty only buffers; 5 kHz bounds the thread's work."""


class EncoderEmitter:
    """Stream counts from ``counts_now()`` (legs 1..6) onto a pty at ``rate_hz``.

    Use as a context manager, or call :meth:`start` / :meth:`stop`. Counts are rounded to the
    nearest integer; in the legacy format they wrap to 16 bits like the thesis's counters.
    If ``counts_now`` raises or returns something unusable, the emitter stops sending (a dead
    sensor) and keeps the exception in :attr:`error`.
    """

    def __init__(
        self,
        counts_now: Callable[[], Sequence[float]],
        *,
        rate_hz: float = 100.0,
        fmt: Format = "ks",
        wiring: Sequence[int] = THESIS_WIRING,
        start_seq: int = 0,
        drop_rate: float = 0.0,
        corrupt_rate: float = 0.0,
        seed: int | None = None,
        index_counts: Sequence[float] | None = None,
    ) -> None:
        if not callable(counts_now):
            raise InputError("EncoderEmitter: counts_now must be a callable returning 6 counts")
        if not (isinstance(rate_hz, (int, float)) and math.isfinite(rate_hz)
                and 0 < rate_hz <= MAX_RATE_HZ):
            raise InputError(f"EncoderEmitter: rate_hz must be in (0, {MAX_RATE_HZ:g}], got "
                             f"{rate_hz!r}")
        if fmt not in ("ks", "legacy"):
            raise InputError(f"EncoderEmitter: unknown format {fmt!r}; use 'ks' or 'legacy'")
        for name, p in (("drop_rate", drop_rate), ("corrupt_rate", corrupt_rate)):
            if not (isinstance(p, (int, float)) and 0.0 <= p <= 1.0):
                raise InputError(f"EncoderEmitter: {name} must be in [0, 1], got {p!r}")
        legs_to_channels(np.zeros(6), wiring)  # validates the wiring
        self._index = None
        if index_counts is not None:
            idx = np.asarray(index_counts, dtype=float)
            if idx.shape != (6,) or not np.all(np.isfinite(idx)):
                raise InputError(f"EncoderEmitter: index_counts must be 6 finite leg counts, "
                                 f"got {index_counts!r}")
            self._index = idx
        self._drift = np.zeros(6, dtype=np.int64)
        self._side: np.ndarray | None = None  # each leg's side of its index at the last frame
        self._pulsed = np.zeros(6, dtype=bool)
        self.counts_now = counts_now
        self.rate_hz = float(rate_hz)
        self.fmt: Format = fmt
        self.wiring = tuple(int(w) for w in wiring)
        self.drop_rate = float(drop_rate)
        self.corrupt_rate = float(corrupt_rate)
        self._rng = np.random.default_rng(seed)
        self._seq = int(start_seq) % SEQ_MODULUS
        self._lock = threading.Lock()
        self._drop_n = 0
        self._corrupt_n = 0
        self._frozen = False
        self._silent = False
        self._last_frame: bytes | None = None
        self._inject: list[bytes] = []
        self._master: int | None = None
        self._slave: int | None = None
        self._path: str | None = None
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self.sent = 0
        self.dropped = 0
        self.corrupted = 0
        self.overruns = 0
        self.error: BaseException | None = None

    # -- fault injection (thread-safe)
    def drop(self, n: int = 1) -> None:
        """Lose the next ``n`` packets on air (their sequence numbers are used up)."""
        with self._lock:
            self._drop_n += int(n)

    def corrupt(self, n: int = 1) -> None:
        """Change one byte in each of the next ``n`` packets."""
        with self._lock:
            self._corrupt_n += int(n)

    def freeze(self, enabled: bool = True) -> None:
        """Repeat the last packet unchanged (same sequence and counts): a frozen sensor."""
        with self._lock:
            self._frozen = bool(enabled)

    def silence(self, enabled: bool = True) -> None:
        """Stop sending (the link goes quiet) or resume."""
        with self._lock:
            self._silent = bool(enabled)

    def miss(self, leg: int, counts: int) -> None:
        """Leg ``leg`` (1..6)'s counter loses ``counts`` counts (signed: positive, it reads that
        many low), a drift that lasts until the leg passes its index mark (for good without
        ``index_counts``)."""
        if not (isinstance(leg, (int, np.integer)) and 1 <= int(leg) <= 6):
            raise InputError(f"EncoderEmitter.miss: leg must be 1..6, got {leg!r}")
        with self._lock:
            self._drift[int(leg) - 1] -= int(counts)

    def _box_counts(self, true: np.ndarray) -> tuple[np.ndarray, int | None]:
        """The box's counters for the true counts: the drift, re-zeroed at index crossings
        (a change of side of a leg's index mark since the last frame); the ``I`` mask."""
        if self._index is None:
            return true + self._drift, None
        side = np.sign(true - self._index)
        if self._side is not None:
            crossed = side != self._side
            self._drift[crossed] = 0
            self._pulsed |= crossed
        self._side = side
        mask = legs_to_index_mask(self._pulsed, self.wiring) if self.fmt == "ks" else None
        self._pulsed[:] = False
        return true + self._drift, mask

    def inject(self, raw: bytes) -> None:
        """Write ``raw`` bytes onto the line before the next packet (garbage, partial frames)."""
        with self._lock:
            self._inject.append(bytes(raw))

    # -- frames
    def _counts(self) -> np.ndarray:
        c = np.asarray(self.counts_now(), dtype=float)
        if c.shape != (6,) or not np.all(np.isfinite(c)):
            raise InputError(f"counts_now() returned {c!r}; expected 6 finite leg counts")
        return np.rint(c).astype(np.int64)

    def next_frame(self) -> bytes:
        """Build the bytes the emitter writes next, applying the injected faults.

        Returns ``b""`` when nothing is to be sent (dropped, silenced, or after an error).
        The streaming thread calls this; tests may call it directly without a pty.
        """
        with self._lock:
            out = b"".join(self._inject)
            self._inject.clear()
            if self._silent or self.error is not None:
                return out
            if self._frozen and self._last_frame is not None:
                frame = self._last_frame
            else:
                try:
                    legs, mask = self._box_counts(self._counts())
                    ch = legs_to_channels(legs, self.wiring)
                    if self.fmt == "ks":
                        frame = encode_packet(self._seq, ch.tolist(), index_mask=mask)
                        self._seq = (self._seq + 1) % SEQ_MODULUS
                    else:
                        frame = encode_legacy_line((ch & 0xFFFF).tolist())
                except Exception as exc:
                    self.error = exc
                    return out
                self._last_frame = frame
            if self._drop_n > 0 or (self.drop_rate and self._rng.random() < self.drop_rate):
                self._drop_n = max(0, self._drop_n - 1)
                self.dropped += 1
                return out
            if self._corrupt_n > 0 or (self.corrupt_rate
                                       and self._rng.random() < self.corrupt_rate):
                self._corrupt_n = max(0, self._corrupt_n - 1)
                self.corrupted += 1
                frame = self._damage(frame)
            self.sent += 1
            return out + frame

    def _damage(self, frame: bytes) -> bytes:
        b = bytearray(frame)
        # a byte inside the payload: after '$' / the legacy header, before the trailer
        lo, hi = (1, len(b) - 7) if self.fmt == "ks" else (4, len(b) - 3)
        i = int(self._rng.integers(lo, hi))
        new = b[i] ^ 0x01
        if new in (0x0A, 0x0D, 0x24, 0x2A):  # keep framing bytes out: a checksum fault only
            new = b[i] ^ 0x02
        b[i] = new
        return bytes(b)

    # -- life cycle
    @property
    def path(self) -> str:
        """Device path of the pty's slave side (open it with the reader)."""
        if self._path is None:
            raise DeviceError("EncoderEmitter: not started; call start() or use 'with'")
        return self._path

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def start(self) -> EncoderEmitter:
        """Open the pty and start streaming in a background thread."""
        if self._thread is not None:
            return self
        try:
            master, slave = os.openpty()
        except OSError as exc:
            raise DeviceError(f"EncoderEmitter: cannot open a pseudo-terminal: {exc}") from exc
        tty.setraw(slave)  # no echo, no line editing, 8-bit clean
        os.set_blocking(master, False)
        self._master, self._slave = master, slave
        self._path = os.ttyname(slave)
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="encoder-emitter", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop streaming and close the pty (readers then see the device vanish)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None
        for fd in (self._master, self._slave):
            if fd is not None:
                with contextlib.suppress(OSError):
                    os.close(fd)
        self._master = self._slave = None

    def __enter__(self) -> EncoderEmitter:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _run(self) -> None:
        period = 1.0 / self.rate_hz
        next_t = time.monotonic()
        while not self._stop.is_set():
            try:
                data = self.next_frame()
            except KinestatError as exc:  # pragma: no cover - next_frame keeps its errors
                self.error = exc
                data = b""
            if data:
                self._write(data)
            next_t += period
            delay = next_t - time.monotonic()
            if delay < -period:  # fell behind (suspended?): do not burst to catch up
                next_t = time.monotonic()
                delay = 0.0
            self._stop.wait(max(0.0, delay))

    def _write(self, data: bytes) -> None:
        fd = self._master
        if fd is None:
            return
        try:
            n = os.write(fd, data)
        except BlockingIOError:
            n = 0
        except OSError:
            return
        if n < len(data):  # nobody reading and the pty buffer is full: bytes are lost
            self.overruns += 1
