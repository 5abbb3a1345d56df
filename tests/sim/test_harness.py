"""The harness: simulated Galil + encoder emitter wired to the simulated cell."""

from __future__ import annotations

import time

import numpy as np
import pytest

from kinestat.app.sim_cell import InProcessIO, SimHarness, control_model, start_counts
from kinestat.control.controller import THESIS_FORCE_DIRECTION, ControllerConfig
from kinestat.devices.encoder_stream import StaleDataError
from kinestat.errors import DeviceError
from kinestat.hardware.leg_calibration import counts_to_lengths
from kinestat.parallel.platform import special_6_6
from kinestat.robots.puma762 import closed_form as puma762
from kinestat.robots.puma762.axes import counts_to_joint_rad
from kinestat.sim.contact import equilibrium, make_cell
from kinestat.sim.sensor import Sensor

PLAT = special_6_6()
F = np.asarray(THESIS_FORCE_DIRECTION)
START = np.array([-400.0, 800.0, -100.0])


def _setup(depth: float):
    """A cell whose plane sits ``depth`` mm behind the start tool point (negative: ahead)."""
    cell = make_cell(PLAT, plane_point=START - depth * F, plane_normal=-F)
    sensor = Sensor()
    cfg = ControllerConfig(model=control_model(cell, sensor), force=4 * F,
                           start_tool_point=START)
    return cell, sensor, start_counts(cfg)


def test_start_counts_place_the_tool_at_the_start_pose():
    cell, sensor, sc = _setup(-2.0)
    fwd = puma762.forward(counts_to_joint_rad(sc), cell.tool_point_6)
    assert np.linalg.norm(fwd.tool_point - START) < 0.05
    np.testing.assert_allclose(fwd.s6, F, atol=1e-4)


def test_packets_carry_the_cell_at_the_true_pose():
    cell, sensor, sc = _setup(0.4)  # in contact at the start pose
    with SimHarness(cell, sensor, start_counts=sc, rate_hz=200) as h:
        client = h.client()
        assert tuple(client.position_counts()) == tuple(int(c) for c in sc)
        reader = h.reader()
        r = reader.read(timeout=1.0)
        eq = equilibrium(cell, puma762.forward(counts_to_joint_rad(sc)).pose)
        assert eq.in_contact
        np.testing.assert_array_equal(r.counts, sensor.counts(PLAT, eq.leg_lengths))
        lengths = counts_to_lengths(r.counts, sensor.calibration, PLAT.leg_names)
        assert np.max(np.abs(lengths - eq.leg_lengths)) < 0.03
        truth = h.truth()
        np.testing.assert_allclose(truth["tool_force"], eq.tool_force, atol=1e-9)
        assert truth["in_contact"]
        np.testing.assert_allclose(truth["tool_axis"], F, atol=1e-4)


def test_a_bottomed_out_cell_silences_the_sensor():
    cell, sensor, sc = _setup(12.0)  # too deep: beyond the legs' stroke
    with SimHarness(cell, sensor, start_counts=sc, rate_hz=200) as h:
        deadline = time.monotonic() + 2.0
        while h.emitter.error is None and time.monotonic() < deadline:
            time.sleep(0.01)
        assert h.emitter.error is not None and "stroke" in str(h.emitter.error)
        assert "error" in h.truth()

        with pytest.raises(StaleDataError):
            h.reader(stale_after=0.1).read()


def test_in_process_io_moves_exactly_and_reports_sensor_failures():
    cell, sensor, sc = _setup(-1.0)
    io = InProcessIO(cell, sensor, start_counts=sc)
    np.testing.assert_array_equal(io.robot_counts(), sc)
    s = io.sensor()
    np.testing.assert_array_equal(s.counts, sensor.counts(PLAT, PLAT.free_lengths))
    assert io.truth()["in_contact"] is False
    io.move(sc + np.array([0, 10, 0, 0, 0, 0]))
    np.testing.assert_array_equal(io.robot_counts(), sc + np.array([0, 10, 0, 0, 0, 0]))
    deep, sensor2, sc2 = _setup(30.0)
    bad = InProcessIO(deep, sensor2, start_counts=sc2)
    with pytest.raises(DeviceError, match="simulated sensor failed"):
        bad.sensor()
    assert "error" in bad.truth()
    assert io.stop() and io.stopped
