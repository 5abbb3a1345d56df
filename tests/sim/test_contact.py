"""The simulated contact's solvers (kinestat.sim.contact)."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from kinestat.errors import UnreachableError
from kinestat.parallel.platform import special_6_6
from kinestat.sim.contact import DEFAULT_TOOL_POINT_6, equilibrium, make_cell

PLAT = special_6_6()
FLANGE = np.eye(4)  # frame 6 = fixed frame: the tool points along +z
TIP0 = np.asarray(DEFAULT_TOOL_POINT_6)


def _plane_cell(depth, tilt_deg, azimuth_deg, mu, off=(0.0, 0.0)):
    """A plane ``depth`` mm into the unloaded tip, tilted, with friction ``mu``, and an anchor
    on it ``off`` mm (along n × x, n × y) from the straight-ahead point."""
    t, a = math.radians(tilt_deg), math.radians(azimuth_deg)
    n = -np.array([math.sin(t) * math.cos(a), math.sin(t) * math.sin(a), math.cos(t)])
    cell = make_cell(PLAT, plane_point=TIP0 + depth * n, plane_normal=n, friction=mu)
    anchor = TIP0 + depth * n + off[0] * np.cross(n, [1.0, 0, 0]) + off[1] * np.cross(n, [0, 1, 0])
    return cell, n, anchor - (anchor - cell.workpiece.point) @ n * n


def _solve(cell, anchor, newton: bool):
    """The equilibrium with the slide's one Newton (``newton``; its results recorded, None
    where it gave up) or with the secant search alone. Returns ``(eq, results)``."""
    from kinestat.sim import contact

    results = []
    one = contact._solve_slide
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(contact, "_solve_slide",
                   (lambda *a, **k: results.append(one(*a, **k)) or results[-1]) if newton
                   else (lambda *a, **k: None))
        return equilibrium(cell, FLANGE, anchor=anchor), results


def test_the_damped_slide_converges_where_plain_newton_diverges():
    # arctan's Newton iteration diverges from |x| > 1.39; the backtracking fallback of the
    # sliding contact must still reach the root (a property of the solver, no cell needed)
    from kinestat.sim._slide import damped_slide
    from kinestat.sim.contact import SLIDE_CONVERGED

    c = np.array([0.3, -0.2])

    def resid(d, X):
        return np.arctan(d - c), X

    d, x = 3.0 + c, 3.0 + c
    for _ in range(5):  # plain Newton: the step grows
        d = d - np.arctan(d - c) * (1.0 + (d - c) ** 2)
    assert np.max(np.abs(d - c)) > 10.0
    d2, X = damped_slide(resid, x.copy(), np.eye(4), SLIDE_CONVERGED)
    assert np.max(np.abs(np.arctan(d2 - c))) <= SLIDE_CONVERGED
    assert np.allclose(d2, c, atol=1e-9) and np.array_equal(X, np.eye(4))


@settings(max_examples=25, deadline=None)
@given(depth=st.floats(0.002, 3.0), tilt=st.floats(2.0, 25.0), azimuth=st.floats(0.0, 360.0),
       slip=st.floats(0.05, 0.95), off=st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)))
def test_the_one_newton_slide_is_the_secant_searchs_slide(depth, tilt, azimuth, slip, off):
    # the sliding contact by the one Newton on (pose, force, slip) against the same slide found
    # by the older search (a secant along the slip, then a 2-D Newton over whole stick solves),
    # from light touches to 3 mm deep, anchors off the straight-ahead point
    mu = slip * math.tan(math.radians(tilt))  # below the tilt's slope: a straight push slides
    cell, n, anchor = _plane_cell(depth, tilt, azimuth, mu, off)
    try:
        eq, used = _solve(cell, anchor, newton=True)
    except UnreachableError:
        assume(False)
    # compared where the one Newton settled the slide (a far snap is left to the search)
    assume(eq.in_contact and not eq.sticking and used and used[-1] is not None)
    ref, _ = _solve(cell, anchor, newton=False)
    assert not ref.sticking
    np.testing.assert_allclose(eq.anchor, ref.anchor, atol=1e-6)
    np.testing.assert_allclose(eq.contact_force, ref.contact_force, atol=1e-7)
    np.testing.assert_allclose(eq.leg_lengths, ref.leg_lengths, atol=1e-8)
    fn = eq.contact_force @ n
    ft = eq.contact_force - fn * n
    # on the cone's edge to 1e-10 N (the Newton stops on an absolute residual: at a 0.008 mm
    # touch, fn 0.08 N, it left 2e-11 N, 1.5e-8 relative; seen 2026-12-04)
    np.testing.assert_allclose(np.linalg.norm(ft), mu * fn, rtol=1e-8, atol=1e-10)
    assert ft @ (eq.anchor - anchor) < 0  # friction against the slip


@pytest.mark.parametrize(("depth", "tilt", "mu"), [(0.005, 8.0, 0.05), (0.05, 20.0, 0.3),
                                                   (1.0, 8.0, 0.05), (2.0, 25.0, 0.3)])
def test_the_one_newton_settles_light_and_loaded_slides(depth, tilt, mu):
    # the slides of a follow run, from a touch of hundredths of a newton to tens of newtons:
    # the one Newton settles them (no secant search), on Coulomb's cone against the slip
    cell, n, anchor = _plane_cell(depth, tilt, 0.0, mu)
    eq, used = _solve(cell, anchor, newton=True)
    assert not eq.sticking and used and used[-1] is not None
    fn = eq.contact_force @ n
    ft = eq.contact_force - fn * n
    assert fn > 0
    np.testing.assert_allclose(np.linalg.norm(ft), mu * fn, rtol=1e-8)
    slip = eq.anchor - anchor
    np.testing.assert_allclose(ft / np.linalg.norm(ft), -slip / np.linalg.norm(slip), atol=1e-8)


def test_a_light_slide_that_first_runs_on_is_found_from_a_start_further_out():
    # 0.018 N on a plane tilted 28°, the anchor 3 mm off the straight-ahead point: from the
    # guessed slip the one Newton turns back (the tangential stiffness along the slip is
    # negative there), from a start further out it settles where the secant search does
    cell, n, anchor = _plane_cell(0.01166, 27.86, 176.33, 0.4363, (2.2065, -2.3568))
    eq, used = _solve(cell, anchor, newton=True)
    assert not eq.sticking and len(used) > 1 and used[0] is None and used[-1] is not None
    ref, _ = _solve(cell, anchor, newton=False)
    np.testing.assert_allclose(eq.anchor, ref.anchor, atol=1e-6)
    np.testing.assert_allclose(eq.contact_force, ref.contact_force, atol=1e-9)
    fn = eq.contact_force @ n
    assert 0 < fn < 0.05
    np.testing.assert_allclose(np.linalg.norm(eq.contact_force - fn * n), 0.4363 * fn, rtol=1e-7)
