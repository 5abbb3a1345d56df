"""The fast control cycle decides exactly what the unoptimised one decided (issue 13, compute
time): recorded (state, measurement) pairs of simulated runs replayed through both paths, and
the compiled pieces (vernier, selection, flange pose, motion check) against their NumPy
formulations on random inputs."""

from __future__ import annotations

import copy
import functools
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, CylinderSpec, SimulatedCell, prepare_control
from kinestat.app.sim_cell import InProcessIO, start_counts
from kinestat.control import controller as ctl
from kinestat.control._reference import (
    reference_cycle,
    solve_counts_reference,
    vernier_costs_reference,
)
from kinestat.control.controller import THESIS_FORCE_DIRECTION, Target, decide
from kinestat.control.envelope import Envelope, check_motion
from kinestat.control.follow import decide_follow
from kinestat.control.log import CycleLog
from kinestat.control.loop import run
from kinestat.errors import JointLimitError, UnreachableError
from kinestat.serial import puma762

START = np.array([-400.0, 800.0, -100.0])

SCENARIOS = {
    "press": dict(task="press"),
    "press-fixed": dict(task="press", method="fixed"),
    "follow-plane": dict(task="follow", travel=20.0),
    "follow-cylinder-friction": dict(
        task="follow", travel=20.0, auto_tilt=True,
        cell=SimulatedCell(friction=0.3, cylinder=CylinderSpec(200.0, np.array([0.0, 0.0, 1.0])))),
}


def _record(**kw) -> tuple:
    """Run a scenario on the in-process simulated cell (fast path); its decision function and
    every (state, measurement) pair it was given."""
    kw.setdefault("cell", SimulatedCell())
    req = ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                         travel_dir=np.array([0.0, 1.0, 0.0]), **kw)
    prep = prepare_control(req)
    fn = (functools.partial(decide_follow, prep.follow) if kw["task"] == "follow"
          else functools.partial(decide, prep.config))
    pairs: list = []

    def recording(state, meas):
        pairs.append((state, meas))
        return fn(state, meas)

    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with tempfile.TemporaryDirectory() as tmp, CycleLog(Path(tmp) / "log.jsonl") as log:
        run(prep.config, io, log, decide_fn=recording)
    return prep, fn, pairs


def _same_command(a, b) -> None:
    assert (a.kind, a.label, a.action, a.reason) == (b.kind, b.label, b.action, b.reason)
    if a.axis_counts is None:
        assert b.axis_counts is None
        return
    assert np.array_equal(a.axis_counts, b.axis_counts)  # the command sent: identical
    assert np.array_equal(a.q, b.q)
    # the stiffness is compiled on the fast path (equal to rounding), and so are what follows
    # from it: the target (through the Newton step / the twist of compliance), the prediction
    for x, y in ((a.target.tool_point, b.target.tool_point), (a.target.s6, b.target.s6),
                 (a.prediction.force, b.prediction.force),
                 (a.prediction.deflections, b.prediction.deflections),
                 (a.prediction.top_pose, b.prediction.top_pose)):
        np.testing.assert_allclose(x, y, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_recorded_cycles_decide_the_same_commands(name):
    prep, fn, pairs = _record(**SCENARIOS[name])
    moves = 0
    for state, meas in pairs:
        fast_cmd, fast_state = fn(state, copy.copy(meas))
        with reference_cycle():
            ref_cmd, ref_state = fn(state, copy.copy(meas))
        _same_command(fast_cmd, ref_cmd)
        assert fast_state.label == ref_state.label
        moves += fast_cmd.kind == "move"
    assert moves >= 3  # the run really moved (the replay compared vernier choices)


def _random_target(rng) -> tuple[Target, np.ndarray]:
    """A reachable target near a random configuration inside the limits, and that q."""
    lo, hi = np.radians(puma762.AXIS_LIMITS_DEG).T
    axis = rng.uniform(0.8 * lo, 0.8 * hi)
    q = puma762.from_axis_angles(axis)
    f = puma762.forward(q + rng.normal(0.0, 1e-3, 6), [0.0, 0.0, 235.0])
    return Target(f.tool_point, f.s6, f.a67), q


def test_vernier_and_selection_match_the_numpy_reference_on_random_targets(model_and_counts):
    model, rng = model_and_counts
    checked = 0
    for _ in range(150):
        target, q = _random_target(rng)
        counts_now = ctl._q_to_axis_counts(model, puma762.to_axis_angles(q))
        counts_now = counts_now + rng.integers(-200, 200, 6)
        for vernier in (True, False):
            try:
                ref, ref_along = solve_counts_reference(model, target, q, counts_now, vernier)
            except (UnreachableError, JointLimitError) as exc:
                with pytest.raises(type(exc)):
                    ctl._solve_counts(model, target, q, counts_now, vernier)
                continue
            fast, fast_along = ctl._solve_counts(model, target, q, counts_now, vernier)
            if not np.array_equal(fast, ref):  # only a tie to rounding may differ (documented)
                c0 = ctl._q_to_axis_counts(model, puma762.select(
                    puma762.reverse(target.tool_point, target.s6, target.a67,
                                    model.tool_point_6), q, model.limits_deg).axis)
                cand, cost, _ = vernier_costs_reference(model, target, c0, counts_now, vernier)
                k = int(np.flatnonzero(np.all(cand == fast, axis=1))[0])
                assert cost[k] == pytest.approx(cost.min(), rel=1e-9, abs=1e-12)
            assert fast_along == pytest.approx(ref_along, abs=1e-9)
            checked += 1
    assert checked > 200


def test_the_puma_move_in_one_call_is_the_three_steps(model_and_counts):
    """``puma_move_one`` (one compiled call) gives the counts of ``_solve_counts``, their joint
    angles and the flange pose; where the reverse analysis or selection fails it gives None
    and the three steps raise."""
    from kinestat.control.vernier import puma_move_one

    model, rng = model_and_counts
    moved = refused = 0
    for i in range(200):
        target, q = _random_target(rng)
        if i % 10 == 0:  # out of reach
            target = Target(target.tool_point * 4.0, target.s6, target.a67)
        counts_now = ctl._q_to_axis_counts(model, puma762.to_axis_angles(q))
        counts_now = counts_now + rng.integers(-200, 200, 6)
        for vernier in (True, False):
            got = puma_move_one(model, target, q, counts_now, vernier)
            if got is None:
                with pytest.raises((UnreachableError, JointLimitError)):
                    ctl._solve_counts(model, target, q, counts_now, vernier)
                refused += 1
                continue
            counts, q_new, T = got
            ref, _ = ctl._solve_counts(model, target, q, counts_now, vernier)
            np.testing.assert_array_equal(counts, ref)
            np.testing.assert_array_equal(q_new, ctl.axis_counts_to_q(model, ref))
            np.testing.assert_allclose(T, ctl._flange_pose(model, q_new), rtol=0, atol=1e-12)
            moved += 1
    assert moved > 300 and refused >= 20


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


def test_cross_helpers_are_numpy_cross_bit_for_bit():
    from kinestat.control.cycle import cross3, cross_rows

    rng = np.random.default_rng(5)
    for _ in range(2000):
        a, b = rng.normal(size=(2, 3)) * 10.0 ** rng.uniform(-6, 6, (2, 1))
        np.testing.assert_array_equal(cross3(a, b), np.cross(a, b))
    for _ in range(200):
        a, b = rng.normal(size=(2, 6, 3)) * 10.0 ** rng.uniform(-6, 6, (2, 6, 1))
        np.testing.assert_array_equal(cross_rows(a, b), np.cross(a, b))


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


def test_compiled_base_twist_is_the_numpy_formulation(model_and_counts):
    """The follow law's base twist, compiled, against its NumPy formulation at random loaded
    poses, base poses, contacts and motions (with and without the friction edge and the hold);
    a singular K falls back to the NumPy formulation, which raises its error."""
    from types import SimpleNamespace

    from kinestat.control import follow
    from kinestat.errors import InputError
    from kinestat.spatial.se3 import twist_exp

    model, rng = model_and_counts
    plat = model.platform
    for i in range(300):
        top = twist_exp(np.concatenate([rng.normal(0, 0.03, 3), rng.normal(0, 2, 3)])) \
            @ plat.home_pose
        base = twist_exp(np.concatenate([rng.normal(0, 1.0, 3), rng.normal(0, 500, 3)]))
        meas = SimpleNamespace(top_pose=top, base_pose=base)
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        t = np.cross(n, rng.normal(size=3))  # a travel along the tangent plane
        args = (model, meas, base[:3, 3] + rng.normal(0, 300, 3), n, rng.normal(0, 0.01, 3),
                rng.uniform(0, 2) * t / np.linalg.norm(t), rng.normal(0, 1), 0.5,
                rng.uniform(0, 0.5) if i % 2 else 0.0, t if i % 3 else None,
                (rng.normal(0, 5, 3), rng.normal(0, 0.01, 3)) if i % 4 else None)
        fast = follow._base_twist_fast(*args)
        ref = follow._base_twist_numpy(*args)
        assert fast is not None
        np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))
        np.testing.assert_array_equal(follow._base_twist(*args), fast)
    meas = SimpleNamespace(top_pose=plat.home_pose, base_pose=np.eye(4))
    ctl_cycle = follow.cycle_data(model, meas)
    ctl_cycle.__dict__["K"] = np.diag([1.0, 1.0, 1.0, 1.0, 1.0, 0.0])  # singular
    args = (model, meas, np.zeros(3), np.array([0.0, 0.0, 1.0]), np.zeros(3),
            np.array([1.0, 0.0, 0.0]), 0.5, 0.5)
    assert follow._base_twist_fast(*args, 0.0, None, None) is None
    with pytest.raises((InputError, np.linalg.LinAlgError)):  # (what _act stops on)
        follow._base_twist(*args)


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


def test_motion_check_shortcut_gives_the_same_verdicts(model_and_counts):
    """Rotations around the ranges' edges: the check with its shortcut and with SciPy's
    rotation vector on every pose report the same violations."""
    from kinestat.control import envelope as env_mod

    model, rng = model_and_counts
    env = Envelope()
    home = model.platform.home_pose
    rot_lim = min(env.motion_range[3:])
    for _ in range(400):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = math.radians(rot_lim * rng.uniform(0.5, 1.5))
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        R = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
        T = home.copy()
        T[:3, :3] = R @ home[:3, :3]
        T[:3, 3] += rng.normal(0.0, 2.0, 3)
        fast = check_motion(env, model, T, "predicted")
        saved = env_mod._rotation_clear
        env_mod._rotation_clear = lambda *a: False
        try:
            ref = check_motion(env, model, T, "predicted")
        finally:
            env_mod._rotation_clear = saved
        assert fast == ref


@pytest.fixture
def model_and_counts():
    prep = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=START, cell=SimulatedCell()))
    return prep.config.model, np.random.default_rng(11)
