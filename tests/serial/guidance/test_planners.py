"""Path planners of Nadkarni's analysis types I–IV: geometry of the ideal paths and the
step twists B (eqs. 4-11, 4-17, 4-19, 4-21, 4-22)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError
from kinestat.mechanism.nadkarni import hand_points
from kinestat.serial.guidance.planners import (
    auto_steps,
    command_path,
    general_motion,
    general_path,
    line_path,
    path_extent,
    pose_error,
    screw_path,
    twist_between,
    twist_exp,
)
from kinestat.spatial.displacement import screw_from_poses
from kinestat.spatial.transforms import make_pose

vec = st.lists(st.floats(-1, 1), min_size=3, max_size=3).map(np.array)


def _pose(rv, p):
    from scipy.spatial.transform import Rotation

    return make_pose(Rotation.from_rotvec(rv).as_matrix(), p)


@settings(max_examples=30, deadline=None)
@given(vec, vec, vec, vec, st.floats(0.05, 0.95))
def test_screw_path_keeps_axis_and_pitch(rv1, p1, rv2, p2, s):
    """Type II: every intermediate pose is on the screw of the whole displacement."""
    T1, T2 = _pose(rv1, 3 * p1), _pose(2 * rv2, 3 * p2)
    whole = screw_from_poses(T1, T2)
    if abs(float(whole.theta)) < 1e-3:
        return
    path = screw_path(T1, T2)
    part = screw_from_poses(T1, path.pose_at(s))
    sign = np.sign(np.dot(part.axis, whole.axis))
    np.testing.assert_allclose(sign * part.axis, whole.axis, atol=1e-9)
    np.testing.assert_allclose(part.point, whole.point, atol=1e-8)
    assert float(part.pitch) == pytest.approx(float(whole.pitch), rel=1e-7, abs=1e-9)
    assert sign * float(part.theta) == pytest.approx(s * float(whole.theta), abs=1e-9)
    np.testing.assert_allclose(path.pose_at(1.0), T2, atol=1e-12)
    # eq. 4-19: the step twist is constant and k of them make the whole screw
    B = path.step_twist(0.2, 0.3, np.eye(4))
    np.testing.assert_allclose(twist_exp(10 * B) @ T1, T2, atol=1e-10)


def test_twist_between_inverts_twist_exp(rng):
    for _ in range(20):
        T1 = _pose(rng.normal(size=3), rng.normal(size=3))
        T2 = _pose(rng.normal(size=3), rng.normal(size=3))
        np.testing.assert_allclose(twist_exp(twist_between(T1, T2)) @ T1, T2, atol=1e-10)


@settings(max_examples=30, deadline=None)
@given(vec, vec, vec, vec, st.floats(0, 1))
def test_line_path_origin_moves_on_the_straight_line(rv1, p1, rv2, p2, s):
    """Type III: the hand origin of every split position is on the segment a1 a2."""
    P1 = hand_points(_pose(rv1, 5 * p1))
    P2 = hand_points(_pose(1.5 * rv2, 5 * p2))
    try:
        path = line_path(P1, P2)
    except InputError:
        return  # an intermediate triangle degenerates (rotations near a half turn)
    o = path.pose_at(s)[:3, 3]
    a1, a2 = P1[0], P2[0]
    np.testing.assert_allclose(o, a1 + s * (a2 - a1), atol=1e-12)
    np.testing.assert_allclose(path.pose_at(1.0), _pose(1.5 * rv2, 5 * p2), atol=1e-9)


def test_line_path_refuses_degenerate_splits():
    P1 = np.array([[0, 0, 0], [0, 0, 1.0], [1, 0, 0]])
    P2 = np.array([[0, 0, 0], [0, 0, -1.0], [1, 0, 0]])  # z reverses: the split passes 0
    with pytest.raises(InputError):
        line_path(P1, P2)


def test_general_path_example_4_reaches_target_on_a_straight_line(rng):
    T1 = _pose(rng.normal(size=3), rng.normal(size=3))
    T2 = _pose(rng.normal(size=3), rng.normal(size=3))
    path = general_path(T1, T2)
    np.testing.assert_allclose(path.pose_at(1.0), T2, atol=1e-12)
    for s in (0.25, 0.5):
        o = path.pose_at(s)[:3, 3]
        np.testing.assert_allclose(o, T1[:3, 3] + s * (T2[:3, 3] - T1[:3, 3]), atol=1e-12)
    # eq. 4-11a: rotation about u_w through the current origin plus δr along u_v
    H = path.pose_at(0.3)
    B = path.step_twist(0.3, 0.4, H)
    v_origin = B[3:] + np.cross(B[:3], H[:3, 3])
    np.testing.assert_allclose(v_origin, 0.1 * (T2[:3, 3] - T1[:3, 3]), atol=1e-12)
    sc = screw_from_poses(T1, T2)
    np.testing.assert_allclose(B[:3], 0.1 * float(sc.theta) * sc.axis, atol=1e-12)


def test_general_motion_examples_1_to_3():
    """Ex. 3: rotation about z through O_H plus translation along x. Eq. 4-11a gives
    B = [0 0 δθ  ρ2δθ+δr  −ρ1δθ  0]; the thesis prints −ρ2δθ, ρ1δθ (a sign slip, see
    docs/seed-errata.md G2): with it the hand origin would not stay on its path."""
    H = _pose([0.1, 0.2, 0.3], [1.0, 2.0, 3.0])
    path = general_motion(H, [0, 0, 2.0], math.radians(30), [3.0, 0, 0], 2.0)
    k = 10
    B = path.step_twist(0.0, 1 / k, H)
    d_th, d_r = math.radians(30) / k, 2.0 / k
    rho = H[:3, 3]
    np.testing.assert_allclose(B, [0, 0, d_th, rho[1] * d_th + d_r, -rho[0] * d_th, 0],
                               atol=1e-14)
    # independent check: the velocity of the hand origin is δr u_v, with no part from ω
    np.testing.assert_allclose(B[3:] + np.cross(B[:3], rho), [d_r, 0, 0], atol=1e-14)
    end = path.pose_at(1.0)
    np.testing.assert_allclose(end[:3, 3], rho + [2.0, 0, 0], atol=1e-12)
    with pytest.raises(InputError):
        general_motion(H, [0, 0, 0], 0.5, [1, 0, 0], 1.0)


def test_command_in_hand_frame_equals_global_command_with_q_prime():
    """Eq. 4-22: R = Q'R'."""
    H = _pose([0.3, -0.7, 1.1], [15.0, -25.0, 12.0])
    Rp = np.array([1.0, 0.0, 0.0])
    hand = command_path(H, Rp, -1.0, math.radians(15), "hand")
    glob = command_path(H, H[:3, :3] @ Rp, -1.0, math.radians(15), "global")
    np.testing.assert_allclose(hand.twist, glob.twist, atol=1e-14)
    # eq. 4-21: the axis passes through the hand origin, pitch d/θ
    sc = screw_from_poses(H, hand.end)
    assert float(sc.pitch) == pytest.approx(-1.0 / math.radians(15) * np.sign(
        np.dot(sc.axis, H[:3, :3] @ Rp)), rel=1e-9)
    c = np.cross(H[:3, 3] - sc.point, sc.axis)
    assert np.linalg.norm(c) < 1e-9
    # a pure translation (θ = 0) moves the origin by d along R
    tr = command_path(H, [0, 0, 2.0], 4.0, 0.0)
    np.testing.assert_allclose(tr.end[:3, 3], H[:3, 3] + [0, 0, 4.0], atol=1e-12)
    with pytest.raises(InputError):
        command_path(H, [0, 0, 0], 1.0, 0.0)
    with pytest.raises(InputError):
        command_path(H, [0, 0, 1], 1.0, 0.0, frame="tool")


def test_auto_steps_bounds_rotation_and_translation_per_step():
    H = np.eye(4)
    T = _pose([0, 0, math.radians(45)], [0, 0, 0])
    assert auto_steps(screw_path(H, T), length=10.0) == 45
    T = _pose([0, 0, 0], [3.0, 0, 0])
    assert auto_steps(screw_path(H, T), length=10.0) == 30  # 0.1 per step
    T = _pose([0, 0, math.radians(10)], [3.0, 0, 0])
    path = general_path(H, T)
    k = auto_steps(path, length=10.0)
    P = path.pose_at(np.linspace(0, 1, k + 1))
    dp, da = pose_error(P[1:], P[:-1])
    assert np.max(dp) <= 0.1 + 1e-12 and np.max(np.degrees(da)) <= 1.0 + 1e-9
    rot, dist = path_extent(path)
    assert rot == pytest.approx(math.radians(10)) and dist == pytest.approx(3.0)
