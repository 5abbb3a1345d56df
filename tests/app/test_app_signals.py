"""kinestat.app.signals: SIGTERM/SIGHUP raise StopRequested once, handlers are restored."""

from __future__ import annotations

import os
import signal
import threading

import pytest

from kinestat.app.signals import stop_on_signals
from kinestat.errors import StopRequested


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_raises_stop_requested_once_and_handlers_are_restored(sig):
    before = signal.getsignal(sig)
    with stop_on_signals() as log:
        assert signal.getsignal(sig) is not before
        with pytest.raises(StopRequested) as exc:
            os.kill(os.getpid(), sig)
            for _ in range(1000):  # the handler runs at the next bytecode boundary
                pass
        assert exc.value.signal_name == sig.name and isinstance(exc.value, KeyboardInterrupt)
        os.kill(os.getpid(), sig)  # a second signal while stopping: recorded, ignored
        for _ in range(1000):
            pass
    assert [n for n, _ in log.received] == [sig.name, sig.name]
    assert signal.getsignal(sig) is before


def test_sigint_stays_a_keyboard_interrupt():
    with stop_on_signals(), pytest.raises(KeyboardInterrupt) as exc:
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(1000):
            pass
    assert not isinstance(exc.value, StopRequested)


def test_outside_the_main_thread_nothing_is_installed():
    result = {}

    def worker():
        before = signal.getsignal(signal.SIGTERM)
        with stop_on_signals() as log:
            result["same"] = signal.getsignal(signal.SIGTERM) is before
            result["installed"] = log.installed

    t = threading.Thread(target=worker)
    t.start()
    t.join()
    assert result == {"same": True, "installed": False}
