"""The guidance loop: path invariants of types II–IV, closed loop, singularities, joint limits,
stops that end cleanly, and joint rates (suggestion 1)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError, JointLimitError, KinestatError
from kinestat.mechanism.chain import from_nadkarni
from kinestat.mechanism.nadkarni import hand_points
from kinestat.serial.fk import fk
from kinestat.serial.guidance.planners import (
    command_path,
    general_path,
    line_path,
    screw_path,
    twist_between,
)
from kinestat.serial.guidance.run import GuidanceOptions, joint_display, run_guidance
from kinestat.serial.guidance.velocity import joint_rates
from kinestat.spatial.displacement import frame_from_triple, screw_from_poses
from kinestat.spatial.transforms import make_pose
from tests.serial.guidance._models import C1, C2, PUMA

Q_REG = np.radians([40.0, 70.0, 60.0, 30.0, 50.0, 20.0])  # a regular pose of configuration 1
OPEN = GuidanceOptions(settle=False)
CLOSED = GuidanceOptions(closed_loop=True, settle=False)


def _target(model, q, rv, dp):
    from scipy.spatial.transform import Rotation

    H = fk(model, q)
    R = Rotation.from_rotvec(rv).as_matrix() @ H[:3, :3]
    return make_pose(R, H[:3, 3] + dp)


def _on_screw(start, poses, whole):
    """Largest departure of intermediate poses from the whole screw: axis line and pitch."""
    worst = 0.0
    for T in poses[1:]:
        part = screw_from_poses(start, T)
        s = np.sign(np.dot(part.axis, whole.axis)) or 1.0
        worst = max(worst, float(np.linalg.norm(s * part.axis - whole.axis)),
                    float(np.linalg.norm(part.point - whole.point)),
                    abs(float(part.pitch) - float(whole.pitch)))
    return worst


@settings(max_examples=8, deadline=None)
@given(st.lists(st.floats(-0.4, 0.4), min_size=3, max_size=3),
       st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3))
def test_type_ii_closed_loop_keeps_every_pose_on_the_screw(rv, dp):
    T2 = _target(C1, Q_REG, np.array(rv), np.array(dp))
    H0 = fk(C1, Q_REG)
    whole = screw_from_poses(H0, T2)
    if abs(float(whole.theta)) < 0.05:
        return
    r = run_guidance(C1, Q_REG, [screw_path(H0, T2)], steps=20, options=CLOSED)
    if r.stopped:  # the straight screw may leave the workspace: a clean stop is fine
        assert r.stop_kind in ("singular", "not_converged", "joint_limit")
        return
    # every pose is the whole screw's motion by some angle θ_j: compared pose to pose (the
    # axis of a tiny partial screw is ill-conditioned, so the poses themselves are checked)
    tol = CLOSED.tol * r.length  # the closed-loop tolerance, relative to the mechanism's size
    assert _off_screw_motion(H0, r.poses, whole) < tol
    # the screw of H0 -> final pose: a pose error e moves its axis by up to e / (2 sin(θ/2))
    cond = 1.0 / min(1.0, 2.0 * abs(math.sin(float(whole.theta) / 2.0)))
    assert _on_screw(H0, [H0, r.poses[-1]], whole) < tol * cond
    dp_, da = r.final_pose_error()
    assert dp_ < tol and da < CLOSED.tol


def _off_screw_motion(start, poses, whole):
    """Largest distance (position, and rotation in rad) of each pose from the pose the whole
    screw's motion gives at the same angle about its axis."""
    from scipy.spatial.transform import Rotation

    from kinestat.spatial.displacement import pose_from_screw

    worst = 0.0
    u, h = whole.axis, float(whole.pitch)
    for T in poses[1:]:
        D = T @ np.linalg.inv(start)
        theta = float(np.dot(Rotation.from_matrix(D[:3, :3]).as_rotvec(), u))
        ideal = pose_from_screw(u, whole.point, theta, h * theta) @ start
        err_p = float(np.linalg.norm(T[:3, 3] - ideal[:3, 3]))
        err_r = float(np.linalg.norm(Rotation.from_matrix(T[:3, :3] @ ideal[:3, :3].T)
                                     .as_rotvec()))
        worst = max(worst, err_p, err_r)
    return worst


def test_type_ii_open_loop_stays_near_the_screw_and_converges_with_k():
    T2 = _target(C1, Q_REG, np.array([0.3, -0.2, 0.4]), np.array([2.0, -1.0, 1.5]))
    H0 = fk(C1, Q_REG)
    whole = screw_from_poses(H0, T2)
    devs = []
    for k in (20, 40, 80):
        r = run_guidance(C1, Q_REG, [screw_path(H0, T2)], steps=k, options=OPEN)
        assert not r.stopped and len(r.q) == k + 1
        devs.append(_on_screw(H0, r.poses, whole))
        # the thesis's B is constant: row j is J^-1 B applied j times
        assert r.max_path_deviation()[0] < 0.5
    assert devs[2] < devs[1] < devs[0]
    assert devs[0] / devs[2] == pytest.approx(4.0, rel=0.35)  # first-order method: O(1/k)


def test_type_iii_keeps_the_hand_origin_on_its_line():
    H0 = fk(C2, C2.q_home)
    P0 = hand_points(H0)
    P2 = np.array([[10, -10, 20], [11, -10, 20], [10, -10, 19.0]])
    a1, a2 = P0[0], P2[0]
    d = (a2 - a1) / np.linalg.norm(a2 - a1)

    def off_line(poses):
        o = poses[:, :3, 3] - a1
        return float(np.max(np.linalg.norm(o - np.outer(o @ d, d), axis=1)))

    r = run_guidance(C2, C2.q_home, [line_path(P0, P2)], steps=30, options=CLOSED)
    assert off_line(r.poses) < 1e-9
    np.testing.assert_allclose(joint_display(C2, r.q[-1]), [-15, 20, 0, 90, 90, 0], atol=1e-9)
    r = run_guidance(C2, C2.q_home, [line_path(P0, P2)], steps=30, options=OPEN)
    assert off_line(r.poses) < 0.05  # first-order error of one step only (no drift)


def test_type_iv_hand_frame_commands_equal_global_commands():
    """NTY = 1 with R' gives the same run as NTY = 0 with R = Q'R' (Q' at each command's
    start), and each command continues where the last ended (GUIDM)."""
    cmds_hand = [([1.0, 0, 0], -1.0, 15.0), ([0, 1.0, 1.0], 2.0, -20.0)]
    stages_hand = [(lambda H, c=c: command_path(H, c[0], c[1], math.radians(c[2]), "hand"))
                   for c in cmds_hand]
    r_hand = run_guidance(C2, C2.q_home, stages_hand, steps=[12, 16], options=OPEN)
    # the global equivalent, built from the actual hand at each command's start
    starts = [r_hand.poses[0], r_hand.poses[r_hand.stage_end_rows()[0]]]
    stages_glob = [command_path(S, S[:3, :3] @ np.array(c[0]), c[1], math.radians(c[2]))
                   for S, c in zip(starts, cmds_hand, strict=True)]
    r_glob = run_guidance(C2, C2.q_home, stages_glob, steps=[12, 16], options=OPEN)
    np.testing.assert_allclose(r_glob.q, r_hand.q, atol=1e-12)


def test_illustration_6_commands_move_the_hand_as_commanded():
    """Table A2-10: 4 along global z with −30° about it, then −1 along the hand's x with 15°."""
    stages = [lambda H: command_path(H, [0, 0, 1.0], 4.0, math.radians(-30)),
              lambda H: command_path(H, [1.0, 0, 0], -1.0, math.radians(15), "hand")]
    r = run_guidance(C2, C2.q_home, stages, options=CLOSED)
    ends = r.stage_end_rows()
    np.testing.assert_allclose(r.poses[ends[0], :3, 3], [15, -25, 16], atol=1e-9)
    # the hand x axis is global -z throughout (rotations about z): -1 along it is +1 in z
    np.testing.assert_allclose(r.poses[ends[1], :3, 3], [15, -25, 17], atol=1e-9)
    z_final = r.poses[-1, :3, 2]
    np.testing.assert_allclose(z_final, [math.sin(math.radians(45)),
                                         math.cos(math.radians(45)), 0], atol=1e-9)


def test_illustration_4_near_singular_start_is_detected_and_handled():
    H0 = fk(C1, C1.q_home)
    T2 = frame_from_triple(np.array([[-20.30, -7.83, -6.66], [-20.65, -8.29, -5.85],
                                     [-21.06, -7.18, -6.62]]))
    r = run_guidance(C1, C1.q_home, [screw_path(H0, T2)])
    ev = r.events[0]
    assert ev["step"] == 1 and ev["kind"] == "singular" and ev["action"] == "perturbed"
    assert ev["cond"] > 1e3 > ev["cond_after"]
    assert np.max(np.abs(ev["joint_increments"])) > 0
    assert not r.stopped
    assert r.final_pose_error()[0] < 1e-9
    rd = run_guidance(C1, C1.q_home, [screw_path(H0, T2)],
                      options=GuidanceOptions(singular="damped"))
    assert rd.events[0]["action"] == "damped" and rd.events[0]["damping"] > 0
    assert not rd.stopped and rd.final_pose_error()[0] < 1e-9 * rd.length
    rs = run_guidance(C1, C1.q_home, [screw_path(H0, T2)],
                      options=GuidanceOptions(singular="stop"))
    assert rs.stopped and rs.stop_kind == "singular" and len(rs.q) == 1
    with pytest.raises(KinestatError, match="singular"):
        rs.raise_if_stopped()


def _limited_config2(theta4_upper_deg):
    rows = np.array(C2.extra_dict()["rows"], dtype=float)
    fp = np.array(C2.extra_dict()["frame_points"], dtype=float)
    inf = math.inf
    limits = [(-inf, inf)] * 3 + [(-math.pi, math.radians(theta4_upper_deg))] + [(-inf, inf)] * 2
    return from_nadkarni(rows, fp, n_active=6, limits=limits)


def test_joint_limit_stops_cleanly_with_which_joint_step_and_limit():
    m = _limited_config2(30.0)
    P2 = np.array([[10, -10, 20], [11, -10, 20], [10, -10, 19.0]])
    r = run_guidance(m, m.q_home, [line_path(hand_points(fk(m, m.q_home)), P2)], steps=27)
    assert r.stopped and r.stop_kind == "joint_limit"
    ev = r.events[-1]
    assert ev["kind"] == "joint_limit" and ev["joint"] == 4 and ev["limit"] == "upper"
    assert ev["limit_value"] == pytest.approx(30.0) and ev["value"] > 30.0
    assert ev["step"] == len(r.q)  # the rows so far are kept, the offending step is not
    assert np.all(joint_display(m, r.q)[:, 3] <= 30.0)
    with pytest.raises(JointLimitError) as info:
        r.raise_if_stopped()
    assert info.value.joint == 4 and info.value.step == ev["step"]


def test_start_outside_limits_is_reported():
    m = _limited_config2(-10.0)
    r = run_guidance(m, m.q_home, [screw_path(fk(m, m.q_home), fk(m, m.q_home))], steps=1)
    assert r.stopped and r.events[0]["step"] == 0 and r.events[0]["kind"] == "joint_limit"


def test_unreachable_target_ends_with_a_report_not_a_traceback():
    H0 = fk(C1, Q_REG)
    far = H0.copy()
    far[:3, 3] += [200.0, 0, 0]  # the arm is ~30 in long
    for opts in (GuidanceOptions(), CLOSED, GuidanceOptions(singular="damped")):
        r = run_guidance(C1, Q_REG, [screw_path(H0, far)], steps=40, options=opts)
        assert r.stopped
        assert r.stop_kind in ("singular", "not_converged", "target_not_reached")
        assert r.stop_message
        with pytest.raises(KinestatError):
            r.raise_if_stopped()


def test_closed_loop_final_error_and_general_path():
    T2 = _target(C1, Q_REG, np.array([-0.2, 0.3, 0.1]), np.array([1.0, 2.0, -1.0]))
    H0 = fk(C1, Q_REG)
    for path in (screw_path(H0, T2), general_path(H0, T2)):
        r = run_guidance(C1, Q_REG, [path], steps=15, options=CLOSED)
        dp, da = r.final_pose_error()
        assert dp < CLOSED.tol * r.length and da < CLOSED.tol
        assert r.max_path_deviation()[0] < CLOSED.tol * r.length
    # without closed loop, settle steps still reach the target
    r = run_guidance(C1, Q_REG, [general_path(H0, T2)], steps=15)
    assert r.final_pose_error()[0] < 1e-9
    assert any(e["kind"] == "settle" for e in r.events)


def test_second_order_option_improves_type_iii_of_illustration_5():
    H0 = fk(C2, C2.q_home)
    P2 = np.array([[10, -10, 20], [11, -10, 20], [10, -10, 19.0]])
    path = line_path(hand_points(H0), P2)
    first = run_guidance(C2, C2.q_home, [path], steps=15, options=OPEN)
    second = run_guidance(C2, C2.q_home, [path], steps=15,
                          options=GuidanceOptions(second_order=True, settle=False))
    assert second.max_path_deviation()[0] < 0.2 * first.max_path_deviation()[0]


def test_step_counts_validation():
    H0 = fk(C2, C2.q_home)
    path = screw_path(H0, H0)
    with pytest.raises(InputError):
        run_guidance(C2, C2.q_home, [path, path], steps=[3])
    with pytest.raises(InputError):
        run_guidance(C2, C2.q_home, [], steps=3)
    with pytest.raises(InputError):
        run_guidance(C2, C2.q_home, [path], steps=[-2])
    with pytest.raises(InputError):
        GuidanceOptions(singular="ignore")


def test_joint_rates_reproduce_the_hand_speed():
    """Eqs. 5-1..5-4: the rates move the hand along the twist with |ω_H| = speed (or
    |v_H| = speed for a pure translation); checked by finite differences of the FK."""
    q = np.array([0.1, -0.5, 0.4, 0.3, 0.7, 0.2])
    tw = np.array([0.1, -0.2, 0.3, 0.05, 0.02, -0.01])
    speed = 0.7
    qd = joint_rates(PUMA, q, tw, speed)
    h = 1e-6
    V = twist_between(fk(PUMA, q), fk(PUMA, q + h * qd)) / h
    np.testing.assert_allclose(V, tw * speed / np.linalg.norm(tw[:3]), rtol=1e-5, atol=1e-7)
    qd_t = joint_rates(C2, C2.q_home, [0, 0, 0, 1.0, 2.0, 2.0], 6.0)
    V = twist_between(fk(C2, C2.q_home), fk(C2, C2.q_home + h * qd_t)) / h
    np.testing.assert_allclose(V, [0, 0, 0, 2.0, 4.0, 4.0], atol=1e-6)
    batch = joint_rates(PUMA, np.stack([q, q]), np.stack([tw, 2 * tw]), np.array([1.0, 1.0]))
    np.testing.assert_allclose(batch[0], batch[1], atol=1e-12)
    with pytest.raises(InputError):
        joint_rates(PUMA, q, np.zeros(6), 1.0)
