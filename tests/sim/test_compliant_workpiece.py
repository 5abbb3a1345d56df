"""Compliant workpieces (``stiffness`` k in N/mm) in the built-in simulator: the tip sinks
``f_n / k`` into the surface, the equilibrium is the rigid one on the surface moved back by that
depth, the friction cone holds, and a stiff workpiece is the rigid one."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError, UnreachableError
from kinestat.parallel.platform import special_6_6
from kinestat.parallel.statics import spring_wrench
from kinestat.sim.contact import (
    DEFAULT_TOOL_POINT_6,
    SLIDE_TOL,
    Workpiece,
    _springs,
    equilibrium,
    make_cell,
)
from kinestat.sim.surface import Cylinder, solve
from kinestat.spatial.transforms import apply_vector, inv

PLAT = special_6_6()
FLANGE = np.eye(4)  # frame 6 = fixed frame: the tool points along +z
TIP0 = np.asarray(DEFAULT_TOOL_POINT_6)


def _normal(tilt_deg: float, azimuth_deg: float) -> np.ndarray:
    t, a = math.radians(tilt_deg), math.radians(azimuth_deg)
    return -np.array([math.sin(t) * math.cos(a), math.sin(t) * math.sin(a), math.cos(t)])


def _plane(depth, n, mu, k):
    """A plane ``depth`` mm into the unloaded tip along its normal ``n``."""
    return make_cell(PLAT, plane_point=TIP0 + depth * n, plane_normal=n, friction=mu, stiffness=k)


def _cylinder(depth, radius, mu, k, axis=(0.0, 1.0, 0.0), off=0.0):
    """A cylinder whose surface is ``depth`` mm behind the unloaded tip along the tool's axis
    (+z), its axis along ``axis`` moved ``off`` mm along x (the tip meets it off its crest)."""
    cell = make_cell(PLAT, plane_point=TIP0, plane_normal=[0, 0, -1.0])
    centre = TIP0 + np.array([off, 0.0, math.sqrt(radius ** 2 - off ** 2) - depth])
    return replace(cell, workpiece=Cylinder(centre, axis, radius, mu, k))


def _balanced(cell, eq) -> float:
    """Largest residual of the top's balance: springs against the contact force at the tip."""
    TB = eq.base_pose
    f = apply_vector(inv(TB), eq.contact_force)
    p = (inv(TB) @ np.append(eq.tip, 1.0))[:3]
    w = spring_wrench(_springs(cell, eq.top_pose), eq.top_pose)
    return float(np.max(np.abs(w - np.concatenate([f, np.cross(p, f)]))))


def _normal_at(wp, point) -> np.ndarray:
    return wp.normal if isinstance(wp, Workpiece) else wp.normal_at(point)


def _check_contact(cell, eq):
    """The compliant contact's laws at a solution: penetration f_n/k along the normal, balance,
    unilateral force, Coulomb's cone (and its edge when sliding)."""
    wp = cell.workpiece
    assert eq.in_contact
    n = _normal_at(wp, eq.tip)
    f = eq.contact_force
    fn = float(f @ n)
    assert fn >= 0.0
    # a sliding solve is accepted with a force residual up to SLIDE_TOL (kinestat.sim.contact),
    # which the workpiece's spring turns into a depth error of at most SLIDE_TOL / k
    depth_tol = 2e-9 if wp.friction == 0.0 or eq.sticking else SLIDE_TOL / wp.stiffness
    assert float(wp.gap(eq.tip)) == pytest.approx(-fn / wp.stiffness, abs=depth_tol)
    assert _balanced(cell, eq) <= 1e-6
    ft = float(np.linalg.norm(f - fn * n))
    assert ft <= wp.friction * fn * (1.0 + 1e-6) + SLIDE_TOL
    if wp.friction > 0.0 and not eq.sticking:
        assert ft == pytest.approx(wp.friction * fn, abs=SLIDE_TOL)
    if wp.friction > 0.0 and eq.sticking:  # the tip stays on the normal through its anchor
        np.testing.assert_allclose(eq.tip, eq.anchor - fn / wp.stiffness * n, atol=1e-7)
    return fn


@settings(max_examples=30, deadline=None)
@given(depth=st.floats(0.05, 3.0), tilt=st.floats(0.0, 25.0), azimuth=st.floats(0.0, 360.0),
       mu=st.sampled_from([0.0, 0.05, 0.3, 1.0]), log_k=st.floats(-0.5, 3.0))
def test_plane_penetration_is_f_over_k_within_the_cone(depth, tilt, azimuth, mu, log_k):
    cell = _plane(depth, _normal(tilt, azimuth), mu, 10.0 ** log_k)
    try:
        eq = equilibrium(cell, FLANGE)
    except UnreachableError:
        assume(False)
    _check_contact(cell, eq)


@settings(max_examples=15, deadline=None)
@given(depth=st.floats(0.05, 3.0), radius=st.floats(60.0, 500.0), off=st.floats(-20.0, 20.0),
       mu=st.sampled_from([0.0, 0.3]), log_k=st.floats(-0.5, 3.0))
def test_cylinder_penetration_is_f_over_k_along_the_true_normal(depth, radius, off, mu, log_k):
    cell = _cylinder(depth, radius, mu, 10.0 ** log_k, off=off)
    try:
        eq = solve(cell, FLANGE)
    except UnreachableError:
        assume(False)
    _check_contact(cell, eq)


@settings(max_examples=20, deadline=None)
@given(depth=st.floats(0.05, 3.0), tilt=st.floats(0.0, 25.0), azimuth=st.floats(0.0, 360.0),
       log_k=st.floats(-0.5, 3.0))
def test_a_compliant_plane_is_the_rigid_plane_moved_back_by_the_penetration(depth, tilt, azimuth,
                                                                             log_k):
    # frictionless: the rigid plane through the compliant solution's tip, solved on its own,
    # gives the same top pose and force (an independent solve of the same mechanics)
    n = _normal(tilt, azimuth)
    cell = _plane(depth, n, 0.0, 10.0 ** log_k)
    eq = equilibrium(cell, FLANGE)
    fn = eq.normal_force
    rigid = _plane(depth - fn / cell.workpiece.stiffness, n, 0.0, None)
    ref = equilibrium(rigid, FLANGE)
    np.testing.assert_allclose(ref.contact_force, eq.contact_force, atol=1e-7)
    np.testing.assert_allclose(ref.top_pose, eq.top_pose, atol=1e-9)


def test_a_sticking_compliant_tip_is_the_rigid_one_at_the_sunk_anchor():
    n = _normal(10.0, 30.0)
    cell = _plane(2.0, n, 1.0, 2.0)
    eq = equilibrium(cell, FLANGE)
    assert eq.sticking
    sunk = eq.anchor - eq.normal_force / 2.0 * n
    rigid = _plane(2.0 - eq.normal_force / 2.0, n, 1.0, None)
    ref = equilibrium(rigid, FLANGE, anchor=sunk)
    assert ref.sticking
    np.testing.assert_allclose(ref.contact_force, eq.contact_force, atol=1e-7)


@pytest.mark.parametrize("mu", [0.0, 0.05, 0.3])
@pytest.mark.parametrize("kind", ["plane", "cylinder"])
def test_a_stiff_workpiece_is_the_rigid_one(kind, mu):
    # the force differs from the rigid one by O(1/k): a thousandfold stiffer workpiece comes
    # a thousandfold closer, and the rigid solution is the limit
    def force(k):
        cell = (_plane(2.0, _normal(10.0, 0.0), mu, k) if kind == "plane"
                else _cylinder(2.0, 150.0, mu, k, off=10.0))
        return solve(cell, FLANGE).contact_force

    rigid = force(None)
    errs = [float(np.linalg.norm(force(k) - rigid)) for k in (1e2, 1e5)]
    assert errs[0] > 1e-3  # the compliance shows at 100 N/mm
    assert errs[1] < 2e-3 * errs[0] and errs[1] < 1e-3 * np.linalg.norm(rigid)


def test_softer_wood_takes_less_force_for_the_same_push():
    f = [equilibrium(_plane(2.0, _normal(0.0, 0.0), 0.0, k), FLANGE).normal_force
         for k in (0.5, 2.0, 10.0, None)]
    assert f == sorted(f)
    # head-on, the tip's spring and the workpiece's act in series: f ≈ depth / (1/k_p + 1/k)
    kp = f[-1] / 2.0  # the platform's own (secant) stiffness along the push
    assert f[0] == pytest.approx(2.0 / (1.0 / kp + 1.0 / 0.5), rel=0.05)


@pytest.mark.parametrize("bad", [0.0, -1.0, math.inf, math.nan, "wood"])
def test_stiffness_must_be_finite_and_positive(bad):
    with pytest.raises(InputError, match="workpiece stiffness"):
        Workpiece([0, 0, 0], [0, 0, 1], 0.0, bad)
    with pytest.raises(InputError, match="workpiece stiffness"):
        Cylinder([0, 0, 0], [0, 0, 1], 100.0, 0.0, bad)


def test_stiffness_attribute_and_default():
    assert Workpiece([0, 0, 0], [0, 0, 1]).stiffness is None
    c = Cylinder([0, 0, 0], [0, 0, 1], 100.0, stiffness=3)
    assert c.stiffness == 3.0 and isinstance(c.stiffness, float)
    assert c.tangent_plane([200.0, 0.0, 0.0]).stiffness == 3.0
