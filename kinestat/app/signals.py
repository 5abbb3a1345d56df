"""Termination signals during a run: SIGTERM and SIGHUP stop the cell as Ctrl-C does.

:func:`stop_on_signals` installs handlers (main thread only) that raise
:class:`~kinestat.errors.StopRequested` (a ``KeyboardInterrupt``) for SIGTERM and SIGHUP and
``KeyboardInterrupt`` for SIGINT, so the control loop's safe stop (``ST``, a ``fault`` and an
``end`` record) runs whatever the signal. Only the FIRST signal raises: later ones, which would
otherwise interrupt the stop in progress, are recorded and ignored. The previous handlers are
restored on exit.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

from kinestat.errors import StopRequested

__all__ = ["STOP_SIGNALS", "SignalLog", "stop_on_signals"]

STOP_SIGNALS: tuple[signal.Signals, ...] = tuple(
    s for s in (getattr(signal, n, None) for n in ("SIGINT", "SIGTERM", "SIGHUP")) if s is not None)
"""The signals handled: Ctrl-C, a process manager's stop, a closed terminal."""


@dataclass
class SignalLog:
    """Signals received while the handlers were installed: ``(name, time.monotonic())``."""

    received: list[tuple[str, float]] = field(default_factory=list)
    installed: bool = False


@contextmanager
def stop_on_signals(signals: tuple[signal.Signals, ...] = STOP_SIGNALS) -> Iterator[SignalLog]:
    """Within the block, the first of ``signals`` raises ``KeyboardInterrupt`` (SIGINT) or
    :class:`StopRequested` (the others) in the main thread; later ones are ignored.

    Outside the main thread (where Python cannot install handlers) it does nothing.

    >>> with stop_on_signals() as log:
    ...     pass
    >>> log.received
    []
    """
    log = SignalLog()
    if threading.current_thread() is not threading.main_thread():
        yield log
        return

    def handler(signum: int, frame: object) -> None:
        name = signal.Signals(signum).name
        log.received.append((name, time.monotonic()))
        if len(log.received) > 1:
            return  # a stop is already under way: let it finish
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        raise StopRequested(signum, name)

    previous: dict[signal.Signals, object] = {}
    try:
        for s in signals:
            previous[s] = signal.signal(s, handler)
        log.installed = True
        yield log
    finally:
        for s, h in previous.items():
            signal.signal(s, h)  # type: ignore[arg-type]
