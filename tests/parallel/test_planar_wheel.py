"""Fig. 2-10 wheel on a wall (Vibhute §2.1.3.3): equilibrium checked by an independent scipy
solve of the force balance, closed forms of eqs. 2-14/2-24/2-25, the planar decomposition."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize

from kinestat.errors import InputError
from kinestat.parallel.kinestatic import DELTA, decompose_twist
from kinestat.parallel.planar_wheel import (
    WheelOnWall,
    actuator_displacements,
    actuator_step,
    figure_2_10_example,
    spring_offset,
    unloaded_offset,
    wheel_center,
    wheel_response,
    wheel_stiffness,
)

M = figure_2_10_example()
TILTED = WheelOnWall(body_points=np.array([[-40.0, 10.0], [55.0, -5.0]]),
                     stiffness=np.array([1.5, 4.0]), free_lengths=np.array([90.0, 75.0]),
                     wheel_radius=15.0, wall_point=np.array([5.0, -3.0]),
                     wall_normal=np.array([np.sin(0.3), np.cos(0.3)]))
MODELS = {"figure": M, "tilted wall": TILTED}


def force_on_wheel(model, C, d):
    """Independent: the springs' force on C, Σ −k (l − L0) (C − B)/l (Hooke along each spring)."""
    F = np.zeros(2)
    for b, k, L0 in zip(model.body_points, model.stiffness, model.free_lengths, strict=True):
        v = C - (d + b)
        ell = np.hypot(*v)
        F -= k * (ell - L0) * v / ell
    return F


def solve_wheel(model, d, guess):
    """Independent forward problem: the wheel's (s, N) for actuators at d (scipy root)."""
    n = model.wall_normal
    t = np.array([n[1], -n[0]])  # n is t turned +90°

    def balance(x):
        C = model.wall_point + x[0] * t + model.wheel_radius * n
        return force_on_wheel(model, C, d) + x[1] * n

    sol = scipy.optimize.root(balance, guess, tol=1e-14)
    assert np.linalg.norm(balance(sol.x)) <= 1e-10
    return sol.x


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("s, N", [(0.0, 0.0), (12.0, 5.0), (-30.0, 20.0), (7.5, 45.0)])
def test_actuator_displacements_balance_the_wheel(name, s, N):
    model = MODELS[name]
    d = actuator_displacements(model, s, N)
    C = wheel_center(model, s)
    F = force_on_wheel(model, C, d)
    np.testing.assert_allclose(F + N * model.wall_normal, 0.0, atol=1e-9 * max(1.0, N))
    # scipy's least squares on the same balance, for d, from a guess 10 mm away
    ls = scipy.optimize.least_squares(
        lambda x: force_on_wheel(model, C, x) + N * model.wall_normal, d + [10.0, -10.0],
        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    np.testing.assert_allclose(ls.x, d, atol=1e-7)
    # and the forward problem gives back (s, N)
    np.testing.assert_allclose(solve_wheel(model, d, [s + 3.0, N + 1.0]), [s, N], atol=1e-8)


def test_batched_and_linear_in_s():
    s = np.array([[-10.0, 0.0, 25.0], [3.0, 4.0, 5.0]])
    N = np.array([1.0, 10.0, 30.0])
    d = actuator_displacements(M, s, N)
    assert d.shape == (2, 3, 2)
    for i in np.ndindex(2, 3):
        np.testing.assert_allclose(d[i], actuator_displacements(M, s[i], N[i[1]]), atol=1e-12)
    # the balance fixes r = C − d from N alone: d moves with s along t exactly
    np.testing.assert_allclose(d[0, 1] - d[1, 1], (s[0, 1] - s[1, 1]) * M.wall_tangent,
                               atol=1e-12)


def test_eq_2_25_unloaded_and_eq_2_14_loaded():
    """Closed forms with c_i, s_i of the spring angles (theta_i from B_i to C)."""
    for N in (0.0, 8.0, 25.0):
        r = spring_offset(M, N)
        v = r - M.body_points
        ell = np.hypot(v[:, 0], v[:, 1])
        c, sn = v[:, 0] / ell, v[:, 1] / ell
        k1, k2 = M.stiffness
        rho = M.free_lengths / ell
        kcs = k1 * c[0] * sn[0] + k2 * c[1] * sn[1]
        eq_2_25 = np.array([[k1 * c[0] ** 2 + k2 * c[1] ** 2, kcs],
                            [kcs, k1 * sn[0] ** 2 + k2 * sn[1] ** 2]])
        kg = M.stiffness * (1 - rho)
        geometric = np.array([[kg @ sn**2, -kg @ (sn * c)], [-kg @ (sn * c), kg @ c**2]])
        K = wheel_stiffness(M, N)
        np.testing.assert_allclose(K, eq_2_25 + geometric, rtol=1e-12, atol=1e-12)
        # eq. 2-24 by central differences of the independent force (external force = −springs')
        h = 1e-5
        Kfd = np.column_stack([(force_on_wheel(M, r - h * e, 0) - force_on_wheel(M, r + h * e, 0))
                               / (2 * h) for e in np.eye(2)])
        np.testing.assert_allclose(K, Kfd, rtol=1e-7, atol=1e-7)
        assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()  # symmetric under load
        if N == 0.0:
            np.testing.assert_allclose(ell, M.free_lengths, rtol=1e-12)
            np.testing.assert_allclose(K, eq_2_25, rtol=1e-12)
        else:
            assert np.abs(K - eq_2_25).max() > 1e-3 * np.abs(K).max()


@pytest.mark.parametrize("name", list(MODELS))
def test_wheel_response_is_the_derivative_of_the_exact_equilibrium(name):
    model = MODELS[name]
    s0, N0 = 4.0, 12.0
    d0 = actuator_displacements(model, s0, N0)
    for dd in (np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([0.6, -0.8])):
        ds, dN = wheel_response(model, N0, dd)
        h = 1e-4
        plus = solve_wheel(model, d0 + h * dd, [s0, N0])
        minus = solve_wheel(model, d0 - h * dd, [s0, N0])
        np.testing.assert_allclose((plus - minus) / (2 * h), [ds, dN], rtol=1e-6, atol=1e-7)
        # actuator_step is its inverse
        np.testing.assert_allclose(actuator_step(model, N0, ds, dN), dd, atol=1e-12)


def test_kinestatic_step_reaches_the_target_to_second_order():
    s0, N0 = 0.0, 10.0
    d0 = actuator_displacements(M, s0, N0)
    errs = []
    for h in (1.0, 0.5, 0.25):
        d1 = d0 + actuator_step(M, N0, 2 * h, 4 * h)
        s1, N1 = solve_wheel(M, d1, [s0, N0])
        errs.append(np.hypot(s1 - (s0 + 2 * h), N1 - (N0 + 4 * h)))
    assert errs[0] < 0.05 * np.hypot(2.0, 4.0)  # within 5 % of a 2 mm, 4 N step
    assert errs[1] / errs[0] < 0.3 and errs[2] / errs[1] < 0.3  # halving the step quarters it


def test_planar_decomposition_equals_the_spatial_one_embedded():
    """Translation in the plane ↔ v_O, force ↔ f: decompose_twist gives δs t and λ = −δN."""
    N0 = 15.0
    K2 = wheel_stiffness(M, N0)
    K_ray = np.diag([1.0, 1.0, 7.0, 50.0, 60.0, 70.0])
    K_ray[:2, :2] = K2
    K_axis = K_ray @ DELTA
    W = np.r_[M.wall_normal, 0.0, 0.0, 0.0, 0.0]
    for dd in (np.array([1.0, 2.0]), np.array([-0.3, 0.1])):
        split = decompose_twist(K_axis, W, np.r_[0.0, 0.0, 0.0, dd, 0.0])
        ds, dN = wheel_response(M, N0, dd)
        np.testing.assert_allclose(split.freedom, np.r_[0, 0, 0, ds * M.wall_tangent, 0],
                                   atol=1e-12)
        np.testing.assert_allclose(split.lam, [-dN], rtol=1e-12)


def test_model_checks():
    assert np.all(unloaded_offset(M) @ M.wall_normal < 0)
    with pytest.raises(InputError, match="unit vector"):
        WheelOnWall(M.body_points, M.stiffness, M.free_lengths, 20.0, np.zeros(2), [0, 2.0])
    with pytest.raises(InputError, match="positive"):
        WheelOnWall(M.body_points, [-1.0, 2.0], M.free_lengths, 20.0, np.zeros(2), [0, 1.0])
    short = WheelOnWall(M.body_points, M.stiffness, [20.0, 20.0], 20.0, np.zeros(2), [0, 1.0])
    with pytest.raises(InputError, match="cannot meet"):
        actuator_displacements(short, 0.0, 1.0)
    with pytest.raises(AttributeError):
        M.wheel_radius = 3.0
    with pytest.raises(ValueError):
        M.stiffness[0] = 1.0
