"""The control cycle's joint-space step against independent computations: the vernier's choice
is the cheapest of its neighbours evaluated one by one through the forward analysis; and the
single-pose kernels of the arm, platform and SE(3) packages it builds on against their batched
formulations on random inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.control import controller as ctl
from kinestat.control.controller import THESIS_FORCE_DIRECTION, Target
from kinestat.errors import JointLimitError, UnreachableError
from kinestat.serial import puma762

START = np.array([-400.0, 800.0, -100.0])

def _cost(model, target, counts, counts_now) -> tuple[float, float]:
    """The vernier's cost and offset along S6 of one count vector, from the forward analysis
    of its joint angles (the axis-5 rounding of the 4 → 5 compensation included)."""
    phys = np.asarray(counts, dtype=float).copy()
    kappa = model.coupling * (counts[3] - counts_now[3])
    phys[4] += np.sign(-kappa) * np.floor(abs(kappa) + 0.5) + kappa  # round half away
    q = puma762.from_axis_angles(np.radians(phys * model.axis_deg_per_count))
    f = puma762.forward(q, model.tool_point_6)
    d = f.tool_point - target.tool_point
    along = float(d @ target.s6)
    lateral = float(np.linalg.norm(d - along * target.s6))
    tilt = math.acos(min(1.0, max(-1.0, float(f.s6 @ target.s6))))
    return (along / 1e-3) ** 2 + (lateral / 0.05) ** 2 + (tilt / math.radians(0.01)) ** 2, along


def test_vernier_picks_the_cheapest_neighbour_by_forward_analysis(model_and_counts):
    """Random reachable targets: without the vernier the counts are the rounded selection;
    with it, a count vector within ±4 counts on axes 1-3 and ±1 on 4-5 of those, no dearer
    than the rounded one or any of 40 random neighbours, each evaluated on its own; and the
    reported offset along S6 is the chosen counts' own. Unreachable targets raise."""
    model, rng = model_and_counts
    checked = refused = 0
    for i in range(60):
        target, q = _random_target(rng)
        if i % 10 == 0:  # out of reach
            target = Target(target.tool_point * 4.0, target.s6, target.a67)
        counts_now = ctl.q_to_axis_counts(model, puma762.to_axis_angles(q))
        counts_now = counts_now + rng.integers(-200, 200, 6)
        try:
            axis = puma762.select(puma762.reverse(target.tool_point, target.s6, target.a67,
                                                  model.tool_point_6), q, model.limits_deg).axis
        except (UnreachableError, JointLimitError) as exc:
            with pytest.raises(type(exc)):
                ctl._solve_counts(model, target, q, counts_now, True)
            refused += 1
            continue
        c0 = np.sign(x := np.degrees(axis) / model.axis_deg_per_count) * np.floor(np.abs(x) + 0.5)
        plain, _ = ctl._solve_counts(model, target, q, counts_now, False)
        np.testing.assert_array_equal(plain, c0)
        counts, along = ctl._solve_counts(model, target, q, counts_now, True)
        off = counts - c0
        assert np.all(np.abs(off[:3]) <= 4) and np.all(np.abs(off[3:5]) <= 1) and off[5] == 0
        best, best_along = _cost(model, target, counts, counts_now)
        assert along == pytest.approx(best_along, abs=1e-9)
        others = [c0] + [c0 + np.concatenate([rng.integers(-4, 5, 3), rng.integers(-1, 2, 2),
                                              [0]]) for _ in range(40)]
        for c in others:
            assert best <= _cost(model, target, c, counts_now)[0] * (1 + 1e-9) + 1e-12
        checked += 1
    assert checked > 40 and refused >= 5


def _random_target(rng) -> tuple[Target, np.ndarray]:
    """A reachable target near a random configuration inside the limits, and that q."""
    lo, hi = np.radians(puma762.AXIS_LIMITS_DEG).T
    axis = rng.uniform(0.8 * lo, 0.8 * hi)
    q = puma762.from_axis_angles(axis)
    f = puma762.forward(q + rng.normal(0.0, 1e-3, 6), [0.0, 0.0, 235.0])
    return Target(f.tool_point, f.s6, f.a67), q


def test_apply_one_is_apply():
    from kinestat.spatial.transforms import apply, apply_one

    rng = np.random.default_rng(11)
    for _ in range(2000):
        T = rng.normal(size=(4, 4)) * 10.0 ** rng.uniform(-3, 3)
        p = rng.normal(size=3) * 10.0 ** rng.uniform(-3, 3)
        ref = apply(T, p)
        np.testing.assert_allclose(apply_one(T, p), ref, rtol=0,
                                   atol=1e-15 * (np.abs(T).max() * np.abs(p).max() + 1.0))


def test_selection_matches_select_including_wrist_singular_poses(model_and_counts):
    model, rng = model_and_counts
    for i in range(300):
        q = puma762.from_axis_angles(rng.uniform(-2.5, 2.5, 6))
        if i % 3 == 0:
            q[4] = 0.0  # wrist singular: a family of solutions
        f = puma762.forward(q, model.tool_point_6)
        q_now = q + rng.normal(0.0, 0.3, 6)
        try:
            ref = puma762.select(puma762.reverse(f.tool_point, f.s6, f.a67, model.tool_point_6),
                                 q_now, model.limits_deg).axis
        except JointLimitError:
            with pytest.raises(JointLimitError):
                puma762.select_axis_one(f.tool_point, f.s6, f.a67, model.tool_point_6, q_now,
                                        model.limits_deg)
            continue
        fast = puma762.select_axis_one(f.tool_point, f.s6, f.a67, model.tool_point_6, q_now,
                                       model.limits_deg)
        np.testing.assert_array_equal(fast, ref)


def test_cross3_is_numpy_cross_bit_for_bit():
    from kinestat.spatial.transforms import cross3

    rng = np.random.default_rng(5)
    for _ in range(2000):
        a, b = rng.normal(size=(2, 3)) * 10.0 ** rng.uniform(-6, 6, (2, 1))
        np.testing.assert_array_equal(cross3(a, b), np.cross(a, b))


def test_compiled_stiffness_equals_the_numpy_formulation(model_and_counts):
    from kinestat.parallel.stiffness import stiffness, stiffness_axis_trusted
    from kinestat.spatial.se3 import twist_exp

    model, rng = model_and_counts
    plat = model.platform
    for _ in range(200):
        T = twist_exp(np.concatenate([rng.normal(0, 0.03, 3), rng.normal(0, 2, 3)])) \
            @ plat.home_pose
        K = stiffness(plat, T, twist_order="axis")
        np.testing.assert_allclose(stiffness_axis_trusted(plat, T), K, rtol=0,
                                   atol=1e-13 * np.max(np.abs(K)))


def test_compose_twist_line_is_compose_twist_for_one_contact(model_and_counts):
    from kinestat.errors import KinestatError
    from kinestat.parallel.kinestatic import DELTA, compose_twist, compose_twist_line

    model, rng = model_and_counts
    from kinestat.parallel.stiffness import stiffness

    K = stiffness(model.platform, model.platform.home_pose, twist_order="axis")
    for i in range(300):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        p = rng.normal(0.0, 50.0, 3)
        w = np.concatenate([n, np.cross(p, n)])
        T = rng.normal(size=6)
        X = np.concatenate([np.zeros(3), n])  # w·ΔX = n·n = 1
        Tf = T - float(w @ (T @ DELTA)) * X if i % 4 else T  # reciprocal to w, or not
        dw = rng.normal() * w if i % 5 else rng.normal(size=6)
        try:
            ref = compose_twist(K, w, Tf, dw)
        except KinestatError as exc:
            with pytest.raises(type(exc)):
                compose_twist_line(K, w, Tf, dw)
            continue
        np.testing.assert_array_equal(compose_twist_line(K, w, Tf, dw), ref)


def test_single_twist_and_rotation_vector_agree_with_the_batched_ones():
    from scipy.spatial.transform import Rotation

    from kinestat.spatial.se3 import rotvec_matrix_one, twist_exp, twist_exp_one

    rng = np.random.default_rng(7)
    for i in range(3000):
        w = rng.normal(size=3) * 10.0 ** rng.uniform(-9, 0.5) if i % 10 else np.zeros(3)
        V = np.concatenate([w, rng.normal(size=3) * 10.0 ** rng.uniform(-3, 3)])
        scale = max(1.0, float(np.max(np.abs(V[3:]))))
        np.testing.assert_allclose(twist_exp_one(V), twist_exp(V), rtol=0, atol=4e-15 * scale)
        np.testing.assert_allclose(rotvec_matrix_one(w), Rotation.from_rotvec(w).as_matrix(),
                                   rtol=0, atol=4e-15)


def test_flange_pose_is_the_forward_analysis_bit_for_bit():
    rng = np.random.default_rng(3)
    for _ in range(500):
        q = rng.uniform(-5.0, 5.0, 6)
        np.testing.assert_array_equal(puma762.pose_one(q), puma762.forward(q).pose)


@pytest.fixture
def model_and_counts():
    prep = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=START, cell=SimulatedCell()))
    return prep.config.model, np.random.default_rng(11)
