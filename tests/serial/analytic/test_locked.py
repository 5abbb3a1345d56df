"""7-joint arms (Panda, iiwa 14) with one joint locked: every solution reproduces its pose by the
7-joint model's FK, the locked joint keeps its value, the generating configuration is found,
the count equals EAIK's with the same axis fixed; the self-motion samples the joint's range."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinestat
from kinestat.errors import InputError, ModelError
from kinestat.serial.analytic import ik_all, ik_self_motion
from kinestat.serial.analytic.geometry import home_axes
from kinestat.serial.analytic.locked import fold, plan
from tests.urdf_arms import ARMS, arm_path

from .arms import wrapped_distance


def _arm(name):
    if name == "panda":
        return kinestat.load(arm_path("panda"), tip=ARMS["panda"][1])
    rtbdata = pytest.importorskip("rtbdata")
    return kinestat.load(Path(rtbdata.__file__).parent / "xacro" / "kuka_description" /
                         "kuka_lbr_iiwa" / "urdf" / "lbr_iiwa_14_r820.urdf", tip="tool0")


def _configs(model, j, value, n, seed):
    q = np.random.default_rng(seed).uniform(-2.0, 2.0, (n, model.n))
    q[:, j] = value
    return q


@pytest.mark.parametrize("name", ["panda", "iiwa"])
@pytest.mark.parametrize("j", range(7))
def test_locked_solutions_reproduce_the_pose(name, j):
    model = _arm(name)
    q = _configs(model, j, 0.4, 40, seed=j)
    T = kinestat.fk(model, q)
    res = ik_all(model, T, locked={j: 0.4})
    assert res.q.shape[-1] == 7
    F = kinestat.fk(model, np.where(res.valid[..., None], res.q, 0.0))
    pos = np.linalg.norm(F[..., :3, 3] - T[:, None, :3, 3], axis=-1)
    rot = np.linalg.norm(F[..., :3, :3] - T[:, None, :3, :3], axis=(-2, -1))
    assert np.where(res.valid, pos, 0).max() < 1e-9 and np.where(res.valid, rot, 0).max() < 1e-9
    assert np.all(res.q[..., j][res.valid] == 0.4)
    d = wrapped_distance(res.q, q[:, None, :])
    assert np.all(np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1))


@pytest.mark.parametrize("name", ["panda", "iiwa"])
@pytest.mark.parametrize("j", [0, 2, 4, 6])
def test_locked_count_equals_eaik_fixed_axes(name, j):
    HPRobot = pytest.importorskip("eaik.IK_HP", reason="eaik is not installed "
                                  "(pip install -r requirements/bench.txt)").HPRobot
    model = _arm(name)
    ax = home_axes(model)
    pts = np.vstack([ax.r, ax.T0[:3, 3]])
    bot = HPRobot(ax.w.copy(), np.vstack([pts[0], np.diff(pts, axis=0)]), fixed_axes=[(j, 0.4)])
    if not bot.hasKnownDecomposition():
        pytest.skip(f"EAIK has no decomposition for {name} with joint {j} fixed")
    q = _configs(model, j, 0.4, 30, seed=10 + j)
    T = kinestat.fk(model, q)
    res = ik_all(model, T, locked={j: 0.4})
    for i in range(len(q)):
        Tp = T[i].copy()
        Tp[:3, :3] = T[i][:3, :3] @ ax.T0[:3, :3].T
        theirs: list[np.ndarray] = []
        for s in bot.IK(Tp).Q:
            s = np.asarray(s)
            F = kinestat.fk(model, s)
            if np.linalg.norm(F[:3, 3] - T[i][:3, 3]) < 1e-6 and \
                    np.linalg.norm(F[:3, :3] - T[i][:3, :3]) < 1e-6 and \
                    all(wrapped_distance(s, t) > 1e-6 for t in theirs):
                theirs.append(s)
        assert res.n_solutions[i] == len(theirs), f"pose {i}"


def test_self_motion_samples_the_limits_and_every_sample_solves():
    model = _arm("iiwa")
    q = np.array([0.3, 0.5, -0.4, -1.2, 0.2, 0.8, -0.3])
    T = kinestat.fk(model, q)
    sm = ik_self_motion(model, T, 2, 9)
    assert sm.values[0] == model.lower[2] and sm.values[-1] == model.upper[2]
    sols, which = sm.solutions()
    assert len(sols) == sum(int(r.n_solutions) for r in sm.results) > 0
    assert np.allclose(sols[:, 2], sm.values[which])
    F = kinestat.fk(model, sols)
    assert np.abs(F - T).max() < 1e-9
    # the generating configuration's joint value is on the curve: sampling it finds q
    res = ik_all(model, T, locked={2: q[2]})
    assert np.min(wrapped_distance(res.solutions(), q)) < 1e-9


def test_locked_errors():
    model = _arm("panda")
    T = kinestat.fk(model, np.zeros(7))
    with pytest.raises(ModelError, match="6 free joints"):
        ik_all(model, T, locked={0: 0.1, 1: 0.2})
    with pytest.raises(InputError, match="not a joint index"):
        ik_all(model, T, locked={7: 0.1})
    with pytest.raises(InputError, match="not finite"):
        ik_all(model, T, locked={1: float("nan")})
    with pytest.raises(ModelError, match="exactly 6"):
        ik_all(model, T)
    with pytest.raises(InputError, match="positive integer"):
        ik_self_motion(model, T, 1, 0)


@pytest.mark.parametrize("name,j", [("panda", 6), ("panda", 2), ("iiwa", 2)])
def test_locked_single_calls_equal_the_batch_and_the_folded_chain(name, j):
    """One pose per call (the cached plan, every key spelling of the same lock) gives the
    batch's solutions and the folded 6-joint chain's with the locked value put back."""
    model = _arm(name)
    q = _configs(model, j, -0.7, 25, seed=30 + j)
    T = kinestat.fk(model, q)
    batch = ik_all(model, T, locked={j: -0.7})
    six = ik_all(fold(model, ((j, -0.7),)), T)
    assert np.array_equal(batch.n_solutions, six.n_solutions)
    for i in range(len(q)):
        for locked in ({j: -0.7}, {np.int64(j): np.float64(-0.7)}, {j: -0.7}):
            one = ik_all(model, T[i], locked=locked)
            sols = one.solutions()
            assert sols.shape[1] == 7 and np.all(sols[:, j] == -0.7)
            assert np.all(np.isnan(one.q[~one.valid]))
            assert _same(sols, batch.solutions((i,)))
            assert _same(np.delete(sols, j, axis=1), six.solutions((i,)))
            F = kinestat.fk(model, sols)
            assert np.abs(F - T[i]).max() < 1e-9
        assert np.min(wrapped_distance(sols, q[i])) < 1e-6


def _same(a, b):
    return len(a) == len(b) and all(np.min(wrapped_distance(b, s)) < 1e-9 for s in a)


def test_locked_plans_are_kept_per_value():
    """A joint in between: a new locked value gives its own folded chain; an end joint: one
    chain for every value (the value moves into the pose); the same value the same plan."""
    model = _arm("panda")
    a, b = plan(model, {6: 0.3}), plan(model, {6: 0.5})
    assert a.six is b.six and plan(model, {6: 0.3}) is a and a is not b
    c, d = plan(model, {2: 0.3}), plan(model, {2: 0.5})
    assert c.six is not d.six and plan(model, {2: 0.3}) is c
    assert plan(model, {np.int64(6): 0.3}) is a
    with pytest.raises(InputError, match="not a joint index"):
        plan(model, {True: 0.3})


def test_locked_plans_stay_bounded_and_keep_solving(monkeypatch):
    """Beyond the cache's size the oldest plan goes; a dropped value is planned again and
    solves as before."""
    from kinestat.serial.analytic import locked as L

    monkeypatch.setattr(L, "_PLANS_MAX", 4)
    monkeypatch.setattr(L, "_PLANS", {})
    model = _arm("iiwa")
    q = _configs(model, 2, 0.1, 1, seed=5)[0]
    T = kinestat.fk(model, q)
    first = ik_all(model, T, locked={2: 0.1}).solutions()
    for v in (0.2, 0.3, 0.4, 0.5, 0.6):
        plan(model, {2: v})
    assert len(L._PLANS) <= 4 and (model, 2, 0.1) not in L._PLANS
    again = ik_all(model, T, locked={2: 0.1}).solutions()
    assert _same(first, again) and np.min(wrapped_distance(again, q)) < 1e-6


def _solutions_of_the_fresh_fold(model, j, v, T):
    """The solutions of the chain folded at ``v`` itself (a new chain, not the cached one,
    classified and prepared from scratch), the locked value put back."""
    S6 = ik_all(fold.__wrapped__(model, ((j, v),)), T).solutions()
    return np.insert(S6, j, v, axis=1)


@pytest.mark.parametrize("name", ["panda", "iiwa"])
@pytest.mark.parametrize("j", [0, 6])
def test_end_joint_values_share_one_chain(name, j):
    """An end joint locked at any value, special ones included (0, ±π, a value next to 0):
    the shared chain with the value in the pose finds the same solutions as the chain folded
    at that value, one pose or a batch, the first call or a later (bound) one."""
    model = _arm(name)
    rng = np.random.default_rng(11 + j)
    values = [0.0, np.pi, -np.pi, 1e-13, -np.pi / 2] + list(rng.uniform(-3.0, 3.0, 6))
    for k, v in enumerate(values):
        q = _configs(model, j, v, 3, seed=100 + k)
        T = kinestat.fk(model, q)
        batch = ik_all(model, T, locked={j: float(v)})
        for i in range(len(q)):
            fresh = _solutions_of_the_fresh_fold(model, j, float(v), T[i])
            for _ in range(2):  # the full path, then the bound single call
                sols = ik_all(model, T[i], locked={j: float(v)}).solutions()
                assert _same(sols, fresh) and np.all(sols[:, j] == v)
                assert np.abs(kinestat.fk(model, sols) - T[i]).max() < 1e-9
            assert _same(batch.solutions((i,)), fresh)


@pytest.mark.parametrize("name,j,aligned", [("panda", 6, 1), ("iiwa", 2, 5), ("panda", 2, None)])
def test_single_call_equals_the_batch(name, j, aligned):
    """The bound single call (pose mapped, kernel, joints put back in one pass) returns the
    batch's solutions and family joints for each pose, a singular one included: joint
    ``aligned`` at 0 lines up the two outer axes of the spherical triple the closed form
    solves (the Panda's shoulder, solved reversed; the iiwa's wrist)."""
    model = _arm(name)
    q = _configs(model, j, 0.7, 8, seed=21)
    if aligned is not None:
        q[-1, aligned] = 0.0
    T = kinestat.fk(model, q)
    batch = ik_all(model, T, locked={j: 0.7})
    for i in range(len(q)):
        for _ in range(2):
            one = ik_all(model, T[i], locked={j: 0.7})
        assert one.q.shape == batch.q.shape[1:] and one.family_joints == batch.family_joints
        assert int(one.n_solutions) == int(batch.n_solutions[i])
        # isolated solutions equal; a family slot holds one member (any) of the same family
        iso, iso_b = one.valid & ~one.singular, batch.valid[i] & ~batch.singular[i]
        assert _same(one.q[iso], batch.q[i][iso_b])
        fam, fam_b = one.valid & one.singular, batch.valid[i] & batch.singular[i]
        assert np.allclose(np.sort(one.family_value[fam]), np.sort(batch.family_value[i][fam_b]))
        assert np.abs(kinestat.fk(model, one.solutions()) - T[i]).max() < 1e-9


@pytest.mark.parametrize("name", ["panda", "iiwa"])
@pytest.mark.parametrize("j", [1, 2, 3, 4, 5])
def test_joint_in_between_folds_as_the_fresh_fold(name, j):
    """A joint in between at a new value: the chain built from the per-joint terms has the
    fresh fold's constants and geometry class (classify's tests on the moved axes, or the
    class that holds for every value), special values included (0, ±π/2, π, next to 0), and
    the same solutions; where a general 6R remains, the elimination kept from the joint's
    previous value gives them too."""
    from kinestat.serial.analytic.solve import method_for

    model = _arm(name)
    rng = np.random.default_rng(40 + j)
    values = [0.0, np.pi / 2, -np.pi / 2, np.pi, 1e-13] + list(rng.uniform(-3.0, 3.0, 3))
    for k, v in enumerate(values):
        v = float(v)
        six, fresh = plan(model, {j: v}).six, fold.__wrapped__(model, ((j, v),))
        assert np.allclose(six.constants, fresh.constants, rtol=0.0, atol=1e-12)
        assert method_for(six) == method_for(fresh)
        q = _configs(model, j, v, 2, seed=200 + k)
        T = kinestat.fk(model, q)
        for i in range(len(q)):
            sols = ik_all(model, T[i], locked={j: v}).solutions()
            fresh_sols = _solutions_of_the_fresh_fold(model, j, v, T[i])
            # the constants differ by rounding, which a near-singular pose (the iiwa's elbow
            # at π) magnifies to ~1e-9 in the joints: equal within 1e-7
            assert len(sols) == len(fresh_sols)
            assert all(np.min(wrapped_distance(fresh_sols, s)) < 1e-7 for s in sols)
            if len(sols):
                assert np.abs(kinestat.fk(model, sols) - T[i]).max() < 1e-9


@pytest.mark.parametrize("j", [0, 6])
def test_end_joint_bad_poses_are_named(j):
    """The value moved into the pose keeps a pose's fault: the error names the pose, one pose
    or a batch, an array or a list."""
    model = _arm("panda")
    T = kinestat.fk(model, _configs(model, j, 0.5, 3, seed=9))
    for where, bad, match in [((1, 0, 0), np.nan, "NaN"), ((1, 0, 0), 2.0, r"pose \(1,\)"),
                              ((2, 3, 1), 0.1, r"pose \(2,\)")]:
        B = T.copy()
        B[where] = bad
        with pytest.raises(InputError, match=match):
            ik_all(model, B, locked={j: 0.5})
        with pytest.raises(InputError, match="NaN" if match == "NaN" else "not a rigid"):
            ik_all(model, B[where[0]], locked={j: 0.5})
    with pytest.raises(InputError, match="shape"):
        ik_all(model, [[1.0, 2.0]], locked={j: 0.5})
