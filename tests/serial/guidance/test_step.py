"""The step solver: J δq = B (Nadkarni eq. 4-11), scaling, least squares, damping, eq. 5-5,
the perturbation remedy and joint limits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError
from kinestat.mechanism.chain import from_nadkarni, from_standard_dh
from kinestat.serial.fk import fk
from kinestat.serial.guidance.planners import twist_between, twist_exp
from kinestat.serial.guidance.step import (
    DEFAULT_COND_LIMIT,
    characteristic_length,
    conditioning,
    escape_singularity,
    limit_violation,
    scaled_jacobian,
    second_order_residual,
    solve_second_order,
    solve_step,
)
from kinestat.serial.jacobian import jacobian
from tests.serial.guidance._models import C1, C2, PUMA


def test_exact_solve_matches_numpy_and_is_batched(rng):
    q = rng.uniform(-2, 2, (7, 6))
    J = jacobian(PUMA, q)
    B = rng.normal(size=(7, 6))
    sol = solve_step(J, B, prismatic=PUMA.prismatic, length=0.5)
    assert sol.dq.shape == (7, 6) and sol.cond.shape == (7,)
    np.testing.assert_allclose(sol.dq, np.linalg.solve(J, B[..., None])[..., 0],
                               rtol=1e-7, atol=1e-9)
    assert sol.method == "exact"
    assert np.all(sol.residual < 1e-9)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-3, 3), min_size=6, max_size=6), st.floats(0.01, 1000))
def test_unit_change_leaves_the_solution_and_conditioning_unchanged(q, scale):
    """Inches → any unit: lengths scale, angles and the dimensionless cond do not."""
    q = np.array(q)
    rows = np.array(C2.extra_dict()["rows"], dtype=float)
    fp = np.array(C2.extra_dict()["frame_points"], dtype=float)
    scaled = rows.copy()
    scaled[:, [0, 2]] *= scale
    m2 = from_nadkarni(scaled, fp * scale, n_active=6)
    q1 = C2.q_home + 0.1 * q
    q2 = np.where(C2.prismatic, q1 * scale, q1)
    J1, J2 = jacobian(C2, q1), jacobian(m2, q2)
    L1, L2 = characteristic_length(C2, q1), characteristic_length(m2, q2)
    assert L2 == pytest.approx(L1 * scale, rel=1e-9)
    B = np.array([0.01, -0.02, 0.03, 0.1, 0.2, -0.1])
    B2 = np.concatenate([B[:3], B[3:] * scale])
    s1 = solve_step(J1, B, prismatic=C2.prismatic, length=L1)
    s2 = solve_step(J2, B2, prismatic=C2.prismatic, length=L2)
    np.testing.assert_allclose(np.where(C2.prismatic, s2.dq / scale, s2.dq), s1.dq,
                               rtol=1e-6, atol=1e-9)
    assert s2.cond == pytest.approx(s1.cond, rel=1e-6)


def test_least_squares_for_five_and_minimum_norm_for_seven_joints(rng):
    dh = np.array([[0, 0.3, 0.1, np.pi / 2], [0, 0, 0.4, 0], [0, 0, 0.3, -np.pi / 2],
                   [0, 0.2, 0, np.pi / 2], [0, 0, 0.1, 0], [0, 0.1, 0, 0], [0, 0.05, 0.02, 0]])
    m5 = from_standard_dh(dh[:5])
    m7 = from_standard_dh(dh)
    q5 = rng.uniform(-1, 1, 5)
    q7 = rng.uniform(-1, 1, 7)
    B = rng.normal(size=6)
    s5 = solve_step(jacobian(m5, q5), B, prismatic=m5.prismatic, length=1.0)
    ref = np.linalg.lstsq(jacobian(m5, q5), B, rcond=None)[0]
    np.testing.assert_allclose(s5.dq, ref, atol=1e-10)
    assert s5.method == "least_squares" and s5.residual > 1e-6
    s7 = solve_step(jacobian(m7, q7), B, prismatic=m7.prismatic, length=1.0)
    np.testing.assert_allclose(s7.dq, np.linalg.pinv(jacobian(m7, q7)) @ B, atol=1e-10)
    assert s7.residual < 1e-9


def test_damping_is_zero_when_regular_and_bounded_when_singular(rng):
    q = np.array([0.1, -0.5, 0.4, 0.3, 0.7, 0.2])
    J = jacobian(PUMA, q)
    B = rng.normal(size=6)
    plain = solve_step(J, B, prismatic=PUMA.prismatic, length=0.5)
    damped = solve_step(J, B, prismatic=PUMA.prismatic, length=0.5, damping="auto")
    assert plain.cond < DEFAULT_COND_LIMIT
    assert float(damped.damping) == 0.0
    np.testing.assert_allclose(damped.dq, plain.dq)
    qs = q.copy()
    qs[4] = 0.0  # PUMA wrist singularity: joints 4 and 6 aligned
    Js = jacobian(PUMA, qs)
    sol = solve_step(Js, B, prismatic=PUMA.prismatic, length=0.5, damping="auto")
    assert sol.method == "damped" and float(sol.damping) > 0
    assert np.all(np.isfinite(sol.dq)) and np.linalg.norm(sol.dq) < 1e3


def test_bad_inputs_raise_input_error():
    J = jacobian(PUMA, np.zeros(6))
    with pytest.raises(InputError):
        solve_step(J, np.full(6, np.nan), prismatic=PUMA.prismatic)
    with pytest.raises(InputError):
        solve_step(J[:5], np.zeros(6), prismatic=PUMA.prismatic)
    with pytest.raises(InputError):
        solve_step(J, np.zeros(6), prismatic=PUMA.prismatic, length=0.0)
    with pytest.raises(InputError):
        solve_step(J, np.zeros(6), prismatic=PUMA.prismatic, damping="lots")


def test_nadkarni_configuration_1_is_near_singular_and_perturbation_escapes():
    """Illustration 4 starts from Table A2-2: joints 3 and 5 parallel (θ4 = 0)."""
    L = characteristic_length(C1, C1.q_home)
    _, cond = conditioning(scaled_jacobian(jacobian(C1, C1.q_home), C1.prismatic, L))
    assert cond > DEFAULT_COND_LIMIT
    q_new, cond_new, tries = escape_singularity(C1, C1.q_home, length=L)
    assert cond_new < DEFAULT_COND_LIMIT
    assert 1 <= tries <= 30
    _, check = conditioning(scaled_jacobian(jacobian(C1, q_new), C1.prismatic, L))
    assert check == pytest.approx(cond_new)
    assert np.max(np.abs(np.degrees(q_new - C1.q_home))) <= 30.0


def test_second_order_terms_reduce_the_error_of_a_single_rotation():
    """Configuration 2 turning the hand about the joint-4 axis (only θ4 rotates): eq. 5-5 is
    then exact to third order, the first-order solution only to second order."""
    q = C2.q_home
    H = fk(C2, q)
    L = characteristic_length(C2, q)
    errs1, errs2 = [], []
    for deg in (2.0, 5.0, 10.0):
        # target: rotate the hand about global z through its origin, and lift it
        a = math.radians(deg)
        c, s = math.cos(a), math.sin(a)
        T = H.copy()
        R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
        T[:3, :3] = R @ H[:3, :3]
        T[:3, 3] = H[:3, 3] + [0.0, 0.0, 0.3]
        B = twist_between(H, T)
        dq1 = solve_step(jacobian(C2, q), B, prismatic=C2.prismatic, length=L).dq
        dq2, iters, res = solve_second_order(C2, q, B, T[:3, 3] - H[:3, 3], length=L)
        assert res < 1e-12 and iters < 10
        r = second_order_residual(C2, q, dq2, B[:3], T[:3, 3] - H[:3, 3])
        assert np.linalg.norm(r) < 1e-10
        errs1.append(np.linalg.norm(fk(C2, q + dq1)[:3, 3] - T[:3, 3]))
        errs2.append(np.linalg.norm(fk(C2, q + dq2)[:3, 3] - T[:3, 3]))
    assert all(e2 < 0.2 * e1 for e1, e2 in zip(errs1, errs2, strict=True))
    # first-order error grows like the square of the angle, second-order like the cube
    assert errs1[2] / errs1[1] == pytest.approx(4.0, rel=0.1)
    assert errs2[2] / errs2[1] > 6.0


def test_twist_exp_is_the_matrix_exponential():
    from scipy.linalg import expm

    from kinestat.spatial.screws import twist_matrix

    rng = np.random.default_rng(3)
    for V in rng.normal(size=(10, 6)):
        np.testing.assert_allclose(twist_exp(V), expm(twist_matrix(V)), atol=1e-12)
    V = np.array([0, 0, 0, 1.0, 2.0, 3.0])
    np.testing.assert_allclose(twist_exp(V), expm(twist_matrix(V)), atol=1e-14)


def test_limit_violation_reports_joint_side_and_value():
    m = from_standard_dh(np.zeros((2, 4)), limits=[(-1, 1), (-0.5, 0.5)])
    assert limit_violation(m, [0.0, 0.0]) is None
    assert limit_violation(m, [0.0, 0.7]) == (1, "upper", 0.5, 0.7)
    assert limit_violation(m, [-1.5, 0.7]) == (0, "lower", -1.0, -1.5)
