"""The measurement chain: counts -> lengths -> tracking FK -> the contact wrench (fixed frame)."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.app.sim_cell import start_counts
from kinestat.control.controller import axis_counts_to_q
from kinestat.control.wrench import measure
from kinestat.errors import InputError
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.stiffness import equilibrium_pose
from kinestat.serial import puma762
from kinestat.sim.contact import equilibrium
from kinestat.sim.sensor import Sensor

from .conftest import F_HAT, PLATFORM, scenario


def _contact(scn, push: float):
    """The flange at the start pose pushed ``push`` mm beyond the plane along F_req."""
    cfg = scn.config(start_tool_point=scn.cell.workpiece.point + push * F_HAT)
    q = axis_counts_to_q(scn.model, start_counts(cfg))
    return q, equilibrium(scn.cell, puma762.forward(q).pose)


def test_unquantised_counts_reproduce_the_true_force_and_torque():
    scn = scenario(tilt_deg=6.0)
    q, eq = _contact(scn, 0.5)
    assert eq.in_contact
    c = Sensor(calibration=scn.sensor.calibration, quantize=False).counts(PLATFORM,
                                                                          eq.leg_lengths)
    m = measure(scn.model, q, c, PLATFORM.home_pose)
    np.testing.assert_allclose(m.force, eq.tool_force, atol=1e-8)
    np.testing.assert_allclose(m.point_force, eq.tool_force, atol=1e-8)
    assert m.point_residual < 1e-9
    # a point contact: no moment about the true tip; about the tool point, (tip - P) x F
    m_tip = m.wrench[3:] - np.cross(eq.tip, m.force)
    np.testing.assert_allclose(m_tip, 0.0, atol=1e-7)
    np.testing.assert_allclose(m.torque, np.cross(eq.tip - m.tool_point, eq.tool_force),
                               atol=1e-7)
    np.testing.assert_allclose(m.tip(scn.model), eq.tip, atol=1e-8)


def test_platform_at_rest_measures_no_load_with_a_fine_sensor():
    scn = scenario(ideal=True)
    c = scn.sensor.counts(PLATFORM, PLATFORM.free_lengths)
    m = measure(scn.model, np.zeros(6), c, PLATFORM.home_pose)
    assert m.force_magnitude < 1e-4 and np.linalg.norm(m.point_force) < 1e-4


def test_thesis_resolution_errors_are_small_and_point_fit_is_not_worse_in_direction():
    errs_w, errs_p = [], []
    for tilt in (0.0, 3.0, 6.0, 9.0):
        scn = scenario(tilt_deg=tilt)
        for push in (0.3, 0.45, 0.6):
            q, eq = _contact(scn, push)
            m = measure(scn.model, q, scn.sensor.counts(PLATFORM, eq.leg_lengths),
                        PLATFORM.home_pose)
            F = eq.tool_force
            assert np.linalg.norm(m.force - F) < 0.25
            for f, errs in ((m.force, errs_w), (m.point_force, errs_p)):
                errs.append(np.degrees(np.arccos(np.clip(f @ F / np.linalg.norm(f)
                                                         / np.linalg.norm(F), -1, 1))))
    assert np.mean(errs_p) <= np.mean(errs_w)


def test_point_fit_residual_flags_a_wrench_that_is_not_a_point_force():
    scn = scenario()
    tip = scn.model.tool_tip_top
    F = np.array([0.3, -0.2, -4.0])
    for extra_moment, small in ((np.zeros(3), True), (np.array([150.0, -80.0, 40.0]), False)):
        w = np.concatenate([F, np.cross(tip, F) + extra_moment])
        pose = PLATFORM.home_pose
        for _ in range(40):  # the tip moves with the top: iterate the point of application
            p = pose[:3, :3] @ tip + pose[:3, 3]
            w = np.concatenate([F, np.cross(p, F) + extra_moment])
            pose = equilibrium_pose(PLATFORM, w, guess=pose)
        c = Sensor(calibration=scn.sensor.calibration, quantize=False).counts(
            PLATFORM, leg_lengths(PLATFORM, pose))
        m = measure(scn.model, np.zeros(6), c, PLATFORM.home_pose)
        assert (m.point_residual < 1e-8) == small


def test_bad_input():
    scn = scenario()
    with pytest.raises(InputError):
        measure(scn.model, np.zeros(5), np.zeros(6), PLATFORM.home_pose)
    with pytest.raises(InputError):
        measure(scn.model, np.zeros(6), [0, 0, 0, np.nan, 0, 0], PLATFORM.home_pose)
    m = measure(scn.model, np.zeros(6), scn.sensor.counts(PLATFORM, PLATFORM.free_lengths),
                PLATFORM.home_pose)
    with pytest.raises(InputError, match="estimator"):
        m.estimate("magic")


def test_ball_tip_centre_is_the_radius_behind_the_tip_along_the_tools_axis():
    """A ball tip: its centre is ``tip_radius`` behind the tip along the top's axis, in the
    fixed frame whatever the platform's pose; a point tip's centre is the tip."""
    from dataclasses import replace

    scn = scenario(tilt_deg=6.0)
    q, eq = _contact(scn, 0.5)
    c = scn.sensor.counts(PLATFORM, eq.leg_lengths)
    point = measure(scn.model, q, c, PLATFORM.home_pose)
    np.testing.assert_array_equal(point.tip_centre(scn.model), point.tip(scn.model))
    ball = replace(scn.model, tip_radius=1.5)
    m = measure(ball, q, c, PLATFORM.home_pose)
    axis = (m.base_pose @ m.top_pose)[:3, 2]
    np.testing.assert_allclose(m.tip(ball) - m.tip_centre(ball), 1.5 * axis, atol=1e-12)


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf")])
def test_ball_tip_radius_must_be_a_length(bad):
    from dataclasses import replace

    from kinestat.errors import ModelError

    scn = scenario()
    with pytest.raises(ModelError, match="tip_radius"):
        replace(scn.model, tip_radius=bad)
