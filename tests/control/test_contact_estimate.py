"""The sliding contact's normal estimate under Coulomb friction (kinestat.control.contact_estimate):
forces built independently from a known normal, slip direction and friction coefficient."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.control.contact_estimate import (
    MIN_FRICTION_WEIGHT,
    cone_normal,
    friction_sample,
    normal_and_friction,
    update_friction,
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
    assert abs(friction_sample(f, t) - mu) <= 1e-9 * (1.0 + mu)
    fn_est, friction = normal_and_friction(f, n)
    assert abs(fn_est - fn) <= 1e-9 * fn
    np.testing.assert_allclose(friction, -mu * fn * t, atol=1e-9 * fn)


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
    assert abs(friction_sample(3.0 * n, t)) < 1e-12


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


def test_the_running_mean_of_mu_averages_noisy_samples():
    rng = np.random.default_rng(5)
    mu, k = 0.0, 0
    samples = 0.3 + rng.normal(0, 0.03, 400)
    for s in samples:
        mu, k = update_friction(mu, k, s)
    assert k == 400
    # at most the last 1/MIN_FRICTION_WEIGHT samples weigh: the standard error of ~20 samples
    assert abs(mu - 0.3) < 4 * 0.03 * math.sqrt(MIN_FRICTION_WEIGHT / 2)
    # the first sample is taken as it is
    assert update_friction(0.0, 0, 0.25) == (0.25, 1)
