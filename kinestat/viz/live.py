"""A live view of a control run: the cell drawn while it runs (``kinestat control --view
--serve``).

A :class:`LogTail` follows the run's cycle log as the controller writes it (a thread reading new
complete lines every 20 ms), so it works the same for either simulator and for hardware. The
loopback server (:func:`start_live`) answers:

- ``GET /``: the replay page of the cycles logged so far (:func:`kinestat.viz.cell_scene
  .cell_scene`, waiting for the first cycle), with ``live`` set: the page then listens to
- ``GET /events?from=N``: server-sent events, one ``data:`` line per cycle from the N-th on (the
  page's step: frames, items, label, info, and the force for the plot), as each is logged; at
  the end of the run an ``end`` event with the report.
"""

from __future__ import annotations

import json
import os
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import parse_qs, urlparse

from kinestat.errors import InputError, KinestatError
from kinestat.io.library import prototype
from kinestat.io.netbind import resolve_bind_address
from kinestat.viz.cell_scene import cell_scene, run_arm
from kinestat.viz.html import render_html

__all__ = ["LogTail", "LiveServer", "start_live"]

#: how often the log file is read for new lines (s): far below the view's 0.5 s
POLL_S = 0.02


class LogTail:
    """The records of a cycle log as they are written: ``start``, ``cycles`` (each with
    ``_read_at``, the wall time it was read), ``events`` (the page's step of each cycle, made as
    it is read), ``end``. A file that exists when the tail starts is ignored until it is
    rewritten (the run truncates it)."""

    def __init__(self, path: str | os.PathLike, platform=None) -> None:
        self.path = Path(path)
        self.platform = prototype() if platform is None else platform
        self.events: list[bytes] = []
        self._arm = None
        self.start: dict | None = None
        self.cycles: list[dict] = []
        self.end: dict | None = None
        self.changed = threading.Condition()
        self._pos, self._buf = 0, b""
        self._stale = self._stat()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="kinestat-log-tail", daemon=True)
        self._thread.start()

    def _stat(self):
        try:
            st = self.path.stat()
        except OSError:
            return None
        return (st.st_ino, st.st_size, st.st_mtime_ns)

    def _run(self) -> None:
        while not self._stop.is_set():
            self.poll()
            self._stop.wait(POLL_S)

    def poll(self) -> None:
        """Read what was appended since the last call."""
        st = self._stat()
        if st is None or st == self._stale:
            return
        self._stale = None
        if st[1] < self._pos:  # rewritten: start over
            with self.changed:
                self._pos, self._buf, self.start, self.cycles, self.end = 0, b"", None, [], None
                self.events, self._arm = [], None
        try:
            with open(self.path, "rb") as f:
                f.seek(self._pos)
                chunk = f.read()
        except OSError:
            return
        if not chunk:
            return
        self._pos += len(chunk)
        self._buf += chunk
        *lines, self._buf = self._buf.split(b"\n")
        now = time.time()
        with self.changed:
            for line in lines:
                try:
                    rec = json.loads(line)
                except ValueError:
                    continue
                kind = rec.get("type") if isinstance(rec, dict) else None
                if kind == "start":
                    try:
                        self.start, self._arm = rec, run_arm(rec)
                    except KinestatError:
                        self.start = None  # a header this view cannot draw: no live view
                elif kind == "cycle" and isinstance(rec.get("measured"), dict) and self.start:
                    rec["_read_at"] = now
                    self.cycles.append(rec)
                    try:
                        ev = b"data: " + json.dumps({**_step_event(
                            self.start, rec, self.platform, self._arm), "read_at": now,
                            "drawn_at": time.time()}).encode() + b"\n\n"
                    except (KinestatError, KeyError, TypeError, ValueError) as exc:
                        ev = f": cycle {rec.get('cycle')} cannot be drawn: {exc}\n\n".encode()
                    self.events.append(ev)
                elif kind == "end":
                    self.end = rec
            self.changed.notify_all()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2)


def _step_event(start: dict, cycle: dict, platform, arm) -> dict:
    """The page's step for one cycle, as the replay draws it, and its point of the plot."""
    s = cell_scene(start, [cycle], platform=platform, model=arm)
    sr = s["series"]
    return {**s["steps"][0], "series": {"cycle": sr["cycle"][0], "force": sr["force"][0],
                                        "magnitude": sr["magnitude"][0]}}


def _handler(tail: LogTail, title: str, wait_s: float):
    class Handler(BaseHTTPRequestHandler):
        def log_message(self, format, *args):  # noqa: A002 - quiet server
            pass

        def _send(self, code: int, body: bytes, ctype: str) -> None:
            self.send_response(code)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def do_GET(self) -> None:  # noqa: N802 - http.server's name
            url = urlparse(self.path)
            if url.path in ("/", "/index.html"):
                self._page()
            elif url.path == "/events":
                try:
                    n = int(parse_qs(url.query).get("from", ["0"])[0])
                except ValueError:
                    n = 0
                self._events(max(n, 0))
            else:
                self._send(404, b"not found", "text/plain")

        def _page(self) -> None:
            with tail.changed:
                tail.changed.wait_for(lambda: (tail.start is not None and tail.cycles)
                                      or tail.end is not None, timeout=wait_s)
                start, cycles, end = tail.start, list(tail.cycles), tail.end
            if start is None or not cycles:
                self._send(503, b"the run has logged no cycle yet; reload", "text/plain")
                return
            scene = cell_scene(start, cycles, end, platform=tail.platform, title=title,
                               model=tail._arm)
            scene["live"] = {"events": "/events", "ended": end is not None}
            self._send(200, render_html(scene).encode("utf-8"), "text/html; charset=utf-8")

        def _events(self, n: int) -> None:
            self.send_response(200)
            self.send_header("Content-Type", "text/event-stream")
            self.send_header("Cache-Control", "no-cache")
            self.end_headers()
            try:
                while True:
                    with tail.changed:
                        tail.changed.wait_for(lambda k=n: len(tail.events) > k
                                              or tail.end is not None, timeout=1.0)
                        new, end = tail.events[n:], tail.end
                    if new:
                        self.wfile.write(b"".join(new))
                    n += len(new)
                    if end is not None and not new:
                        rep = end.get("report") if isinstance(end.get("report"), dict) else {}
                        self.wfile.write(b"event: end\ndata: " + json.dumps(rep).encode()
                                         + b"\n\n")
                        self.wfile.flush()
                        return
                    self.wfile.write(b": waiting\n\n" if not new else b"")
                    self.wfile.flush()
            except (BrokenPipeError, ConnectionResetError):
                return

    return Handler


class LiveServer:
    """The running live view: its ``url``; :meth:`close` stops the server and the tail."""

    def __init__(self, server: ThreadingHTTPServer, tail: LogTail, url: str) -> None:
        self.server, self.tail, self.url = server, tail, url
        self._thread = threading.Thread(target=server.serve_forever, name="kinestat-live",
                                        daemon=True)
        self._thread.start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()
        self.tail.close()


def start_live(log_path: str | os.PathLike, *, platform=None, port: int = 0,
               title: str | None = None, wait_s: float = 120.0) -> LiveServer:
    """Serve the live view of the run logging to ``log_path`` on loopback (``port`` 0: a free
    one), in background threads."""
    family, sockaddr = resolve_bind_address(
        "127.0.0.1", port, False, what="the live view", exposure="it shows the cell")
    tail = LogTail(log_path, platform)
    server_class = type("_LiveServer", (ThreadingHTTPServer,),
                        {"address_family": family, "daemon_threads": True})
    try:
        srv = server_class(sockaddr, _handler(tail, title or f"control run {log_path}"
                                              " (live)", wait_s))
    except OSError as exc:
        tail.close()
        raise InputError(f"cannot serve the live view on 127.0.0.1:{port}: {exc}") from exc
    host, bound = srv.server_address[:2]
    return LiveServer(srv, tail, f"http://{host}:{bound}/")
