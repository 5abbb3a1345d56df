"""A failure of the simulated cell (raised in the encoder emitter's thread) stops the run with
the simulator's own reason — ST, a `fault` and an `end` record — and never as "stale encoder
data" (QA: `kinestat control --force 10`); the contact solve continues from the previous
solution where Newton from the unloaded pose fails; `--force 10` then stops on the envelope."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from kinestat.app.control_run import DEFAULT_START, SimulatedCell, simulated_cell
from kinestat.app.sim_cell import (
    SimCheckedReader,
    SimHarness,
    control_model,
    simulator_fault,
    start_counts,
)
from kinestat.cli.main import main
from kinestat.control.controller import THESIS_FORCE_DIRECTION, ControllerConfig
from kinestat.control.envelope import Envelope, sent_command_guard
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import run
from kinestat.errors import DeviceError, UnreachableError
from kinestat.parallel.platform import special_6_6
from kinestat.robots.puma762 import closed_form as puma762
from kinestat.robots.puma762.axes import counts_to_joint_rad
from kinestat.sim.contact import equilibrium, make_cell
from kinestat.sim.sensor import Sensor

D = THESIS_FORCE_DIRECTION / np.linalg.norm(THESIS_FORCE_DIRECTION)
P0 = np.array([float(v) for v in DEFAULT_START.split(",")])


def _default_cell():
    cell, sensor = simulated_cell(SimulatedCell(), P0, D)
    cfg = ControllerConfig(model=control_model(cell, sensor), force=4 * D, start_tool_point=P0)
    return cell, sensor, cfg


def test_a_simulator_failure_mid_run_is_the_stop_reason(tmp_path):
    cell, sensor, cfg = _default_cell()
    cell = replace(cell, stroke=0.5)  # the legs bottom out at first contact: the cell fails
    log = tmp_path / "log.jsonl"
    with SimHarness(cell, sensor, start_counts=start_counts(cfg)) as h:
        io = h.device_io(guard=sent_command_guard(cfg.envelope, cfg.model))
        with CycleLog(log) as cl:
            rep = run(cfg, io, cl)
        assert isinstance(h.emitter.error, UnreachableError)
    assert not rep.converged
    assert "the simulated cell failed (UnreachableError)" in rep.stop_reason
    assert "beyond the legs' stroke" in rep.stop_reason and "smaller --force" in rep.stop_reason
    assert "stale" not in rep.stop_reason
    recs = read_log(log)
    assert [r["type"] for r in recs][-2:] == ["fault", "end"]
    assert "the simulated cell failed" in recs[-2]["reason"]
    assert recs[-2]["action"].startswith("ST confirmed by the controller")
    assert recs[-2]["stop_confirmed"]


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


def test_simulator_fault_names_the_load_only_for_a_failed_solve():
    assert "smaller --force" in str(simulator_fault(UnreachableError("no equilibrium")))
    assert "smaller --force" not in str(simulator_fault(RuntimeError("pty closed")))


def test_continuation_finds_the_equilibrium_newton_from_the_unloaded_pose_misses():
    cell, _, cfg = _default_cell()
    T0 = puma762.forward(counts_to_joint_rad(start_counts(cfg))).pose
    eq = None
    for s in np.arange(2.0, 16.01, 0.5):  # push the flange along F_req, 0.5 mm at a time
        T = T0.copy()
        T[:3, 3] += s * D
        new = equilibrium(cell, T, top_pose_guess=None if eq is None else eq.top_pose)
        if eq is not None and eq.in_contact:  # the solution moves continuously
            assert np.max(np.abs(new.leg_lengths - eq.leg_lengths)) < 0.5
        eq = new
    assert eq.in_contact and eq.residual <= 1e-9 and abs(cell.workpiece.gap(eq.tip)) <= 1e-9
    with pytest.raises(UnreachableError, match="no frictionless contact equilibrium"):
        equilibrium(cell, T)  # the same pose from the unloaded pose alone


def test_control_force_10_stops_on_the_envelope_not_on_the_simulator(tmp_path, capsys):
    log = tmp_path / "log.jsonl"
    code = main(["control", "--force", "10", "--no-plot", "--json", "--log", str(log)])
    out = capsys.readouterr().out
    report = json.loads(out[out.index("{"):])
    assert code == 2 and not report["converged"]
    assert "Table 3-1" in report["stop_reason"] and "simulated cell failed" not in \
        report["stop_reason"]
    assert "stale" not in report["stop_reason"]
    assert report["true_force_magnitude"] > 8.0  # past where the solve used to fail (5.9 N)
    assert read_log(log)[-2]["action"].startswith("ST confirmed by the controller")
    assert Envelope().max_load > 10  # the stop is the platform's motion range, not the load
