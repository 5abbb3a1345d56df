"""The sliding contact's normal estimate under Coulomb friction (kinestat.control.contact_estimate):
forces built independently from a known normal, slip direction and friction coefficient."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.control.contact_estimate import (
    cone_normal,
    fit_circle,
    path_curvature,
    turn_by_curvature,
)


def _frame(rng):
    """A random normal n and a random unit slip direction t perpendicular to it."""
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    t = np.cross(n, rng.normal(size=3))
    return n, t / np.linalg.norm(t)


def _sliding_force(n, t, mu, fn):
    """Coulomb's law on the tool: normal reaction f_n n, friction mu f_n against the slip t."""
    return fn * n - mu * fn * t


vec = st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1)


@settings(max_examples=200, deadline=None)
@given(a=vec, b=vec, mu=st.floats(0.0, 1.0), fn=st.floats(0.1, 20.0))
def test_cone_normal_recovers_the_normal(a, b, mu, fn):
    n = np.asarray(a) / np.linalg.norm(a)
    t = np.cross(n, b)
    if np.linalg.norm(t) < 1e-3:
        return
    t /= np.linalg.norm(t)
    f = _sliding_force(n, t, mu, fn)
    np.testing.assert_allclose(cone_normal(f, t, mu), n, atol=1e-10)
    # the force leans from the normal by atan(mu), against the slip
    u = f / np.linalg.norm(f)
    assert math.atan(-u @ t / math.sqrt(1.0 - (u @ t) ** 2)) == pytest.approx(math.atan(mu),
                                                                               abs=1e-9)


def test_an_error_of_the_chord_out_of_the_surface_does_not_bias_the_normal():
    # the chord of a curved path or a noisy tip leaves the tangent plane (its elevation);
    # the normal only depends on the plane spanned by the force and the chord
    rng = np.random.default_rng(1)
    for _ in range(50):
        n, t = _frame(rng)
        mu = rng.uniform(0, 0.8)
        f = _sliding_force(n, t, mu, rng.uniform(1, 8))
        chord = t + rng.uniform(-0.2, 0.2) * n  # up to ~11° out of the surface
        np.testing.assert_allclose(cone_normal(f, chord, mu), n, atol=1e-10)


def test_an_error_across_the_slip_turns_the_normal_by_mu_times_it():
    rng = np.random.default_rng(2)
    for _ in range(50):
        n, t = _frame(rng)
        mu = rng.uniform(0.05, 0.8)
        f = _sliding_force(n, t, mu, 4.0)
        eps = math.radians(rng.uniform(0.5, 3.0))
        chord = math.cos(eps) * t + math.sin(eps) * np.cross(n, t)  # turned in the surface
        err = math.acos(min(1.0, float(cone_normal(f, chord, mu) @ n)))
        alpha = math.atan(mu)
        # the plane of force and chord turns about the force by eps / cos(alpha), the normal
        # (alpha from the force) by sin(alpha) times that
        assert err <= 1.01 * mu * eps + 1e-9
        # the force direction itself is off by alpha; the estimate is far better
        assert err < 0.2 * alpha


def test_frictionless_the_normal_is_the_force_direction():
    rng = np.random.default_rng(3)
    n, t = _frame(rng)
    np.testing.assert_allclose(cone_normal(3.0 * n, t, 0.0), n, atol=1e-12)


def test_cone_normal_is_batched():
    rng = np.random.default_rng(4)
    frames = [_frame(rng) for _ in range(7)]
    n = np.array([a for a, _ in frames])
    t = np.array([b for _, b in frames])
    mu = rng.uniform(0, 0.6, 7)
    f = n * 2.0 - (mu * 2.0)[:, None] * t
    out = cone_normal(f, t, mu)
    assert out.shape == (7, 3)
    np.testing.assert_allclose(out, n, atol=1e-10)


# --- the curvature of the tip path (circle fit) --------------------------------------------


@settings(max_examples=40, deadline=None)
@given(st.floats(-50.0, 50.0), st.floats(-400.0, -5.0), st.floats(5.0, 400.0),
       st.floats(0.0, 2 * math.pi), st.floats(0.05, 0.6))
def test_fit_circle_recovers_a_known_circle(xc, yc, r, a0, span):
    """Exact points on an arc of a known circle (centre off the x axis): the fit's centre and
    radius are the circle's."""
    yc = yc if abs(yc) > 1.0 else -1.0
    a = a0 + np.linspace(0.0, span, 9)
    x, y = xc + r * np.cos(a), yc + r * np.sin(a)
    A, B, D = fit_circle(x, y)
    # A (x² + y²) + B x − y + D = 0: centre (−B, 1)/(2A), radius sqrt(B² + 1 − 4AD)/(2|A|)
    c = np.array([-B, 1.0]) / (2.0 * A)
    rad = math.sqrt(B * B + 1.0 - 4.0 * A * D) / (2.0 * abs(A))
    assert np.allclose(c, [xc, yc], rtol=1e-7, atol=1e-6 * r)
    assert rad == pytest.approx(r, rel=1e-7)


def test_fit_circle_of_a_line_is_flat():
    x = np.linspace(-5.0, 5.0, 7)
    A, B, D = fit_circle(x, 0.2 * x + 1.5)
    assert abs(A) < 1e-12 and B == pytest.approx(0.2) and D == pytest.approx(1.5)


def _cylinder_path(rng, R, s_back, n_pts, obliq=0.0):
    """Tips on a cylinder of radius R (random pose) travelled along a helix at angle `obliq`
    from the circumference, ending at the last tip; the surface normal and travel direction
    there. The normal curvature along the travel is cos²(obliq)/R (Euler's theorem)."""
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    centre = rng.normal(size=3) * 100.0
    s = np.linspace(-s_back, 0.0, n_pts)  # arc length along the helix, last tip at s = 0
    th, z = s * math.cos(obliq) / R, s * math.sin(obliq)
    P = centre + np.column_stack([R * np.cos(th), R * np.sin(th), z]) @ Q.T
    n = Q @ np.array([1.0, 0.0, 0.0])
    t = Q @ np.array([0.0, math.cos(obliq), math.sin(obliq)])
    return P, n, t


@pytest.mark.parametrize("R, obliq_deg", [(150.0, 0.0), (200.0, 0.0), (400.0, 0.0),
                                          (200.0, 20.0), (300.0, 35.0)])
def test_path_curvature_of_exact_tips_on_a_cylinder(R, obliq_deg):
    """Convex: +cos²φ/R (the centre inside the material), to the helix's small torsion."""
    rng = np.random.default_rng(int(R) + int(obliq_deg))
    P, n, t = _cylinder_path(rng, R, 11.0, 12, math.radians(obliq_deg))
    k = path_curvature(P[:-1], P[-1], n, t, 4.0)
    assert k == pytest.approx(math.cos(math.radians(obliq_deg)) ** 2 / R, rel=2e-3)
    # concave: the same path seen from inside the material
    assert path_curvature(P[:-1], P[-1], -n, t, 4.0) == pytest.approx(-k, rel=1e-9)


def test_path_curvature_is_zero_on_a_plane_and_below_the_span():
    rng = np.random.default_rng(3)
    n, t = _frame(rng)
    s = np.linspace(-10.0, 0.0, 11)
    P = np.outer(s, t) + 0.001 * np.outer(s, n)  # a straight, slightly sloped path
    assert abs(path_curvature(P[:-1], P[-1], n, t, 4.0)) < 1e-9
    P2, n2, t2 = _cylinder_path(rng, 200.0, 3.0, 6)
    assert path_curvature(P2[:-1], P2[-1], n2, t2, 4.0) == 0.0  # spans 3 mm < 4 mm
    assert path_curvature(P2[:1], P2[-1], n2, t2, 0.0) == 0.0  # too few points


def test_turn_by_curvature_follows_the_circle():
    """The normal and tangent predicted a step ds ahead on a circle of radius R are the
    circle's own at that point (n = radial, t = its derivative)."""
    R, ds = 200.0, 1.0
    th0, th1 = 0.3, 0.3 + ds / R
    n, t = turn_by_curvature([math.cos(th0), math.sin(th0), 0.0],
                             [-math.sin(th0), math.cos(th0), 0.0], ds / R)
    assert np.allclose(n, [math.cos(th1), math.sin(th1), 0.0], atol=1e-14)
    assert np.allclose(t, [-math.sin(th1), math.cos(th1), 0.0], atol=1e-14)


def test_path_curvature_ignores_noise_on_a_straight_path_and_keeps_a_real_arc():
    """Tips with 0.02 mm noise along the normal: on a straight path any fitted curvature is
    not significant (0); on an R = 200 mm arc over 11 mm (sagitta 0.076 mm) it is kept, near
    1/R."""
    rng = np.random.default_rng(7)
    n, t = _frame(rng)
    s = np.linspace(-11.0, 0.0, 12)
    zeros = 0
    for _ in range(50):
        P = np.outer(s, t) + np.outer(rng.normal(0.0, 0.02, 12), n)
        zeros += path_curvature(P[:-1], P[-1], n, t, 4.0) == 0.0
    assert zeros >= 45
    P2, n2, t2 = _cylinder_path(rng, 200.0, 11.0, 12)
    P2 = P2 + np.outer(rng.normal(0.0, 0.005, 12), n2)
    assert path_curvature(P2[:-1], P2[-1], n2, t2, 4.0) == pytest.approx(1 / 200.0, rel=0.5)


def test_path_curvature_needs_a_sagitta_above_the_stated_noise():
    """Four exact tips fit a circle exactly (no residual): an R = 200 mm path over 3 mm
    (sagitta 5.6 µm) is no curvature against 36 µm of stated noise; over 11 mm (sagitta
    76 µm) it is."""
    rng = np.random.default_rng(11)
    P, n, t = _cylinder_path(rng, 200.0, 3.0, 4)
    assert path_curvature(P[:-1], P[-1], n, t, 0.0) == pytest.approx(1 / 200.0, rel=1e-3)
    assert path_curvature(P[:-1], P[-1], n, t, 0.0, noise=0.036) == 0.0
    P2, n2, t2 = _cylinder_path(rng, 200.0, 11.0, 4)
    assert path_curvature(P2[:-1], P2[-1], n2, t2, 0.0, noise=0.036) == pytest.approx(
        1 / 200.0, rel=1e-3)
