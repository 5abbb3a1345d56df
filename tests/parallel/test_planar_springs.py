"""Planar spring examples (Vibhute eqs. 2-10 to 2-15, 2-25)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError, SingularityError
from kinestat.parallel.planar_springs import (
    springs_in_parallel,
    springs_in_series,
    two_spring_compliance,
    two_spring_force,
    two_spring_stiffness,
)

PIVOTS = np.array([[0.0, 0.0], [100.0, 0.0]])
K = np.array([2.0, 3.5])
L0 = np.array([60.0, 70.0])


def test_parallel_and_series_by_physics():
    k = np.array([2.0, 5.0, 7.0])
    F = 3.0
    assert springs_in_parallel(k) * (F / springs_in_parallel(k)) == pytest.approx(F)
    # series: the same force stretches each spring by F/k_i; the total stretch is their sum
    assert springs_in_series(k) == pytest.approx(F / np.sum(F / k))
    assert springs_in_series([1000.0, 1.0]) == pytest.approx(1.0, rel=2e-3)  # the soft one rules
    with pytest.raises(InputError):
        springs_in_series([1.0, -2.0])


def test_force_balances_the_spring_forces():
    P = np.array([40.0, 50.0])
    f = two_spring_force(PIVOTS, P, K, L0)
    springs = 0.0
    for A, k, l0 in zip(PIVOTS, K, L0, strict=True):
        d = P - A
        l = np.linalg.norm(d)
        springs = springs - k * (l - l0) * d / l  # a stretched spring pulls P toward its pivot
    np.testing.assert_allclose(f + springs, 0.0, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.floats(10, 90), st.floats(5, 80))
def test_stiffness_is_the_derivative_of_the_force(x, y):
    P = np.array([x, y])
    Kfd = np.zeros((2, 2))
    h = 1e-5
    for i in range(2):
        e = np.zeros(2)
        e[i] = h
        Kfd[:, i] = (two_spring_force(PIVOTS, P + e, K, L0)
                     - two_spring_force(PIVOTS, P - e, K, L0)) / (2 * h)
    Ks = two_spring_stiffness(PIVOTS, P, K, L0)
    np.testing.assert_allclose(Ks, Kfd, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(Ks, Ks.T, atol=1e-12)  # a point: symmetric under any load


def test_unloaded_stiffness_is_eq_2_25():
    P = np.array([30.0, 40.0])
    l0 = np.linalg.norm(P - PIVOTS, axis=1)  # springs at their free lengths
    d = (P - PIVOTS) / l0[:, None]
    j = d.T
    np.testing.assert_allclose(two_spring_stiffness(PIVOTS, P, K, l0), j @ np.diag(K) @ j.T,
                               atol=1e-12)
    np.testing.assert_allclose(two_spring_force(PIVOTS, P, K, l0), 0.0, atol=1e-12)


def test_parallel_springs_unloaded_are_singular():
    piv = np.array([[0.0, 0.0], [-10.0, 0.0]])
    P = np.array([50.0, 0.0])
    l0 = np.linalg.norm(P - piv, axis=1)
    with pytest.raises(SingularityError):
        two_spring_compliance(piv, P, K, l0)
    # stretched, the same pair resists sideways motion (the δj term), so K is invertible
    C = two_spring_compliance(piv, P, K, l0 - 5.0)
    np.testing.assert_allclose(C @ two_spring_stiffness(piv, P, K, l0 - 5.0), np.eye(2),
                               atol=1e-12)


def test_batched_points():
    P = np.array([[30.0, 40.0], [50.0, 20.0], [70.0, 60.0]])
    Ks = two_spring_stiffness(PIVOTS, P, K, L0)
    assert Ks.shape == (3, 2, 2)
    np.testing.assert_allclose(Ks[1], two_spring_stiffness(PIVOTS, P[1], K, L0))
