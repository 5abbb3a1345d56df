"""Open viewer pages in headless Chromium: screenshots, the page's status, console output.

Used by the browser tests, benchmarks/viewer_load.py and docs/viewer_screenshots.py. WebGL runs
on the CPU through SwiftShader (``--use-angle=swiftshader --enable-unsafe-swiftshader``), so no
GPU is needed. One browser process serves many pages: :class:`Browser` talks the Chrome DevTools
protocol over ``--remote-debugging-pipe`` (JSON messages ending in a NUL byte on file
descriptors 3 and 4; no network port, a throw-away profile). ``make browser`` installs Chromium
(Debian package ``chromium``) when it is missing and the user is root.
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import select
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinestat.errors import InputError

__all__ = ["find_browser", "Browser", "PageResult", "canvas_variance", "PANEL_OVERFLOW_JS",
           "page_problems"]

#: elements of a viewer page's side panel reaching out of it, and how far the panel itself
#: overflows sideways: ``{"bad": [...], "panel": px}`` (``{"bad": [], "panel": 0}`` when fine)
PANEL_OVERFLOW_JS = """(() => {
  const side = document.getElementById("side"), r = side.getBoundingClientRect(), bad = [];
  for (const e of side.querySelectorAll("*")) {
    const b = e.getBoundingClientRect();
    if (!b.width || e.closest("[hidden]")) continue;
    const spills = getComputedStyle(e).overflowX === "visible" && e.clientWidth > 0
      && e.scrollWidth > e.clientWidth + 1;
    if (b.right > r.right + 0.5 || b.left < r.left - 0.5 || spills)
      bad.push((e.id || e.tagName) + ": " + (e.textContent || "").slice(0, 40));
  }
  return {bad: bad, panel: side.scrollWidth - side.clientWidth};
})()"""

_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
_STATUS_JS = "(() => { const e = document.getElementById('kinestat-status'); " \
             "return e ? e.textContent : ''; })()"


def find_browser() -> str | None:
    """Path of a Chromium/Chrome executable (``KINESTAT_BROWSER`` first), or None."""
    env = os.environ.get("KINESTAT_BROWSER")
    if env:
        return shutil.which(env)
    for name in _NAMES:
        path = shutil.which(name)
        if path:
            return path
    return None


@dataclass(frozen=True)
class PageResult:
    """One page load: the viewer's status (``{"ready", "errors", "fk_frames", "load_ms", ...}``
    written by viewer.js, ``{}`` when it did not finish), every console message and uncaught
    exception, the screenshot (PNG bytes, or None) and the wall time from navigation to load."""

    status: dict
    console: tuple[str, ...]
    png: bytes | None
    seconds: float
    value: object = None


class Browser:
    """A headless Chromium driven over the DevTools protocol (a context manager)."""

    def __init__(self, *, size=(1100, 700), timeout: float = 60.0) -> None:
        exe = find_browser()
        if exe is None:
            raise InputError("no Chromium found (install it with `make browser`, or set "
                             "KINESTAT_BROWSER)")
        self.size, self.timeout = size, timeout
        self._profile = tempfile.TemporaryDirectory(prefix="kinestat-chromium-")
        args = [exe, "--headless", "--remote-debugging-pipe", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--hide-scrollbars", "--mute-audio",
                "--no-first-run", "--no-default-browser-check", "--disable-extensions",
                f"--user-data-dir={self._profile.name}", f"--window-size={size[0]},{size[1]}"]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            args.append("--no-sandbox")  # Chromium refuses to run as root with its sandbox
        cmd_r, self._cmd_w = os.pipe()   # we write commands, the browser reads fd 3
        self._ev_r, ev_w = os.pipe()     # the browser writes fd 4, we read

        # The child gets the pipe ends on fds 3 and 4 (close_fds=False: subprocess would close
        # them after preexec_fn; every other descriptor here is non-inheritable, PEP 446).
        def child_fds() -> None:
            a = fcntl.fcntl(cmd_r, fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(ev_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)
            os.close(a)
            os.close(b)

        self._proc = subprocess.Popen(args, stdin=subprocess.DEVNULL,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                      close_fds=False, preexec_fn=child_fds)
        os.close(cmd_r)
        os.close(ev_w)
        self._buf, self._id, self._events = b"", 0, []

    # -- protocol ---------------------------------------------------------------------------
    def _recv(self, deadline: float) -> dict:
        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._ev_r], [], [], left)[0]:
                raise InputError("headless Chromium did not answer in time")
            chunk = os.read(self._ev_r, 1 << 20)
            if not chunk:
                raise InputError("headless Chromium closed the DevTools pipe")
            self._buf += chunk
        msg, _, self._buf = self._buf.partition(b"\0")
        return json.loads(msg)

    def send(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        """Send one command and wait for its answer (events met meanwhile are kept)."""
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._cmd_w, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + self.timeout
        while True:
            m = self._recv(deadline)
            if m.get("id") == self._id:
                if "error" in m:
                    raise InputError(f"DevTools {method}: {m['error'].get('message')}")
                return m.get("result", {})
            self._events.append(m)

    def _wait_event(self, method: str, session: str) -> dict:
        deadline = time.monotonic() + self.timeout
        while True:
            for i, m in enumerate(self._events):
                if m.get("method") == method and m.get("sessionId") == session:
                    return self._events.pop(i)
            self._events.append(self._recv(deadline))

    # -- pages ------------------------------------------------------------------------------
    def load(self, html: str | os.PathLike, *, screenshot: bool = True, fragment: str = "",
             evaluate: str | None = None) -> PageResult:
        """Open ``html`` (a file, or an ``http://`` address; ``fragment`` e.g. ``"step=5"``)
        in a fresh tab; status, console, screenshot, and the value of the JavaScript expression
        ``evaluate`` run after the load (a promise is awaited; the value must be JSON)."""
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget",
                            {"targetId": target, "flatten": True})["sessionId"]
        try:
            w, h = self.size
            self.send("Emulation.setDeviceMetricsOverride",
                      {"width": w, "height": h, "deviceScaleFactor": 1, "mobile": False},
                      session)
            for domain in ("Page", "Runtime", "Log"):
                self.send(f"{domain}.enable", {}, session)
            self._events = [e for e in self._events if e.get("sessionId") != session]
            t0 = time.perf_counter()
            url = str(html) if str(html).startswith(("http://", "https://")) else \
                Path(html).resolve().as_uri()
            url += f"#{fragment}" if fragment else ""
            self.send("Page.navigate", {"url": url}, session)
            self._wait_event("Page.loadEventFired", session)
            text = self._status_text(session)
            dt = time.perf_counter() - t0
            value = None
            if evaluate is not None:
                ans = self.send("Runtime.evaluate", {"expression": evaluate, "awaitPromise": True,
                                                     "returnByValue": True}, session)
                if "exceptionDetails" in ans:
                    raise InputError(f"page script failed: {ans['exceptionDetails'].get('text')}")
                value = ans.get("result", {}).get("value")
            png = None
            if screenshot:
                png = base64.b64decode(self.send("Page.captureScreenshot", {"format": "png"},
                                                 session)["data"])
            console = tuple(_console_text(e) for e in self._events
                            if e.get("sessionId") == session and e.get("method") in (
                                "Runtime.consoleAPICalled", "Runtime.exceptionThrown",
                                "Log.entryAdded"))
        finally:
            self._events = [e for e in self._events if e.get("sessionId") != session]
            self.send("Target.closeTarget", {"targetId": target})
        return PageResult(status=json.loads(text) if text else {}, console=console, png=png,
                          seconds=dt, value=value)

    def _status_text(self, session: str) -> str:
        """The viewer's status once it has published it (meshes load after the load event),
        or "" when the page threw an uncaught exception or the timeout passed."""
        deadline = time.monotonic() + self.timeout
        while True:
            ans = self.send("Runtime.evaluate", {"expression": _STATUS_JS,
                                                 "returnByValue": True}, session)
            text = ans.get("result", {}).get("value") or ""
            thrown = any(e.get("sessionId") == session
                         and e.get("method") == "Runtime.exceptionThrown" for e in self._events)
            if text or thrown or time.monotonic() > deadline:
                return text
            time.sleep(0.05)

    def close(self) -> None:
        if self._proc.poll() is None:
            try:
                self.send("Browser.close")
            except InputError:
                pass
            try:
                self._proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        for fd in (self._cmd_w, self._ev_r):
            try:
                os.close(fd)
            except OSError:
                pass
        self._profile.cleanup()

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _console_text(e: dict) -> str:
    p = e.get("params", {})
    if e["method"] == "Runtime.consoleAPICalled":
        args = " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", []))
        return f"console.{p.get('type')}: {args}"
    if e["method"] == "Runtime.exceptionThrown":
        d = p.get("exceptionDetails", {})
        return "exception: " + str(d.get("exception", {}).get("description") or d.get("text"))
    entry = p.get("entry", {})
    return f"log.{entry.get('level')}: {entry.get('text')}"


def page_problems(page: PageResult, *, min_variance: float = 20.0) -> list[str]:
    """What is wrong with a viewer page as a user would see it (empty when nothing): it did not
    finish, wrote to the console, left the canvas blank, the drawn scene outside the frame, the
    floor out of view, or something spilling out of the side panel (``page`` loaded with
    ``evaluate=PANEL_OVERFLOW_JS``)."""
    st, out = page.status, []
    if not st.get("ready"):
        out.append("the viewer did not finish")
    if st.get("errors") or page.console:
        out.append(f"console: {list(st.get('errors') or [])} {list(page.console)}")
    if page.png is not None and canvas_variance(page.png) <= min_variance:
        out.append("the canvas is blank")
    if not st.get("in_frame"):
        out.append("the scene is not inside the frame")
    if not st.get("floor_visible"):
        out.append("the floor is not in view")
    if page.value is not None and page.value != {"bad": [], "panel": 0}:
        out.append(f"side panel overflows: {page.value}")
    return out


def canvas_variance(png: bytes | str | os.PathLike, *, panel_width: int = 330) -> float:
    """Grey-level variance of the 3D canvas (the window left of the side panel) in a screenshot;
    0 for a blank canvas."""
    import io  # lazy: with Pillow, only where screenshots are analysed

    from PIL import Image  # lazy: Pillow only where screenshots are analysed

    src = io.BytesIO(png) if isinstance(png, bytes) else png
    with Image.open(src) as im:
        g = np.asarray(im.convert("L"), dtype=float)
    w = g.shape[1] - panel_width
    return float(np.var(g[:, :max(w, 1)]))
