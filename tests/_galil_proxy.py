"""A TCP proxy between a Galil client and the simulator that loses, delays, duplicates or
garbles what passes, per command — the wire faults of the stop tests.

Rules (:meth:`GalilProxy.rule`) match a command by prefix when it passes from the client to
the controller. Command-side actions: ``"lose"`` (the controller never receives it),
``"drop"`` (the link is cut before it is forwarded), ``"signal"`` (the command is forwarded,
then ``sig`` is sent to this process: a signal while the command's reply is pending). Reply
actions apply to that command's reply: ``"lose_reply"``, ``"late"`` (held ``delay`` s; the
replies after it wait too, as on a TCP stream), ``"dup"``, ``"garble"`` (``garble(bytes)``,
default: one byte in the middle changed).
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import threading
import time
from collections import deque

from kinestat.devices.galil_replies import split_reply

_REPLY_ACTIONS = {"lose_reply", "late", "dup", "garble"}


def _flip_middle(reply: bytes) -> bytes:
    if len(reply) < 2:
        return b"X"
    k = len(reply) // 2
    return reply[:k] + bytes([reply[k] ^ 0x08]) + reply[k + 1:]


class GalilProxy:
    """Serve on 127.0.0.1 (``port`` after :meth:`start`), forwarding to ``upstream``."""

    def __init__(self, upstream_port: int) -> None:
        self.upstream = ("127.0.0.1", upstream_port)
        self._lst = socket.socket()
        self._lst.bind(("127.0.0.1", 0))
        self._lst.listen(8)
        self._lst.settimeout(0.05)
        self.port = self._lst.getsockname()[1]
        self._rules: list[dict] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._socks: list[socket.socket] = []
        self.forwarded: list[str] = []   # commands that reached the controller
        self.lost: list[str] = []        # commands the controller never received
        self.connections = 0

    def rule(self, prefix: str, action: str, *, times: int = 1, delay: float = 0.3,
             sig: int = signal.SIGINT, garble=_flip_middle) -> None:
        with self._lock:
            self._rules.append({"prefix": prefix, "action": action, "times": times,
                                "delay": delay, "sig": sig, "garble": garble})

    def _match(self, cmd: str) -> list[dict]:
        out = []
        with self._lock:
            for r in self._rules:
                if r["times"] > 0 and cmd.startswith(r["prefix"]):
                    r["times"] -= 1
                    out.append(r)
        return out

    def start(self) -> GalilProxy:
        threading.Thread(target=self._accept, daemon=True).start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self.cut()
        with contextlib.suppress(OSError):
            self._lst.close()

    def cut(self) -> None:
        """Close every proxied connection (both sides)."""
        with self._lock:
            socks, self._socks = self._socks, []
        for s in socks:
            with contextlib.suppress(OSError):
                s.shutdown(socket.SHUT_RDWR)
            with contextlib.suppress(OSError):
                s.close()

    def __enter__(self) -> GalilProxy:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                c, _ = self._lst.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            try:
                u = socket.create_connection(self.upstream, timeout=1.0)
            except OSError:
                c.close()
                continue
            u.settimeout(None)
            c.settimeout(None)
            with self._lock:
                self._socks += [c, u]
                self.connections += 1
            pending: deque = deque()
            threading.Thread(target=self._c2s, args=(c, u, pending), daemon=True).start()
            threading.Thread(target=self._s2c, args=(u, c, pending), daemon=True).start()

    def _c2s(self, c: socket.socket, u: socket.socket, pending: deque) -> None:
        buf = b""
        while True:
            try:
                chunk = c.recv(4096)
            except OSError:
                return
            if not chunk:
                with contextlib.suppress(OSError):
                    u.shutdown(socket.SHUT_RDWR)
                return
            buf += chunk
            while b"\r" in buf:
                raw, buf = buf.split(b"\r", 1)
                cmd = raw.decode("ascii", "replace")
                rules = self._match(cmd)
                acts = {r["action"] for r in rules}
                if "drop" in acts:
                    self.lost.append(cmd)
                    self.cut()
                    return
                if "lose" in acts:
                    self.lost.append(cmd)
                    continue
                pending.append([r for r in rules if r["action"] in _REPLY_ACTIONS])
                self.forwarded.append(cmd)
                try:
                    u.sendall(raw + b"\r")
                except OSError:
                    return
                for r in rules:
                    if r["action"] == "signal":
                        os.kill(os.getpid(), r["sig"])

    def _s2c(self, u: socket.socket, c: socket.socket, pending: deque) -> None:
        buf = b""
        while True:
            try:
                chunk = u.recv(4096)
            except OSError:
                return
            if not chunk:
                with contextlib.suppress(OSError):
                    c.shutdown(socket.SHUT_RDWR)
                return
            buf += chunk
            while (parts := split_reply(buf)) is not None:
                reply, buf = parts
                rules = pending.popleft() if pending else []
                if not self._send(c, reply, rules):
                    return

    def _send(self, c: socket.socket, reply: bytes, rules: list[dict]) -> bool:
        """Send one reply to the client, altered by its queued rules; False when the client's
        link is gone."""
        out = reply
        for r in rules:
            if r["action"] == "lose_reply":
                out = b""
            elif r["action"] == "late":
                time.sleep(r["delay"])
            elif r["action"] == "dup":
                out = out + out
            elif r["action"] == "garble":
                out = r["garble"](out)
        try:
            c.sendall(out)
        except OSError:
            return False
        return True
