"""The follow task behind the real Galil client and encoder reader (TCP loopback and a pty),
with faults injected during the travel: like the press task's (``test_loop.py``), every fault
must end in a safe stop (ST confirmed) with a complete log, and no command may leave the axis
limits or the platform's load and deflection limits."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.app.sim_cell import SimHarness, start_counts
from kinestat.control.follow import decide_follow
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import run

from .conftest import F_HAT
from .test_loop import FAST, _assert_inside_envelope, _assert_log_complete

START = np.array([-400.0, 800.0, -100.0])


def _during_travel(rec) -> bool:
    task = rec.get("task") or {}
    return task.get("phase") == "travel" and task.get("travel", 0.0) > 1.0


def _during_probing(rec) -> bool:  # a few cycles into the surface probe (lifted or touching)
    return rec.get("action") == "probe" and rec.get("cycle", 0) >= 25


def _follow_with(tmp_path, inject, friction=0.0, when=_during_travel):
    prep = prepare_control(ControlRequest(
        force=4.0 * F_HAT, start_tool_point=START, cell=SimulatedCell(friction=friction),
        task="follow", travel=10.0, travel_dir=np.array([0.0, 1.0, 0.0])))
    path = tmp_path / "log.jsonl"
    with SimHarness(prep.cell, prep.sensor, start_counts=start_counts(prep.config),
                    record=True) as h:
        # the harness's own limits (stale data after SIM_STALE_AFTER = 1 s, a reply within
        # 2 s): the simulated encoder box and Galil are threads sharing this process with the
        # contact solver, and tighter limits can trip on a loaded CI machine before the fault
        # is injected. None of these faults waits on them but the frozen and silent sensor.
        io = h.device_io(profile=FAST)
        injected = []

        def progress(rec):  # the fault comes during the travel (or probing), a few cycles in
            if not injected and when(rec):
                injected.append(rec["cycle"])
                inject(h)

        with CycleLog(path) as log:
            rep = run(prep.config, io, log, progress=progress,
                      decide_fn=functools.partial(decide_follow, prep.follow))
        commands = list(h.controller.commands)
    return prep, rep, read_log(path), commands, injected


FAULTS = {
    "corrupt packets": (lambda h: h.emitter.corrupt(40), "sensor link unreliable"),
    "frozen sensor": (lambda h: h.emitter.freeze(), "stale encoder data"),
    "silent sensor": (lambda h: h.emitter.silence(), "stale encoder data"),
    "rejected move": (lambda h: h.server.reject_next("PA"), "Galil rejected 'PA"),
    "closed link": (lambda h: h.server.drop_link(), "device fault"),
}


@pytest.mark.parametrize("friction", [0.0, 0.3])
@pytest.mark.parametrize("fault", sorted(FAULTS))
def test_a_fault_during_the_travel_stops_the_cell_with_a_complete_log(tmp_path, fault,
                                                                       friction):
    inject, reason = FAULTS[fault]
    prep, rep, recs, commands, injected = _follow_with(tmp_path, inject, friction)
    assert injected, f"the travel never started: {rep.stop_reason}"
    assert not rep.converged and reason in rep.stop_reason, rep.stop_reason
    assert "ST" in commands and "ST confirmed by the controller" in rep.stop_reason
    _assert_log_complete(recs, rep)
    assert any(r["type"] == "fault" for r in recs)
    _assert_inside_envelope(recs, prep.config)  # the axis limits from the config's model


@pytest.mark.parametrize("fault", sorted(FAULTS))
def test_a_fault_while_probing_the_surface_stops_the_cell_with_a_complete_log(tmp_path, fault):
    # the probe lifts the tool off and moves it across: a fault then must stop it the same way
    inject, reason = FAULTS[fault]
    prep, rep, recs, commands, injected = _follow_with(tmp_path, inject, 0.3, _during_probing)
    assert injected, f"the probe never ran: {rep.stop_reason}"
    assert not rep.converged and reason in rep.stop_reason, rep.stop_reason
    assert "ST" in commands and "ST confirmed by the controller" in rep.stop_reason
    _assert_log_complete(recs, rep)
    assert any(r["type"] == "fault" for r in recs)
    _assert_inside_envelope(recs, prep.config)
