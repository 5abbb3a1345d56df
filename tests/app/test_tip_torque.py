"""The measured tip and the moment about it (issue 42): a point contact's wrench is a pure force
through the tip, so its moment about the MEASURED tip vanishes, while the moment about the
commanded tool point P_tool_F is the lever of the platform's deflection."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.app.sim_cell import InProcessIO, start_counts
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.control.log import CycleLog
from kinestat.control.loop import run
from kinestat.viz.control_plots import cycle_series

START = np.array([-400.0, 800.0, -100.0])


@pytest.fixture(scope="module")
def ideal_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("tip") / "log.jsonl"
    req = ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                         cell=SimulatedCell(ideal_sensor=True))
    prep = prepare_control(req)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with CycleLog(path) as log:
        rep = run(prep.config, io, log)
    recs = [json.loads(line) for line in path.read_text().splitlines()]
    return rep, io.truth(), recs


def test_moment_about_the_measured_tip_vanishes_with_the_ideal_sensor(ideal_run):
    rep, truth, _ = ideal_run
    assert rep.converged
    assert np.linalg.norm(rep.torque_about_tip) <= 0.05
    # the tip is measured, not commanded: it agrees with the simulator's equilibrium tip
    # (its own solve) and differs from the commanded tool point by the platform's deflection
    np.testing.assert_allclose(rep.tip, truth["tip"], atol=5e-3)
    assert np.linalg.norm(rep.tip - rep.tool_point) > 0.5
    assert np.linalg.norm(rep.torque_about_tool) > 1.0


def test_the_three_moments_differ_by_their_points_levers(ideal_run):
    rep, _, _ = ideal_run
    f = rep.equivalent_wrench[:3]
    np.testing.assert_allclose(rep.torque_about_base - rep.torque_about_tip,
                               np.cross(rep.tip, f), atol=1e-9)
    np.testing.assert_allclose(rep.torque_about_tool - rep.torque_about_tip,
                               np.cross(rep.tip - rep.tool_point, f), atol=1e-9)
    d = rep.as_dict()
    for key in ("tip", "torque_about_tip", "torque_about_tool", "torque_about_base"):
        assert d[key] is not None and len(d[key]) == 3


def test_log_and_plot_carry_the_labelled_moments(ideal_run):
    rep, _, recs = ideal_run
    cycles = [r for r in recs if r["type"] == "cycle"]
    for r in cycles:
        m = r["measured"]
        np.testing.assert_allclose(np.subtract(m["torque_about_base"], m["torque_about_tip"]),
                                   np.cross(m["tip"], m["force"]), atol=1e-9)
    # the plot's E-G panels are the moments about the robot's base, as the thesis's Fig. 5-2
    s = cycle_series(recs)
    np.testing.assert_allclose(s["torque"], [r["measured"]["torque_about_base"]
                                             for r in cycles])
    assert recs[-1]["report"]["torque_about_tip"] == rep.as_dict()["torque_about_tip"]


def test_report_carries_the_plants_true_tip_and_normal(ideal_run):
    """The truth (the simulator's contact point and surface normal) reaches the report and every
    cycle of the log; the true tip lies on the default plane and the true normal is its normal."""
    rep, truth, recs = ideal_run
    prep = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=START,
                                          cell=SimulatedCell(ideal_sensor=True)))
    wp = prep.cell.workpiece
    n = np.asarray(wp.normal, dtype=float)
    np.testing.assert_allclose(rep.true_normal, n, atol=1e-12)
    assert abs(float((rep.true_tip - np.asarray(wp.point, dtype=float)) @ n)) <= 1e-6
    np.testing.assert_allclose(rep.true_tip, truth["tip"], atol=1e-12)
    d = rep.as_dict()
    assert len(d["true_tip"]) == 3 and len(d["true_normal"]) == 3
    last = rep.cycles[-1]  # in contact
    np.testing.assert_allclose(last["true_tip"], rep.true_tip, atol=1e-12)
    np.testing.assert_allclose(last["true_normal"], n, atol=1e-12)
