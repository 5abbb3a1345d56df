"""The simulated Galil DMC (:class:`kinestat.sim.dmc.DmcSimulator`) served over TCP.

:class:`GalilSimServer` serves a simulator on TCP in a background thread, like the real
controller's port 23: commands end with CR, LF or ``;`` and each gets its own reply. It binds
127.0.0.1 by default and refuses any non-loopback address unless ``allow_remote=True``
(:func:`resolve_bind_address`: the host is resolved once and the checked address is the one
bound).
"""

from __future__ import annotations

import contextlib
import re
import socket
import threading

import numpy as np

from kinestat.errors import DeviceError, InputError
from kinestat.io.netbind import check_bind_address, resolve_bind_address  # re-exported
from kinestat.sim.dmc import DmcSimulator

__all__ = ["resolve_bind_address", "check_bind_address", "GalilSimServer"]


class GalilSimServer:
    """Serve a :class:`DmcSimulator` on TCP from a background thread.

    ``port=0`` picks a free port (read :attr:`port` after :meth:`start`). Several clients may
    connect at once; commands end with CR, LF or ``;`` and each gets its own reply.
    """

    def __init__(self, host: str = "127.0.0.1", port: int = 0, *, allow_remote: bool = False,
                 controller: DmcSimulator | None = None) -> None:
        if not (isinstance(port, int) and 0 <= port <= 65535):
            raise InputError(f"port must be an integer in 0..65535, got {port!r}")
        self._family, self._sockaddr = resolve_bind_address(host, port, allow_remote)
        self.host = host
        self._requested_port = port
        self.controller = controller if controller is not None else DmcSimulator()
        self._listener: socket.socket | None = None
        self._thread: threading.Thread | None = None
        self._stopping = threading.Event()
        self._conns: set[socket.socket] = set()
        self._conn_threads: list[threading.Thread] = []
        self._lock = threading.Lock()
        self.port: int = port

    @property
    def address(self) -> tuple[str, int]:
        return self.host, self.port

    def start(self) -> GalilSimServer:
        """Bind, listen and serve in a daemon thread; raises DeviceError if it cannot bind."""
        if self._thread is not None:
            return self
        try:  # exactly the address resolve_bind_address checked
            lst = socket.socket(self._family, socket.SOCK_STREAM)
            lst.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            lst.bind(self._sockaddr)
            lst.listen(8)
        except OSError as exc:
            raise DeviceError(f"Galil simulator cannot listen on {self.host}:"
                              f"{self._requested_port}: {exc}") from exc
        lst.settimeout(0.05)
        self._listener = lst
        self.port = lst.getsockname()[1]
        self._stopping.clear()
        self._thread = threading.Thread(target=self._accept_loop, name="galil-sim", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Close every connection and the listener; join the threads."""
        self._stopping.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None
        if self._listener is not None:
            with contextlib.suppress(OSError):
                self._listener.close()
            self._listener = None
        self.drop_link()
        for t in self._conn_threads:
            t.join(timeout=2.0)
        self._conn_threads.clear()

    def __enter__(self) -> GalilSimServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- conveniences
    def true_axis_counts(self) -> np.ndarray:
        """Physical axis positions (see :meth:`DmcSimulator.true_axis_counts`)."""
        return self.controller.true_axis_counts()

    def reject_next(self, prefix: str, code: int = 1, times: int = 1) -> None:
        self.controller.reject_next(prefix, code, times)

    def silence_next(self, prefix: str, times: int = 1) -> None:
        self.controller.silence_next(prefix, times)

    def stale_before_next(self, prefix: str, text: str = " 0.0000\r\n:", times: int = 1
                          ) -> None:
        self.controller.stale_before_next(prefix, text, times)

    def send_unsolicited(self, raw: bytes) -> int:
        """Write ``raw`` to every client now, answering nothing (an unsolicited or late
        reply); returns the number of connections written to."""
        with self._lock:
            conns = list(self._conns)
        n = 0
        for c in conns:
            with contextlib.suppress(OSError):
                c.sendall(bytes(raw))
                n += 1
        return n

    def drop_link(self) -> None:
        """Close every client connection now (clients see the link drop)."""
        with self._lock:
            conns = list(self._conns)
            self._conns.clear()
        for c in conns:
            with contextlib.suppress(OSError):
                c.shutdown(socket.SHUT_RDWR)
            with contextlib.suppress(OSError):
                c.close()

    @property
    def connections(self) -> int:
        with self._lock:
            return len(self._conns)

    # -- threads
    def _accept_loop(self) -> None:
        assert self._listener is not None
        while not self._stopping.is_set():
            try:
                conn, _ = self._listener.accept()
            except TimeoutError:
                continue
            except OSError:
                break
            conn.settimeout(0.05)
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                self._conns.add(conn)
            t = threading.Thread(target=self._serve, args=(conn,), name="galil-sim-conn",
                                 daemon=True)
            self._conn_threads = [x for x in self._conn_threads if x.is_alive()] + [t]
            t.start()

    def _serve(self, conn: socket.socket) -> None:
        buf = b""
        try:
            while not self._stopping.is_set():
                with self._lock:
                    if conn not in self._conns:
                        return
                try:
                    chunk = conn.recv(4096)
                except TimeoutError:
                    continue
                except OSError:
                    return
                if not chunk:
                    return
                buf += chunk
                parts = re.split(rb"[\r\n;]", buf)
                buf = parts.pop()
                if len(buf) > 4096:
                    buf = b""
                for raw in parts:
                    text = raw.decode("ascii", errors="replace").strip()
                    if not text:
                        continue
                    try:
                        reply = self.controller.handle(text)
                    except Exception:  # noqa: BLE001 - a command must not end the connection
                        reply = "?"  # (the fuzz tests hold handle() itself to never raising)
                    if reply is not None:
                        conn.sendall(reply.encode("ascii"))
        except OSError:
            return
        finally:
            with self._lock:
                self._conns.discard(conn)
            with contextlib.suppress(OSError):
                conn.close()
