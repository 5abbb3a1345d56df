"""Seeded fault injection on the hardware path: a TCP proxy that damages the reply to the
N-th command it forwards (:class:`FaultProxy`), and a wrapper that damages the encoder byte
stream at the N-th chunk the reader takes in (:func:`corrupt_stream`).

Wire faults (:data:`WIRE_FAULTS`), applied to the reply of command number ``at`` (counted
from 1 over every command forwarded after :meth:`FaultProxy.arm`):

* ``garbage``: random bytes (no ``:``/``?``) before the reply;
* ``truncate``: only the first half of the reply is sent, the rest never;
* ``qmark``: ``?`` instead of the reply (a rejection);
* ``shift``: the previous command's reply instead of this one's, this one's held back and
  sent before the next (a reply out of order: the link one behind);
* ``late``: the reply held ``delay`` s (beyond the client's timeout);
* ``stale``: a reply of the right kind (its numbers zeroed) 30 ms ahead of the real one, in
  its own TCP segment (a stale reply the client cannot tell from the answer);
* ``close``: the command reaches the controller, then the link is cut before its reply;
* ``stop_reset``: one of ``garbage``, ``qmark``, ``close`` at command ``at``, then the first
  ``ST`` after it cuts the link before it reaches the controller (a reset during the stop);
* ``stop_signal``: the same faults, then SIGINT or SIGTERM (the first signal of the run) sent
  to this process as the stop's ``ST`` goes out (a signal during the stop);

and the good-but-odd input the client must accept (:data:`GOOD_WIRE`):

* ``split``: the reply sent one byte per TCP segment;
* ``spaces``: the reply with extra blanks around its data (``"  12.0000 \\r\\n:"``,
  ``" :"``).

Encoder stream faults (:data:`STREAM_FAULTS`), applied to one chunk the reader takes in (the
wrapper hands the reader whole lines, the tail of a read waiting for the next):
``bitflip``, ``drop_byte``, ``dup_byte``, ``index_repeat`` (a frame re-sent with every leg's
index flag set), ``index_drop`` (the index flags of the frames of the next 50 ms removed),
``stale_seq`` (an earlier, valid frame replayed), ``stall`` (the bytes held back ``stall`` s,
then delivered at once: a link that stalls)
and ``jump`` (the frames of the next 50 ms in sequence with a valid CRC, their counts 2^30
away: the stream's NaN).
"""

from __future__ import annotations

import random
import re
import signal
import socket
import time
from collections.abc import Callable

from kinestat.hardware.encoder_packets import decode_packet, encode_packet
from tests._galil_proxy import GalilProxy

WIRE_FAULTS = ("garbage", "truncate", "qmark", "shift", "late", "close", "stale",
               "stop_reset", "stop_signal")
GOOD_WIRE = ("split", "spaces")
STREAM_FAULTS = ("bitflip", "drop_byte", "dup_byte", "index_repeat", "index_drop",
                 "stale_seq", "stall", "jump")

_GARBAGE = bytes(b for b in range(1, 256) if b not in b":?")


def _spaced(reply: bytes) -> bytes:
    """The same reply with blanks around its data (and after each comma of a list)."""
    if reply in (b":", b"?"):
        return b" " + reply
    body, end = reply[:-1], reply[-1:]
    data = body.strip()
    return b"  " + data.replace(b",", b", ") + b"  \r\n" + end


class FaultProxy(GalilProxy):
    """A :class:`~tests._galil_proxy.GalilProxy` that also damages the reply to the ``at``-th
    command forwarded after :meth:`arm` (module docstring). :attr:`fired` holds the command
    damaged (None until then); :attr:`fired_index` its index in :attr:`forwarded`."""

    def __init__(self, upstream_port: int, *, seed: int = 0, delay: float = 1.0) -> None:
        super().__init__(upstream_port)
        self.rng = random.Random(seed)
        self.delay = delay
        self.kind: str | None = None
        self.at = 0
        self._count = 0
        self.fired: str | None = None
        self.fired_index: int | None = None
        self._last_reply = b":"
        self._held = b""
        self._reset_stop = False
        self.prefix, self.span = "", 1

    def arm(self, kind: str, at: int, *, prefix: str = "", span: int = 1) -> None:
        """Damage the reply to the ``at``-th command (counting only those starting with
        ``prefix``) and, for good input, to the ``span - 1`` commands after it."""
        if kind not in WIRE_FAULTS + GOOD_WIRE:
            raise ValueError(f"unknown wire fault {kind!r}")
        self.kind, self.at, self._count = kind, int(at), 0
        self.prefix, self.span = prefix, int(span) if kind in GOOD_WIRE else 1

    def _match(self, cmd: str) -> list[dict]:
        rules = super()._match(cmd)
        if self._reset_stop and cmd == "ST":
            self._reset_stop = False
            return [*rules, {"action": "drop"}]
        if self.kind is None or not cmd.startswith(self.prefix):
            return rules
        self._count += 1
        if not self.at <= self._count < self.at + self.span:
            return rules
        if self.fired is None:
            self.fired, self.fired_index = cmd, len(self.forwarded)
        kind = self.kind
        if kind == "stop_reset":  # a fault that calls for a stop, then the stop's link reset
            self._reset_stop = True
        elif kind == "stop_signal":  # a fault, then SIGINT or SIGTERM as its ST goes out
            self.rule("ST", "signal", sig=self.rng.choice((signal.SIGINT, signal.SIGTERM)))
        if kind in ("stop_reset", "stop_signal"):
            kind = self.rng.choice(("garbage", "qmark", "close"))
        # the base proxy queues only its own reply actions: ride on "garble", marked
        return [*rules, {"action": "garble", "fault": kind}]

    def _send(self, c: socket.socket, reply: bytes, rules: list[dict]) -> bool:
        acts = {r.get("fault", r["action"]) for r in rules}
        out, held, self._held = self._held + reply, self._held, b""
        try:
            if "close" in acts:
                self.cut()
                return False
            if "garbage" in acts:
                n = self.rng.randint(1, 12)
                out = held + bytes(self.rng.choice(_GARBAGE) for _ in range(n)) + reply
            elif "truncate" in acts:
                out = held + reply[: len(reply) // 2]
            elif "qmark" in acts:
                out = held + b"?"
            elif "shift" in acts:
                out, self._held = held + self._last_reply, reply
            elif "late" in acts:
                time.sleep(self.delay)
            elif "stale" in acts:  # a reply of the right kind, zeros, 30 ms ahead of the real one
                c.sendall(held + re.sub(rb"-?\d+(\.\d+)?", b"0", reply))
                time.sleep(0.03)
                out = reply
            elif "spaces" in acts:
                out = held + _spaced(reply)
            if "split" in acts:
                for b in out:
                    c.sendall(bytes([b]))
                    time.sleep(0.001)
            elif out:
                c.sendall(out)
        except OSError:
            return False
        self._last_reply = reply
        return True


# ----------------------------------------------------------------------------- encoder stream


_FRAME = re.compile(rb"\$KS,[^\r\n]*\r\n")


def _reencode(frame: bytes, *, jump: int = 0, seq_shift: int = 0,
              mask: int | None | str = "keep") -> bytes:
    pkt = decode_packet(frame)
    counts = [c + jump for c in pkt.counts]
    m = pkt.index_mask if mask == "keep" else mask
    return encode_packet((pkt.seq + seq_shift) % 65536, counts, index_mask=m)


class StreamFault:
    """What :func:`corrupt_stream` did: ``kind``, the chunk number ``at`` (from 1), and
    ``fired`` once it was applied."""

    def __init__(self, kind: str, at: int, rng: random.Random, stall: float) -> None:
        if kind not in STREAM_FAULTS:
            raise ValueError(f"unknown stream fault {kind!r}")
        self.kind, self.at, self.rng, self.stall = kind, int(at), rng, stall
        self.count = 0
        self.fired = False
        self.frames: list[bytes] = []
        self.until = 0.0
        self.hold_until = 0.0
        self.held = b""
        self.tail = b""
        self.jump = 1 << 30  # counts added by ``jump``
        self.on_fire: Callable[[], None] | None = None

    def __call__(self, data: bytes) -> bytes:
        if self.hold_until:  # stall: the bytes held back, then let through at once
            self.held += data
            if time.monotonic() < self.hold_until:
                time.sleep(0.005)
                return b""
            data, self.held, self.hold_until = self.held, b"", 0.0
        # whole lines only (the reader takes a frame in several reads): the tail waits
        cut = (self.tail + data).rfind(b"\n") + 1
        data, self.tail = (self.tail + data)[:cut], (self.tail + data)[cut:]
        if not data:
            return data
        self.frames = (self.frames + _FRAME.findall(data))[-50:]
        if self.until and time.monotonic() < self.until:  # index_drop, jump: for a while
            return _FRAME.sub(lambda m: self._rewrite(m.group(0)), data)
        self.count += 1
        if self.fired or self.count < self.at:
            return data
        frames = _FRAME.findall(data)
        if self.kind in ("index_repeat", "index_drop", "stale_seq", "jump") and not frames:
            return data  # wait for a chunk holding a whole frame
        self.fired = True
        if self.on_fire is not None:
            self.on_fire()
        return self._apply(data, frames)

    def _apply(self, data: bytes, frames: list[bytes]) -> bytes:
        k = self.rng.randrange(len(data))
        if self.kind == "bitflip":
            return data[:k] + bytes([data[k] ^ (1 << self.rng.randrange(8))]) + data[k + 1:]
        if self.kind == "drop_byte":
            return data[:k] + data[k + 1:]
        if self.kind == "dup_byte":
            return data[:k + 1] + data[k:]
        if self.kind == "stall":
            self.hold_until, self.held = time.monotonic() + self.stall, data
            return b""
        last = frames[-1]
        if self.kind == "index_repeat":
            return data.replace(last, _reencode(last, mask=0x3F))
        if self.kind == "stale_seq":
            old = self.frames[0] if self.frames[0] != last else last
            return data + old
        # index_drop, jump: the frames of the next 50 ms rewritten
        self.until = time.monotonic() + 0.05
        return _FRAME.sub(lambda m: self._rewrite(m.group(0)), data)

    def _rewrite(self, frame: bytes) -> bytes:
        if self.kind == "jump":  # the frame's own sequence number, a valid CRC, 2^30 away
            return _reencode(frame, jump=self.jump)
        return _reencode(frame, mask=None)


def corrupt_stream(reader, kind: str, at: int, *, seed: int = 0, stall: float = 1.0
                   ) -> StreamFault:
    """Damage ``reader``'s (an :class:`~kinestat.devices.encoder_stream.EncoderReader`) byte
    stream at its ``at``-th chunk; returns the :class:`StreamFault` (``fired`` once done)."""
    fault = StreamFault(kind, at, random.Random(seed), stall)
    real: Callable[..., bytes] = reader._read_chunk

    def read_chunk(*, wait: bool) -> bytes:
        return fault(real(wait=wait))

    reader._read_chunk = read_chunk
    return fault
