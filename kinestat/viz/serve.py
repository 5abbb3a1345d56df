"""Serve a viewer page on loopback, with inverse kinematics answered by Python.

``GET /`` is the page (:func:`kinestat.viz.html.render_html`), ``GET /scene.json`` the scene,
``POST /ik`` with ``{"q": [...], "target": [x, y, z]}`` moves the end frame's origin to the
target keeping its orientation and answers ``{"solutions": [[...], ...], "outside_limits": k}``:
every closed-form solution for the PUMA 762
(:func:`kinestat.robots.puma762.reverse.reverse_pose`), else the numerical :func:`kinestat.ik`
from the current configuration; each checked by FK, rotating joints turned by whole turns into
their limits, those still outside the joint limits only counted, the rest nearest the current
configuration first.
"""

from __future__ import annotations

import errno
import http.client
import json
import socket
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import numpy as np

import kinestat
from kinestat.errors import InputError, KinestatError
from kinestat.io.netbind import resolve_bind_address
from kinestat.mechanism.chain import ChainModel
from kinestat.robots.puma762 import closed_form as puma762
from kinestat.viz.html import render_html, scene_json

__all__ = ["ik_answer", "make_server"]


def ik_answer(model: ChainModel, q, target) -> dict:
    """IK for the end origin at ``target`` (orientation kept): ``{"solutions": [...]}``."""
    q = model.check_q(np.asarray(q, dtype=float))
    t = np.asarray(target, dtype=float)
    if t.shape != (3,) or not np.all(np.isfinite(t)):
        raise InputError("target must be three finite numbers x,y,z")
    T = kinestat.fk(model, q).copy()
    T[:3, 3] = t
    if model.name == "puma762":
        cands = list(puma762.reverse_pose(T).solutions)
    else:
        res = kinestat.ik(model, T, q)
        cands = [np.asarray(res.q)] if bool(np.all(res.success)) else []
    scale = max(float(np.linalg.norm(t)), 1.0)
    good = [c for c in (_near(model, np.asarray(c, dtype=float), q) for c in cands)
            if np.max(np.abs(kinestat.fk(model, c) - T)) <= 1e-6 * scale]
    inside = [c for c in good if bool(model.within_limits(c))]
    inside.sort(key=lambda c: float(np.sum((c - q) ** 2)))
    return {"solutions": [[float(x) for x in c] for c in inside],
            "outside_limits": len(good) - len(inside)}


def _near(model: ChainModel, c: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``c`` with every rotating joint turned by whole turns to the value nearest ``q`` that
    lies within its limits (nearest ``q`` when none does)."""
    out = c.copy()
    for i in np.flatnonzero(~model.prismatic):
        base = q[i] + (c[i] - q[i] + np.pi) % (2 * np.pi) - np.pi
        options = sorted((base + k * 2 * np.pi for k in (-1, 0, 1, -2, 2)),
                         key=lambda x: abs(x - q[i]))
        fits = [x for x in options if model.lower[i] <= x <= model.upper[i]]
        out[i] = fits[0] if fits else base
    return out


MAX_BODY = 1 << 20
"""Largest ``POST /ik`` body (bytes): a configuration and a target take well under 1 KiB; a
larger body is answered 413 without being kept (at most this much of it is read and dropped,
so that the client gets the answer before the connection closes)."""

MAX_HEADERS = 32 << 10
"""Largest request head (request line excluded, bytes); beyond it the answer is 431."""

REQUEST_TIMEOUT = 10.0
"""Seconds a connection may stay silent in the middle of a request before it is closed."""


class _HeadBudget:
    """``rfile`` while the headers are read: ``readline`` past :data:`MAX_HEADERS` bytes in
    all raises ``LineTooLong`` (http.server then answers 431)."""

    def __init__(self, raw, budget: int) -> None:
        self.raw, self.left = raw, budget

    def readline(self, limit: int = -1) -> bytes:
        line = self.raw.readline(min(limit, self.left + 1) if limit >= 0 else self.left + 1)
        self.left -= len(line)
        if self.left < 0:
            raise http.client.LineTooLong(f"request headers over {MAX_HEADERS} bytes")
        return line

    def __getattr__(self, name: str):
        return getattr(self.raw, name)


def _ik_request(body: bytes) -> tuple[object, object]:
    """``q`` and ``target`` of a ``POST /ik`` body; InputError for anything else."""
    try:
        req = json.loads(body or b"{}")
    except RecursionError:
        raise InputError("the request body nests too deeply") from None
    except ValueError as exc:  # JSONDecodeError, UnicodeDecodeError, the digit limit
        raise InputError(f"the request body is not JSON: {exc}") from None
    if not isinstance(req, dict):
        raise InputError(f'the request body must be a JSON object {{"q": [...], "target": '
                         f'[x, y, z]}}, got {type(req).__name__}')
    return req.get("q"), req.get("target")


def _handler(page: bytes, scene_bytes: bytes, model: ChainModel | None):
    class Handler(BaseHTTPRequestHandler):
        timeout = REQUEST_TIMEOUT

        def log_message(self, format, *args):  # noqa: A002 - quiet server
            pass

        def parse_request(self) -> bool:
            raw, self.rfile = self.rfile, _HeadBudget(self.rfile, MAX_HEADERS)
            try:
                return super().parse_request()
            finally:
                self.rfile = raw

        def _discard(self, limit: int) -> None:
            """Read and drop up to ``limit`` bytes of an unwanted body (closing with unread
            bytes would reset the connection before the client read the answer)."""
            self.wfile.flush()
            left = limit
            try:
                while left > 0 and (chunk := self.rfile.read1(min(left, 65536))):
                    left -= len(chunk)
            except OSError:
                pass

        def _json(self, code: int, ans: dict) -> None:
            self._send(code, json.dumps(ans).encode(), "application/json")

        def _send(self, code: int, body: bytes, ctype: str) -> None:
            self.send_response(code)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def do_GET(self) -> None:  # noqa: N802 - http.server's name
            if self.path in ("/", "/index.html"):
                self._send(200, page, "text/html; charset=utf-8")
            elif self.path == "/scene.json":
                self._send(200, scene_bytes, "application/json")
            else:
                self._send(404, b"not found", "text/plain")

        def do_POST(self) -> None:  # noqa: N802
            if self.path != "/ik" or model is None:
                self._send(404, b"not found", "text/plain")
                return
            length = self.headers.get("Content-Length", "0").strip()
            if not (length.isascii() and length.isdigit()):
                self.close_connection = True
                self._json(400, {"solutions": [], "error": "Content-Length must be a number "
                                 f"of bytes, got {length[:40]!r}"})
                return
            if int(length) > MAX_BODY:
                self.close_connection = True
                self._json(413, {"solutions": [], "error": f"request body of {length} bytes: "
                                 f"at most {MAX_BODY}"})
                self._discard(MAX_BODY)
                return
            try:
                q, target = _ik_request(self.rfile.read(int(length)))
            except (InputError, OSError) as exc:
                self.close_connection = True
                self._json(400, {"solutions": [], "error": str(exc)})
                return
            try:
                ans = ik_answer(model, q, target)
            except (KinestatError, ValueError, TypeError, OverflowError, RecursionError) as exc:
                ans = {"solutions": [], "error": str(exc)}
            except Exception as exc:  # noqa: BLE001 - the server answers and keeps serving
                self._json(500, {"solutions": [], "error": f"internal error: {exc}"})
                return
            self._json(200, ans)

    return Handler


def make_server(scene: dict, *, host: str = "127.0.0.1", port: int = 0,
                model: ChainModel | None = None,
                allow_remote: bool = False) -> ThreadingHTTPServer:
    """A bound (not yet serving) HTTP server for ``scene``; ``port`` 0 picks a free port.

    Loopback only unless ``allow_remote`` is the bool True (the server answers IK and shows the
    scene to whoever connects): the host is resolved once and exactly the checked address is
    bound (:func:`kinestat.io.netbind.resolve_bind_address`).

    Raises:
        InputError: a non-loopback host without ``allow_remote``, the port is in use or the
            address cannot be bound.
    """
    if not (isinstance(port, int) and not isinstance(port, bool) and 0 <= port <= 65535):
        raise InputError(f"port must be an integer in 0..65535, got {port!r}")
    family, sockaddr = resolve_bind_address(
        host, port, allow_remote, what="the viewer",
        exposure="it shows the scene and answers IK to anyone who can reach it")
    if model is not None and scene.get("robot") and scene["robot"].get("live"):
        scene = {**scene, "ik_url": "/ik"}
    page = render_html(scene).encode("utf-8")
    server_class = type("_ViewerServer", (ThreadingHTTPServer,), {"address_family": family})
    try:  # exactly the address resolve_bind_address checked
        return server_class(sockaddr, _handler(page, scene_json(scene).encode(), model))
    except OSError as exc:
        if exc.errno == errno.EADDRINUSE:
            raise InputError(f"port {port} on {host} is in use; choose another with --port "
                             "(0 picks a free one)") from exc
        if isinstance(exc, socket.gaierror) or exc.errno == errno.EADDRNOTAVAIL:
            raise InputError(f"cannot bind the viewer to {host}:{port}: {exc}") from exc
        raise InputError(f"cannot serve the viewer on {host}:{port}: {exc}") from exc
