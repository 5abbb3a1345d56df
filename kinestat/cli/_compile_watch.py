"""Said out loud: a command's first-run kernel compilation (issue 44: only what a command uses
is compiled, announced when it takes over a second).

:func:`announce_compiles` watches Numba's ``numba:compile`` events (a compilation, never a load
from the cache) from the moment Numba is imported; once a command's (the compilations since its
``announce_compiles`` call) add up to :data:`NOTICE_AFTER_S`, "kinestat: compiling kernels
(first run only)…" goes to stderr, once. Light on purpose: ``kinestat --help`` imports this
module and must not import NumPy or Numba.
"""

from __future__ import annotations

import importlib.abc
import importlib.util
import sys
import threading
import time

__all__ = ["NOTICE", "NOTICE_AFTER_S", "announce_compiles", "say_compiling"]

NOTICE = "compiling kernels (first run only)…"
#: a process's compilations are announced once they have taken this long (s)
NOTICE_AFTER_S = 1.0


class _CompileWatch:
    """Numba's ``numba:compile`` events (a compilation, never a cache load) timed per process;
    the notice goes out from a timer once they add up to :data:`NOTICE_AFTER_S`."""

    def __init__(self) -> None:
        self.depth = 0
        self.spent = 0.0
        self.started = 0.0
        self.timer: threading.Timer | None = None
        self.said = False

    def on_start(self, event) -> None:
        if self.depth == 0:
            self.started = time.perf_counter()
            if not self.said:
                self.timer = threading.Timer(max(0.0, NOTICE_AFTER_S - self.spent), self.say)
                self.timer.daemon = True
                self.timer.start()
        self.depth += 1

    def on_end(self, event) -> None:
        self.depth -= 1
        if self.depth == 0:
            self.spent += time.perf_counter() - self.started
            if self.timer is not None:
                self.timer.cancel()
                self.timer = None

    def say(self) -> None:
        if not self.said:
            self.said = True
            from kinestat.cli._output import err_console  # lazy: rich

            err_console.print(f"kinestat: {NOTICE}", highlight=False)


_WATCH: list[_CompileWatch] = []


def _watch_now() -> None:
    from numba.core import event  # lazy: Numba is imported by now

    if _WATCH:
        return
    watch = _CompileWatch()
    watch.said = bool(_SAID)
    listener = type("_Listener", (event.Listener,), {
        "on_start": lambda self, ev: watch.on_start(ev),
        "on_end": lambda self, ev: watch.on_end(ev)})()
    event.register("numba:compile", listener)
    _WATCH.append(watch)


class _AfterNumba(importlib.abc.MetaPathFinder):
    """Installs the compile watch right after Numba's import, so that a command that never
    compiles never imports Numba for it."""

    def find_spec(self, name, path=None, target=None):
        if name != "numba":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.loader is not None:
            run = spec.loader.exec_module

            def exec_module(module):
                run(module)
                _watch_now()

            spec.loader.exec_module = exec_module
        return spec


def say_compiling() -> None:
    """Say it now (a caller about to compile for long), and not again in this process."""
    if _WATCH:
        _WATCH[0].say()
    else:
        _CompileWatch().say()
        _SAID.append(True)


_SAID: list[bool] = []


def announce_compiles() -> None:
    """Say on stderr, once, when the kernel compilations from now on (a command's) take more
    than :data:`NOTICE_AFTER_S` (a compilation, not a load from the cache)."""
    _SAID.clear()
    if _WATCH:
        _WATCH[0].spent = 0.0
        _WATCH[0].said = False
    if "numba" in sys.modules:
        _watch_now()
    elif not any(isinstance(f, _AfterNumba) for f in sys.meta_path):
        sys.meta_path.insert(0, _AfterNumba())
