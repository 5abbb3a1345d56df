"""The follow task's travel: the measured tips' displacement on the developed surface."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinestat.control.follow.estimator import developed_step


def _walk(steps, n, t):
    dev = (0.0, 0.0)
    for d in steps:
        dev = developed_step(dev, n, np.asarray(d, float), t)
    return dev


N = np.array([0.0, 0.0, 1.0])
T = np.array([1.0, 0.0, 0.0])


def test_a_wander_across_the_travel_and_back_does_not_count():
    rng = np.random.default_rng(0)
    side = rng.uniform(-0.5, 0.5, 40)
    side -= side.mean()  # back where it started across the travel
    steps = [(1.0, s, 0.0) for s in side]
    a, c = _walk(steps, N, T)
    assert math.hypot(a, c) == pytest.approx(40.0, abs=1e-9)


@pytest.mark.parametrize("phi_deg", [0.0, 10.0, 35.0])
def test_a_steady_drift_counts_its_whole_length(phi_deg):
    phi = math.radians(phi_deg)
    steps = [(0.8 * math.cos(phi), 0.8 * math.sin(phi), 0.0)] * 25
    a, c = _walk(steps, N, T)
    assert math.hypot(a, c) == pytest.approx(20.0, abs=1e-9)


def test_a_stuck_tips_jitter_cancels():
    rng = np.random.default_rng(1)
    pts = rng.normal(0.0, 0.05, (30, 3))
    steps = np.diff(np.vstack([np.zeros(3), pts, np.zeros(3)]), axis=0)
    a, c = _walk(steps, N, T)
    assert math.hypot(a, c) == pytest.approx(0.0, abs=1e-12)


def test_on_a_cylinder_the_sum_of_short_chords_is_the_unrolled_length():
    """Round a cylinder of radius R at a helix angle: the developed length is the helix's
    length, which the campaign's true travel (arc and axial part) also measures."""
    R, k, psi = 200.0, 200, math.radians(30.0)
    s = np.linspace(0.0, 50.0, k + 1)
    ang, z = s * math.cos(psi) / R, s * math.sin(psi)
    P = np.column_stack([R * np.sin(ang), R * np.cos(ang), z])
    dev = (0.0, 0.0)
    for i in range(k):
        n = np.array([math.sin(ang[i]), math.cos(ang[i]), 0.0])
        t = np.array([math.cos(ang[i]) * math.cos(psi), -math.sin(ang[i]) * math.cos(psi),
                      math.sin(psi)])
        dev = developed_step(dev, n, P[i + 1] - P[i], t)
    assert math.hypot(*dev) == pytest.approx(50.0, rel=1e-4)
