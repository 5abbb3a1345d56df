"""The simulated cell: contact equilibrium (frictionless, sticking, sliding) and the sensor."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from kinestat.errors import InputError, ModelError, UnreachableError
from kinestat.hardware.leg_calibration import MM_PER_COUNT, counts_to_lengths
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import special_6_6
from kinestat.parallel.statics import spring_wrench
from kinestat.sim.contact import (
    DEFAULT_TOOL_POINT_6,
    Workpiece,
    centred_mount,
    equilibrium,
    make_cell,
    unloaded_tip,
)
from kinestat.sim.sensor import Sensor, ideal_sensor
from kinestat.spatial.transforms import apply

PLAT = special_6_6()
FLANGE = np.eye(4)  # frame 6 = fixed frame: the tool points along +z
TIP0 = np.asarray(DEFAULT_TOOL_POINT_6)


def _normal(tilt_deg: float, azimuth_deg: float = 0.0) -> np.ndarray:
    """Outward normal of a workpiece facing the tool (−z), tilted by ``tilt_deg``."""
    t, a = math.radians(tilt_deg), math.radians(azimuth_deg)
    return -np.array([math.sin(t) * math.cos(a), math.sin(t) * math.sin(a), math.cos(t)])


def _cell(depth: float, tilt_deg: float = 0.0, azimuth_deg: float = 0.0, friction: float = 0.0):
    n = _normal(tilt_deg, azimuth_deg)
    # the unloaded tip is ``depth`` behind the plane
    return make_cell(PLAT, plane_point=TIP0 + depth * n, plane_normal=n, friction=friction)


def _external_on_top(cell, eq):
    """The contact force and its moment about the base origin, in base coordinates."""
    TB = FLANGE @ cell.mount
    R = TB[:3, :3]
    f = R.T @ eq.contact_force
    p = apply(eq.top_pose, cell.tool_tip)
    return np.concatenate([f, np.cross(p, f)])


def test_default_tool_and_mount_match_the_thesis():
    cell = _cell(0.5)
    np.testing.assert_allclose(cell.tool_point_6, [0.0, 0.0, 235.0], atol=1e-12)
    # the base triangle's centroid is on S6 and the top's unloaded axis is S6
    M = centred_mount(PLAT)
    corners = apply(M, PLAT.base_points[:3])
    np.testing.assert_allclose(corners.mean(axis=0)[:2], 0.0, atol=1e-12)
    top = M @ PLAT.home_pose
    np.testing.assert_allclose(top[:3, 2], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(apply(top, PLAT.top_points[3:]).mean(axis=0)[:2], 0.0,
                               atol=1e-12)
    np.testing.assert_allclose(unloaded_tip(cell, FLANGE), TIP0, atol=1e-12)


def test_out_of_contact_the_top_rests_at_home():
    cell = _cell(-0.3)  # plane 0.3 mm ahead of the tip
    eq = equilibrium(cell, FLANGE)
    assert not eq.in_contact
    np.testing.assert_array_equal(eq.tool_force, 0.0)
    np.testing.assert_allclose(eq.leg_lengths, PLAT.free_lengths, atol=1e-12)


def test_frictionless_contact_balances_and_matches_energy_minimum():
    cell = _cell(0.6, tilt_deg=7.0, azimuth_deg=30.0)
    eq = equilibrium(cell, FLANGE)
    assert eq.in_contact and eq.residual <= 1e-9
    n = cell.workpiece.normal
    # force along the normal, pushing the tool out (unilateral), tip on the plane
    assert np.linalg.norm(np.cross(eq.contact_force, n)) <= 1e-9 * np.linalg.norm(eq.contact_force)
    assert eq.contact_force @ n > 0
    assert abs(cell.workpiece.gap(eq.tip)) <= 1e-9
    # wrench balance recomputed independently: springs' external wrench = contact wrench
    np.testing.assert_allclose(spring_wrench(PLAT, eq.top_pose), _external_on_top(cell, eq),
                               atol=1e-9)

    # independent oracle: the top minimises the springs' energy with the tip outside the plane
    home = PLAT.home_pose
    k, l0 = PLAT.stiffness, PLAT.free_lengths
    TB = FLANGE @ cell.mount

    def pose(x):
        R = Rotation.from_rotvec(x[:3]).as_matrix()
        T = home.copy()
        T[:3, :3] = R @ home[:3, :3]
        T[:3, 3] = R @ home[:3, 3] + x[3:]
        return T

    def energy(x):
        return 0.5 * float(np.sum(k * (leg_lengths(PLAT, pose(x)) - l0) ** 2))

    def gap(x):
        return float(cell.workpiece.gap(apply(TB @ pose(x), cell.tool_tip)))

    res = minimize(energy, np.zeros(6), method="SLSQP",
                   constraints=[{"type": "ineq", "fun": gap}],
                   options={"ftol": 1e-14, "maxiter": 500})
    assert res.success
    np.testing.assert_allclose(leg_lengths(PLAT, pose(res.x)), eq.leg_lengths, atol=2e-5)


@settings(max_examples=15, deadline=None)
@given(depth=st.floats(0.01, 1.5), tilt=st.floats(0.0, 15.0), azimuth=st.floats(0.0, 360.0))
def test_frictionless_equilibrium_properties(depth, tilt, azimuth):
    cell = _cell(depth, tilt, azimuth)
    eq = equilibrium(cell, FLANGE)
    assert eq.in_contact and eq.residual <= 1e-9
    assert eq.normal_force > 0
    assert abs(cell.workpiece.gap(eq.tip)) <= 1e-9
    np.testing.assert_allclose(eq.tool_force, -eq.contact_force)
    # pushing deeper along the tool axis increases the force
    deeper = equilibrium(cell, FLANGE + _shift(0.05))
    assert deeper.normal_force > eq.normal_force


def _shift(dz: float) -> np.ndarray:
    S = np.zeros((4, 4))
    S[2, 3] = dz
    return S


def test_sticking_contact_holds_the_anchor_inside_the_cone():
    cell = _cell(0.5, tilt_deg=5.0, friction=0.5)
    anchor = TIP0 + 0.5 * cell.workpiece.normal  # on the plane, straight ahead
    eq = equilibrium(cell, FLANGE, anchor=anchor)
    assert eq.sticking and eq.residual <= 1e-9
    np.testing.assert_allclose(eq.tip, anchor, atol=1e-9)
    fn = eq.contact_force @ cell.workpiece.normal
    ft = eq.contact_force - fn * cell.workpiece.normal
    assert fn > 0 and np.linalg.norm(ft) <= 0.5 * fn
    np.testing.assert_allclose(spring_wrench(PLAT, eq.top_pose), _external_on_top(cell, eq),
                               atol=1e-9)


def test_first_contact_anchor_is_where_the_path_crosses_the_plane():
    cell = _cell(0.4, tilt_deg=10.0, friction=0.8)
    before = TIP0 - np.array([0.0, 0.0, 2.0])  # the unloaded tip 2 mm back along the approach
    eq = equilibrium(cell, FLANGE, approach_from=before)
    assert eq.sticking
    # the anchor lies on the plane and on the approach line x = y = 0
    assert abs(cell.workpiece.gap(eq.anchor)) <= 1e-9
    np.testing.assert_allclose(eq.anchor[:2], 0.0, atol=1e-9)


def test_sliding_contact_sits_on_the_cone_and_slides_with_the_push():
    mu = 0.05
    cell = _cell(0.5, tilt_deg=8.0, friction=mu)  # tan 8° > 0.05: cannot stick straight on
    anchor = TIP0 + 0.5 * cell.workpiece.normal
    eq = equilibrium(cell, FLANGE, anchor=anchor)
    assert not eq.sticking and eq.residual <= 1e-9
    n = cell.workpiece.normal
    fn = eq.contact_force @ n
    ft = eq.contact_force - fn * n
    np.testing.assert_allclose(np.linalg.norm(ft), mu * fn, rtol=1e-6)
    slip = eq.anchor - anchor
    # friction on the tool opposes the slip
    assert ft @ slip < 0
    np.testing.assert_allclose(np.cross(ft, slip) @ n, 0.0, atol=1e-6 * np.linalg.norm(slip))
    # and the force lies between the frictionless and the sticking ones
    free = equilibrium(_cell(0.5, tilt_deg=8.0), FLANGE)
    stick = equilibrium(_cell(0.5, tilt_deg=8.0, friction=1.0), FLANGE, anchor=anchor)
    assert free.normal_force < fn < stick.normal_force


def test_pulling_away_releases_a_sticking_contact():
    cell = _cell(0.5, friction=0.5)
    anchor = TIP0 + 0.5 * cell.workpiece.normal
    eq = equilibrium(cell, FLANGE - _shift(1.0), anchor=anchor)  # retract 1 mm
    assert not eq.in_contact and eq.anchor is None


def test_pushing_beyond_the_stroke_is_refused():
    cell = _cell(20.0)
    with pytest.raises(UnreachableError, match="stroke"):
        equilibrium(cell, FLANGE)


def test_bad_input_is_refused():
    with pytest.raises(InputError, match="normal"):
        Workpiece([0, 0, 0], [0, 0, 0])
    with pytest.raises(InputError, match="friction"):
        Workpiece([0, 0, 0], [0, 0, 1], friction=-0.1)
    with pytest.raises(InputError, match="NaN"):
        equilibrium(_cell(0.5), np.full((4, 4), np.nan))
    with pytest.raises(ModelError, match="rigid"):
        make_cell(PLAT, plane_point=[0, 0, 0], plane_normal=[0, 0, 1], mount=2 * np.eye(4))


def test_sensor_quantises_to_the_calibration_and_ideal_sensor_does_not():
    cell = _cell(0.7, tilt_deg=3.0)
    eq = equilibrium(cell, FLANGE)
    s = Sensor()
    c = s.counts(PLAT, eq.leg_lengths)
    assert np.all(c == np.rint(c))
    back = counts_to_lengths(c, s.calibration, PLAT.leg_names)
    slopes = np.abs(s.calibration.length_coeffs[:, 1])
    assert np.all(np.abs(back - eq.leg_lengths) <= 0.5 * slopes.max() + 1e-12)
    assert 0.9 * MM_PER_COUNT < slopes.min() and slopes.max() < 1.1 * MM_PER_COUNT
    ideal = ideal_sensor()
    ci = ideal.counts(PLAT, eq.leg_lengths)
    back = counts_to_lengths(ci, ideal.calibration, PLAT.leg_names)
    assert np.max(np.abs(back - eq.leg_lengths)) <= 1e-6
    noisy = Sensor(noise=0.05)
    draws = np.array([noisy.counts(PLAT, eq.leg_lengths, np.random.default_rng(i))
                      for i in range(200)])
    spread = np.std(counts_to_lengths(draws, s.calibration, PLAT.leg_names), axis=0)
    np.testing.assert_allclose(spread, 0.05, rtol=0.25)
    with pytest.raises(InputError):
        Sensor(noise=-1.0)


def test_mount_moves_the_cell_rigidly():
    """The same contact seen through a turned and shifted mount gives the same force."""
    turned = centred_mount(PLAT, offset=3.0, turn=0.4)
    base = _cell(0.5, tilt_deg=6.0)
    other = make_cell(PLAT, plane_point=base.workpiece.point + [0, 0, 3.0],
                      plane_normal=base.workpiece.normal, mount=turned, tool_tip=base.tool_tip)
    # rotate the flange about S6 by -0.4 so that the base sits where it did
    e1 = equilibrium(base, FLANGE)
    F2 = np.eye(4)
    F2[:3, :3] = Rotation.from_rotvec([0, 0, -0.4]).as_matrix()
    e2 = equilibrium(other, F2)
    np.testing.assert_allclose(e2.tool_force, e1.tool_force, atol=1e-9)
    np.testing.assert_allclose(e2.leg_lengths, e1.leg_lengths, atol=1e-9)
