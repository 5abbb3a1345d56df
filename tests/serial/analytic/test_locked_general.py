"""7-joint arms with a joint in between locked where a general 6R remains (Panda and xArm7,
joint 3): a new value takes the kernel's arrays from per-joint terms, without a new chain.
Checked against the chain folded at that value and prepared from scratch (classified, its
formulation searched, its arrays built): the same arrays, the same solutions, the same
completeness of the formulation; the special values found from the axes are those where an
axis pair across the joint meets, lines up or coincides."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.serial.analytic import general6r, ik_all, ik_self_motion
from kinestat.serial.analytic.geometry import home_axes, meet, parallel
from kinestat.serial.analytic.locked import _joint_info, fold, plan
from tests.urdf_arms import ARMS, arm_path

from .arms import wrapped_distance

J = 2  # joint 3 (0-based 2): a general 6R remains on both arms


def _arm(name):
    return kinestat.load(arm_path(name), tip=ARMS[name][1])


def _adopted(model):
    """The joint's GeneralLock, which a second value takes from the first (solved by the
    full path)."""
    q = np.random.default_rng(1).uniform(-1.0, 1.0, model.n)
    for v in (0.77, 0.78):
        q[J] = v
        ik_all(model, kinestat.fk(model, q), locked={J: v})
    gl = _joint_info(model, J).general
    assert gl is not None and gl.form
    return gl


def _fresh(model, v):
    return fold.__wrapped__(model, ((J, v),))


def _fresh_solutions(model, v, T):
    return np.insert(ik_all(_fresh(model, v), T).solutions(), J, v, axis=1)


@pytest.mark.parametrize("name", ["panda", "xarm7"])
def test_new_values_solve_as_the_fresh_fold(name):
    """Random (pose, value) pairs: the plan has no chain of its own (the fast path), and its
    solutions are the freshly folded chain's, each reproducing the pose by the 7-joint FK,
    the generating configuration among them."""
    model = _arm(name)
    gl = _adopted(model)
    rng = np.random.default_rng(50)
    q = rng.uniform(-np.pi, np.pi, (40, 7))
    q[:, J] = rng.uniform(-np.pi, np.pi, 40)
    T = kinestat.fk(model, q)
    for i in range(len(q)):
        v = float(q[i, J])
        assert not gl.special(v)
        sols = ik_all(model, T[i], locked={J: v}).solutions()
        assert plan(model, {J: v})._six is None
        fresh = _fresh_solutions(model, v, T[i])
        assert len(sols) == len(fresh)
        assert all(np.min(wrapped_distance(fresh, s)) < 1e-7 for s in sols)
        assert np.all(sols[:, J] == v)
        assert np.abs(kinestat.fk(model, sols) - T[i]).max() < 1e-9
        assert np.min(wrapped_distance(sols, q[i])) < 1e-6
    # the chain on demand: the fresh fold's, as the batch path takes it
    v = float(q[0, J])
    assert np.allclose(plan(model, {J: v}).six.constants, _fresh(model, v).constants,
                       rtol=0.0, atol=1e-12)
    batch = ik_all(model, T[:5], locked={J: v})
    assert np.all(batch.n_solutions[0] == len(_fresh_solutions(model, v, T[0])))


@pytest.mark.parametrize("name", ["panda", "xarm7"])
def test_arrays_equal_the_fresh_folds(name):
    """The kernel's arrays at a value from the per-joint terms equal those built from the
    chain folded at that value (L of RR eq. 4 by the invariants' products)."""
    model = _arm(name)
    gl = _adopted(model)
    for v in np.random.default_rng(51).uniform(-np.pi, np.pi, 12):
        got = gl.arrays(float(v))
        want = general6r._compiled_data(_fresh(model, float(v)), gl.form)
        for a, b in zip(got[:9], want[:9], strict=True):
            assert np.asarray(a).shape == np.asarray(b).shape
            assert np.allclose(a, b, rtol=0.0, atol=1e-12 * max(1.0, np.abs(b).max()))


def _relations(ax, j, tol):
    """The relations of the axis pairs across joint j by the geometry tests: parallel (with
    or without coinciding) or meeting."""
    out = set()
    for a in range(j):
        for b in range(j, 6):
            if parallel(ax, a, b, tol):
                gap = np.linalg.norm(np.cross(ax.r[b] - ax.r[a], ax.w[a]))
                out.add((a, b, "coincide" if gap <= tol * ax.scale else "parallel"))
            elif meet(ax, a, b, tol) is not None:
                out.add((a, b, "meet"))
    return out


@pytest.mark.parametrize("name", ["panda", "xarm7"])
def test_special_values_are_where_axes_meet_or_line_up(name):
    """A value is special exactly where the axis pairs across the joint relate otherwise
    than at random values (by the geometry tests on the freshly folded chain's axes); a
    special value takes the full path and solves as the fresh fold."""
    model = _arm(name)
    gl = _adopted(model)
    rng = np.random.default_rng(52)
    generic = _relations(home_axes(_fresh(model, 0.77)), J, 1e-9)
    for v in rng.uniform(-np.pi, np.pi, 5):
        assert _relations(home_axes(_fresh(model, float(v))), J, 1e-9) == generic
    values = [0.0, np.pi / 2, -np.pi / 2, np.pi, 1e-9, 1e-3] + list(rng.uniform(-3, 3, 6))
    seen = 0
    for k, v in enumerate(values):
        v = float(v)
        near = _relations(home_axes(_fresh(model, v)), J, 1e-8)  # 10 times classify's
        assert gl.special(v) == (near != generic)
        seen += gl.special(v)
        q = np.random.default_rng(60 + k).uniform(-2.0, 2.0, 7)
        q[J] = v
        T = kinestat.fk(model, q)
        sols = ik_all(model, T, locked={J: v}).solutions()
        assert (plan(model, {J: v})._six is None) == (not gl.special(v))
        fresh = _fresh_solutions(model, v, T)
        assert len(sols) == len(fresh)
        assert all(np.min(wrapped_distance(fresh, s)) < 1e-7 for s in sols)
    assert seen >= (5 if name == "panda" else 1)  # the Panda: 0, ±π/2, π, 1e-9; xArm7: π


@pytest.mark.parametrize("name", ["panda", "xarm7"])
def test_the_formulation_found_once_is_as_complete_as_a_search(name):
    """At random values the formulation found at the first value finds as many of 24 random
    configurations as the full search finds at that value (every one)."""
    model = _arm(name)
    gl = _adopted(model)
    for v in np.random.default_rng(53).uniform(-np.pi, np.pi, 8):
        six = _fresh(model, float(v))
        assert general6r._raw_completeness(six, gl.form, 24) == general6r.search(six)[1] == 1.0


def test_self_motion_samples_solve_as_the_fresh_folds():
    """A self-motion of one pose (its values on the fast path but the special ones): every
    sample's solutions are the fresh fold's at that value."""
    model = _arm("panda")
    _adopted(model)
    q = np.random.default_rng(54).uniform(-1.5, 1.5, 7)
    T = kinestat.fk(model, q)
    sm = ik_self_motion(model, T, J, 9)
    for v, res in zip(sm.values, sm.results, strict=True):
        fresh = _fresh_solutions(model, float(v), T)
        sols = res.solutions()
        assert len(sols) == len(fresh) and np.all(sols[:, J] == v)
        assert all(np.min(wrapped_distance(fresh, s)) < 1e-7 for s in sols)


def test_a_formulation_missing_a_few_poses_is_not_kept():
    """The xArm7 with joint 6 locked: the reversed formulation misses a few per cent of the
    poses at every value, yet passes the search's 24 configurations at some; the kept one
    finds every one of 64 at random values, and each value's solutions include the freshly
    folded chain's (the fresh search may keep the weaker one) and reproduce the pose."""
    model = _arm("xarm7")
    j = 5
    rng = np.random.default_rng(55)
    q = rng.uniform(-np.pi, np.pi, (25, 7))
    q[:, j] = rng.uniform(-np.pi, np.pi, 25)
    T = kinestat.fk(model, q)
    for i in range(2):
        ik_all(model, T[i], locked={j: float(q[i, j])})
    gl = _joint_info(model, j).general
    assert gl is not None and gl.form
    for i in range(2, len(q)):
        v = float(q[i, j])
        sols = ik_all(model, T[i], locked={j: v}).solutions()
        fresh = np.insert(ik_all(fold.__wrapped__(model, ((j, v),)), T[i]).solutions(), j, v,
                          axis=1)
        assert all(np.min(wrapped_distance(sols, s)) < 1e-7 for s in fresh)
        assert np.abs(kinestat.fk(model, sols) - T[i]).max() < 1e-9
        assert np.min(wrapped_distance(sols, q[i])) < 1e-6
    for v in rng.uniform(-np.pi, np.pi, 4):
        assert general6r._raw_completeness(fold.__wrapped__(model, ((j, float(v)),)), gl.form,
                                           64) == 1.0


def test_a_new_value_runs_without_a_plan_then_with_its_basis():
    """A value not seen before is solved without a plan (only its value recorded); called
    again, its plan is built and takes the value's basis of the spurious subspace: the same
    solutions each time. Threads solving new values at once (each its own buffers) give
    each pose the solutions of the freshly folded chain."""
    from concurrent.futures import ThreadPoolExecutor

    from kinestat.serial.analytic import locked

    model = _arm("panda")
    _adopted(model)
    rng = np.random.default_rng(51)
    q = rng.uniform(-np.pi, np.pi, (24, 7))
    q[:, J] = rng.uniform(-np.pi, np.pi, 24)
    T = kinestat.fk(model, q)
    v = float(q[0, J])
    first = ik_all(model, T[0], locked={J: v}).solutions()
    assert locked._PLANS[model, J, v] is locked._SEEN
    second = ik_all(model, T[0], locked={J: v}).solutions()
    lp = locked._PLANS[model, J, v]
    assert isinstance(lp, locked.LockedPlan) and lp._six is None
    third = ik_all(model, T[0], locked={J: v}).solutions()
    fresh = _fresh_solutions(model, v, T[0])
    for sols in (first, second, third):
        assert len(sols) == len(fresh)
        assert all(np.min(wrapped_distance(fresh, s)) < 1e-7 for s in sols)

    def solve(i):
        return ik_all(model, T[i], locked={J: float(q[i, J])}).solutions()
    with ThreadPoolExecutor(4) as pool:
        got = list(pool.map(solve, range(1, 24)))
    for i, sols in enumerate(got, start=1):
        fresh = _fresh_solutions(model, float(q[i, J]), T[i])
        assert len(sols) == len(fresh)
        assert all(np.min(wrapped_distance(fresh, s)) < 1e-7 for s in sols)
