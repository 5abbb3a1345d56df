"""kinestat.app.signals: SIGTERM/SIGHUP raise StopRequested once, handlers are restored."""

from __future__ import annotations

import os
import signal
import threading

import numpy as np
import pytest

from kinestat.app.signals import stop_on_signals
from kinestat.app.sim_cell import InProcessIO, control_model, start_counts
from kinestat.errors import StopRequested


def _thesis_cell():
    """The thesis's experiment on the in-process cell: the plate 2.5 mm ahead of the start tool
    point along F_req, 4 N requested; returns (cell, sensor, controller config)."""
    from kinestat.control.controller import THESIS_FORCE_DIRECTION, ControllerConfig
    from kinestat.parallel.platform import special_6_6
    from kinestat.sim.contact import make_cell
    from kinestat.sim.sensor import Sensor

    f = np.asarray(THESIS_FORCE_DIRECTION)
    p0 = np.array([-400.0, 800.0, -100.0])
    cell = make_cell(special_6_6(), plane_point=p0 + 2.5 * f, plane_normal=-f)
    sensor = Sensor()
    cfg = ControllerConfig(model=control_model(cell, sensor, coupling=0.0), force=4.0 * f,
                           start_tool_point=p0)
    return cell, sensor, cfg


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


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_mid_run_stops_the_in_process_cell_with_a_complete_log(tmp_path, sig):
    """The loop over the in-process cell (InProcessIO): the signal arrives while the cell
    moves (here: from inside a move), the run ends in a safe stop."""
    from kinestat.control.log import CycleLog, read_log
    from kinestat.control.loop import run

    cell, sensor, cfg = _thesis_cell()
    io = InProcessIO(cell, sensor, start_counts=start_counts(cfg))
    real_move = io.move
    moves = []

    def move(counts):
        moves.append(1)
        if len(moves) == 2:  # the first approach step
            os.kill(os.getpid(), sig)
        real_move(counts)

    io.move = move
    path = tmp_path / "log.jsonl"
    with stop_on_signals(), CycleLog(path) as log:
        rep = run(cfg, io, log)
    recs = read_log(path)
    assert not rep.converged and rep.stop_reason.startswith(f"stopped by {sig.name}")
    assert io.stopped
    assert [r["type"] for r in recs][-2:] == ["fault", "end"]
    assert recs[-2]["reason"] == f"stopped by {sig.name}"


def test_a_signal_during_the_stop_of_a_fault_does_not_cut_it_short(tmp_path):
    """A device fault starts a safe stop; SIGTERM arrives while ST is being sent (e.g. during
    the reconnection): ST is sent again, the fault and the end are logged."""

    from kinestat.control.log import CycleLog, read_log
    from kinestat.control.loop import run
    from kinestat.errors import DeviceError

    cell, sensor, cfg = _thesis_cell()

    class FaultyIO(InProcessIO):
        stops = 0

        def sensor(self):
            raise DeviceError("link dropped")

        def stop(self):
            FaultyIO.stops += 1
            if FaultyIO.stops == 1:
                os.kill(os.getpid(), signal.SIGTERM)
                for _ in range(1000):
                    pass
            return "ST sent"

    io = FaultyIO(cell, sensor, start_counts=start_counts(cfg))
    path = tmp_path / "log.jsonl"
    with stop_on_signals() as sigs, CycleLog(path) as log:
        rep = run(cfg, io, log)
    assert [n for n, _ in sigs.received] == ["SIGTERM"]
    assert FaultyIO.stops == 2
    assert rep.stop_reason == "device fault: link dropped (ST sent)"
    recs = read_log(path)
    assert [r["type"] for r in recs][-2:] == ["fault", "end"]
