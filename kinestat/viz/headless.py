"""Open viewer pages in headless Chromium: screenshots, the page's status, console output.

Used by the browser tests, benchmarks/viewer_load.py and the docs screenshots. WebGL runs on
the CPU through SwiftShader (``--use-angle=swiftshader --enable-unsafe-swiftshader``), so no GPU
is needed. Each call starts one short-lived browser process on a file URL (no network, a
throw-away profile directory). ``make browser`` installs Chromium (Debian package
``chromium``) when it is missing and the user is root.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinestat.errors import InputError

__all__ = ["find_browser", "BrowserRun", "screenshot", "page_status", "canvas_variance"]

_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
_CONSOLE = re.compile(r":CONSOLE:?\d*\]\s*(.*)")
_STATUS = re.compile(r'<pre id="kinestat-status"[^>]*>(.*?)</pre>', re.S)


def find_browser() -> str | None:
    """Path of a Chromium/Chrome executable (``KINESTAT_BROWSER`` first), or None."""
    env = os.environ.get("KINESTAT_BROWSER")
    if env:
        return env if shutil.which(env) else None
    for name in _NAMES:
        path = shutil.which(name)
        if path:
            return path
    return None


@dataclass(frozen=True)
class BrowserRun:
    """One headless run: what the page printed to its console, stdout, and the wall time."""

    console: tuple[str, ...]
    stdout: str
    seconds: float


def _run(url: str, extra: list[str], *, size=(1100, 700), timeout: float = 60.0) -> BrowserRun:
    exe = find_browser()
    if exe is None:
        raise InputError("no Chromium found (install it with `make browser`, or set "
                         "KINESTAT_BROWSER)")
    with tempfile.TemporaryDirectory(prefix="kinestat-chromium-") as profile:
        args = [exe, "--headless", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                "--enable-logging=stderr", "--v=0", "--hide-scrollbars", "--mute-audio",
                "--no-first-run", "--no-default-browser-check", f"--user-data-dir={profile}",
                f"--window-size={size[0]},{size[1]}", *extra, url]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            args.insert(2, "--no-sandbox")  # Chromium refuses to run as root with its sandbox
        t0 = time.perf_counter()
        proc = subprocess.run(args, capture_output=True, text=True, timeout=timeout,
                              check=False)
        dt = time.perf_counter() - t0
    console = tuple(m.group(1) for m in map(_CONSOLE.search, proc.stderr.splitlines()) if m)
    if proc.returncode != 0:
        raise InputError(f"{exe} exited with status {proc.returncode}: "
                         f"{proc.stderr.strip().splitlines()[-1:]}")
    return BrowserRun(console=console, stdout=proc.stdout, seconds=dt)


def screenshot(html: str | os.PathLike, png: str | os.PathLike, *, size=(1100, 700),
               timeout: float = 60.0) -> BrowserRun:
    """Load ``html`` and write a PNG screenshot of the window to ``png``."""
    url = Path(html).resolve().as_uri()
    return _run(url, [f"--screenshot={Path(png).resolve()}"], size=size, timeout=timeout)


def page_status(html: str | os.PathLike, *, size=(1100, 700),
                timeout: float = 60.0) -> tuple[dict, BrowserRun]:
    """Load ``html`` and return the viewer's status (``{"ready", "errors", "fk_frames",
    "load_ms", ...}``, written by viewer.js into ``#kinestat-status``) and the run."""
    run = _run(Path(html).resolve().as_uri(), ["--dump-dom"], size=size, timeout=timeout)
    m = _STATUS.search(run.stdout)
    if m is None or not m.group(1).strip():
        return {"ready": False, "errors": ["no status: the viewer script did not finish"]}, run
    text = m.group(1).replace("&lt;", "<").replace("&gt;", ">").replace("&quot;", '"')
    return json.loads(text.replace("&amp;", "&")), run


def canvas_variance(png: str | os.PathLike, *, panel_width: int = 330) -> float:
    """Grey-level variance of the 3D canvas (the window left of the side panel) in a screenshot;
    0 for a blank canvas."""
    from PIL import Image  # lazy: Pillow only where screenshots are analysed

    with Image.open(png) as im:
        g = np.asarray(im.convert("L"), dtype=float)
    w = g.shape[1] - panel_width
    return float(np.var(g[:, :max(w, 1)]))
