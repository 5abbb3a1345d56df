"""A failure of the simulated cell (no contact equilibrium, raised in the encoder emitter's
thread) stops the run with the simulator's own reason — ST, a `fault` and an `end` record,
exit 2 — and never as "stale encoder data" (QA: `kinestat control --force 10`)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.app.sim_cell import SimCheckedReader, SimHarness, simulator_fault
from kinestat.cli.main import main
from kinestat.control.log import read_log
from kinestat.errors import DeviceError, UnreachableError
from kinestat.parallel.platform import special_6_6
from kinestat.sim.contact import make_cell
from kinestat.sim.sensor import Sensor


def test_control_beyond_the_platforms_load_stops_with_the_simulators_reason(tmp_path, capsys):
    log = tmp_path / "log.jsonl"
    code = main(["control", "--force", "10", "--no-plot", "--json", "--log", str(log)])
    cap = capsys.readouterr()
    assert code == 2
    out = json.loads(cap.out[cap.out.index("{"):])
    assert out["converged"] is False
    for text in (out["stop_reason"], cap.err):
        assert "the simulated cell failed (UnreachableError)" in text
        assert "no frictionless contact equilibrium" in text
        assert "cannot carry this load" in text
        assert "stale" not in text
    recs = read_log(log)
    assert [r["type"] for r in recs][-2:] == ["fault", "end"]
    assert "no frictionless contact equilibrium" in recs[-2]["reason"]
    assert recs[-2]["action"] == "ST sent to the Galil"
    # it stopped at contact, loaded below the platform's limit
    assert 0 < out["true_force_magnitude"] < 10


def test_the_checked_reader_raises_the_emitters_error_not_stale_data():
    cell = make_cell(special_6_6(), plane_point=np.array([0.0, 0.0, -1e4]),
                     plane_normal=np.array([0.0, 0.0, 1.0]))
    with SimHarness(cell, Sensor()) as h:
        reader = SimCheckedReader(h.reader(stale_after=0.2), h.emitter)
        reader.read()  # a healthy stream
        h.emitter.error = UnreachableError("simulated cell: no contact equilibrium (test)")
        with pytest.raises(DeviceError, match=r"simulated cell failed \(UnreachableError\)"):
            reader.read()
        with pytest.raises(DeviceError, match="no contact equilibrium"):
            reader.poll()


def test_simulator_fault_names_the_load_limit_only_for_a_failed_contact_solve():
    assert "cannot carry" in str(simulator_fault(UnreachableError("no contact equilibrium")))
    assert "cannot carry" not in str(simulator_fault(RuntimeError("pty closed")))
