"""The controller's arm protocol: the thesis PUMA 762 is one instance; another arm with an
analytic solver (a UR5 in millimetres) is driven by the pure controller's IK step."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import kinestat
from kinestat.control.arm import THESIS_ARM, Arm, ChainArm, Puma762Arm
from kinestat.control.controller import ControllerConfig, axis_counts_to_q, decide, start
from kinestat.control.wrench import measure
from kinestat.errors import JointLimitError, ModelError, UnreachableError
from kinestat.mechanism.chain import from_standard_dh
from kinestat.robots.puma762 import closed_form as puma762

from .conftest import PLATFORM, scenario

PI = math.pi


def ur5_mm(limits=None):
    """UR5 (standard DH, millimetres), its own independent table."""
    rows = np.column_stack([np.zeros(6), [89.159, 0, 0, 109.15, 94.65, 82.3],
                            [0, -425.0, -392.25, 0, 0, 0], [PI / 2, 0, 0, PI / 2, -PI / 2, 0]])
    return from_standard_dh(rows, limits=limits, name="ur5-mm", length_unit="mm")


def test_puma762_is_an_arm_instance_and_default():
    assert isinstance(THESIS_ARM, Arm) and isinstance(ChainArm(ur5_mm()), Arm)
    scn = scenario()
    assert isinstance(scn.model.arm, Puma762Arm)
    np.testing.assert_array_equal(scn.model.limits_deg, puma762.AXIS_LIMITS_DEG)
    # its all-solutions view is the thesis closed form as an IKAllResult
    q = np.array([0.3, -0.4, 0.5, 0.2, 0.7, -0.1])
    res = THESIS_ARM.ik_all(puma762.forward(q).pose)
    assert res.method == "puma762"
    assert np.any(np.max(np.abs(res.q - q), axis=-1) < 1e-9)


def test_generic_arm_agrees_with_the_thesis_selection_on_the_puma():
    """ChainArm over the loaded PUMA 762 (axis 1 = φ1 + 180°) picks what the thesis picks."""
    generic = ChainArm(kinestat.load("puma762"), axis_offset=[PI, 0, 0, 0, 0, 0],
                       limits_deg=puma762.AXIS_LIMITS_DEG)
    rng = np.random.default_rng(5)
    lo, hi = np.radians(puma762.AXIS_LIMITS_DEG).T
    n = 0
    for _ in range(60):
        axis_now = rng.uniform(lo, hi) * 0.9
        axis_goal = axis_now + rng.normal(0, 0.3, 6)
        q_now, q_goal = puma762.from_axis_angles(axis_now), puma762.from_axis_angles(axis_goal)
        f = puma762.forward(q_goal, [0.0, 0.0, 150.0])
        args = (f.tool_point, f.s6, f.a67, [0.0, 0.0, 150.0], q_now, puma762.AXIS_LIMITS_DEG)
        try:
            a = THESIS_ARM.solve_axis(*args)
        except JointLimitError:
            with pytest.raises(JointLimitError):
                generic.solve_axis(*args)
            continue
        b = generic.solve_axis(*args)
        np.testing.assert_allclose(b, a, atol=1e-7)
        n += 1
    assert n > 30


def test_ur5_start_and_one_cycle_within_limits():
    lim = np.radians([[-170, 170], [-170, -10], [-160, 160], [-170, 170], [-170, 170],
                      [-350, 350]])
    arm = ChainArm(ur5_mm(limits=lim))
    np.testing.assert_allclose(arm.limits_deg, np.degrees(lim))
    scn = scenario()
    # the UR5 in place of the PUMA: its own limits, no axis 4 -> 5 coupling
    model = replace(scn.model, arm=arm, limits_deg=None, coupling=0.0)
    np.testing.assert_allclose(model.limits_deg, np.degrees(lim))
    p6 = model.tool_point_6
    q_goal = np.array([0.4, -1.1, 1.3, -1.6, -1.2, 0.5])
    f = arm.forward(q_goal, p6)
    config = ControllerConfig(model=model, start_tool_point=f.tool_point, start_s6=f.s6,
                              start_a67=f.a67, force=4.0 * f.s6)
    q_now = q_goal + np.array([0.05, -0.04, 0.03, 0.02, -0.05, 0.04])
    cmd, state = start(config, q_now)
    assert cmd.kind == "move", cmd.reason
    q_cmd = axis_counts_to_q(model, cmd.axis_counts)
    assert np.all(q_cmd >= lim[:, 0]) and np.all(q_cmd <= lim[:, 1])
    got = arm.forward(q_cmd, p6)
    # the commanded counts reach the start tool point (to the encoder resolution)
    assert np.linalg.norm(got.tool_point - f.tool_point) < 0.05
    assert math.degrees(math.acos(min(1.0, float(got.s6 @ f.s6)))) < 0.01
    # of the UR5's 8 solutions, the one nearest the current configuration
    assert np.max(np.abs(q_cmd - q_goal)) < 1e-3
    # one cycle: no contact (legs at their free lengths) -> approach along S6
    counts = scn.sensor.counts(PLATFORM, PLATFORM.free_lengths)
    meas = measure(model, q_cmd, counts, PLATFORM.home_pose)
    cmd2, _ = decide(config, replace(state, axis_counts=cmd.axis_counts), meas)
    assert cmd2.kind == "move" and cmd2.action == "approach", cmd2.reason
    q2 = axis_counts_to_q(model, cmd2.axis_counts)
    assert np.all(q2 >= lim[:, 0]) and np.all(q2 <= lim[:, 1])
    moved = arm.forward(q2, p6).tool_point - got.tool_point
    assert abs(float(moved @ f.s6) - config.approach_step) < 0.05
    assert np.linalg.norm(moved - (moved @ f.s6) * f.s6) < 0.05


def test_ur5_limits_and_unreachable_stop():
    # a shoulder range that no solution of the start pose satisfies -> stop, nothing moves
    lim = np.radians([[-170, 170], [10, 20], [-160, 160], [-170, 170], [-170, 170],
                      [-350, 350]])
    arm = ChainArm(ur5_mm(limits=lim))
    scn = scenario()
    model = replace(scn.model, arm=arm, limits_deg=None, coupling=0.0)
    f = arm.forward(np.array([0.4, -1.1, 1.3, -1.6, -1.2, 0.5]), model.tool_point_6)
    config = ControllerConfig(model=model, start_tool_point=f.tool_point, start_s6=f.s6,
                              start_a67=f.a67, force=4.0 * f.s6)
    cmd, _ = start(config, np.zeros(6))
    assert cmd.kind == "stop" and "limits" in cmd.reason
    with pytest.raises(UnreachableError, match="no inverse-kinematics solution"):
        arm.solve_axis([5000.0, 0, 0], [0, 0, 1.0], [1.0, 0, 0], [0, 0, 0], np.zeros(6),
                       arm.limits_deg)
    with pytest.raises(ModelError):
        ChainArm(from_standard_dh(np.tile([0.0, 0.1, 0.2, 0.5], (5, 1))))


@pytest.mark.parametrize("arm", [THESIS_ARM, ChainArm(ur5_mm())], ids=["puma762", "ur5"])
def test_the_measured_tool_frame_is_the_arms_forward_analysis(arm):
    """measure's tool frame (the arm's single-pose flange_pose and the tool point carried by
    it) against the arm's batched forward analysis, at random joint values."""
    from kinestat.control.wrench import tool_frame

    scn = scenario()
    model = replace(scn.model, arm=arm)
    rng = np.random.default_rng(12)
    for q in rng.uniform(-PI, PI, size=(20, 6)):
        tool, s6, a67, T = tool_frame(q, model)
        want = arm.forward(q, model.tool_point_6)
        np.testing.assert_allclose(T, want.pose, rtol=0, atol=1e-9)
        np.testing.assert_allclose(tool, want.tool_point, rtol=0, atol=1e-9)
        np.testing.assert_allclose(s6, want.s6, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a67, want.a67, rtol=0, atol=1e-12)
