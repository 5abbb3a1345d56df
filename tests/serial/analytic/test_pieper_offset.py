"""Spherical-wrist arms with an offset shoulder (KUKA, ABB, random Pieper arms) and arms whose
first three axes meet (solved reversed): every solution reproduces its pose, the generating
configuration is found, and the count equals EAIK's and a many-start Newton oracle's."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.serial.analytic import ik_all, method_for
from kinestat.serial.analytic._offset_kernels import quartic_real_roots
from kinestat.serial.analytic.geometry import home_axes

from .arms import (
    INDUSTRIAL,
    PI,
    industrial,
    newton_solutions,
    random_pieper,
    random_shoulder,
    slot_residuals,
    wrapped_distance,
)

RANDOM = [("", 0), ("", 1), ("", 2), ("12", 3), ("23", 4), ("23", 5), ("123", 6), ("123", 7)]


def _arm(key):
    if isinstance(key, str):
        return industrial(key)
    return random_shoulder(key[1]) if key[0] == "123" else random_pieper(key[1], key[0])


KEYS = sorted(INDUSTRIAL) + RANDOM


def _ids(key):
    return key if isinstance(key, str) else f"random{key[0]}-{key[1]}"


@pytest.mark.parametrize("key", KEYS, ids=_ids)
@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_every_solution_reproduces_its_pose(key, backend):
    model = _arm(key)
    assert method_for(model) == "pieper"
    q = np.random.default_rng(len(_ids(key))).uniform(-PI, PI, (300 if backend == "numba"
                                                               else 40, 6))
    T = kinestat.fk(model, q)
    res = ik_all(model, T, backend=backend)
    assert res.method == "pieper"
    d = wrapped_distance(res.q, q[:, None, :])
    found = np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1)
    assert found.all(), f"generating configuration missed in {np.sum(~found)} poses"
    pos, dR = slot_residuals(model, res, T)
    assert pos.max() <= 1e-9 and dR.max() <= 1e-9
    assert np.all(res.n_solutions == res.valid.sum(-1))


@pytest.mark.parametrize("key", [RANDOM[0], RANDOM[3], "kr16"], ids=_ids)
def test_backends_agree(key):
    model = _arm(key)
    q = np.random.default_rng(3).uniform(-PI, PI, (30, 6))
    T = kinestat.fk(model, q)
    a, b = ik_all(model, T), ik_all(model, T, backend="numpy")
    assert np.array_equal(a.n_solutions, b.n_solutions)
    for i in range(len(q)):
        sa, sb = a.solutions((i,)), b.solutions((i,))
        for s in sb:
            assert np.min(wrapped_distance(sa, s)) < 1e-7


def _eaik(model):
    """EAIK's solver on the model's home axes (H, P form), and a call returning its solutions
    (flagged least-squares or not: its general spherical-wrist family flags every one; they
    are verified by FK here)."""
    HPRobot = pytest.importorskip("eaik.IK_HP", reason="eaik is not installed "
                                  "(pip install -r requirements/bench.txt)").HPRobot
    ax = home_axes(model)
    pts = np.vstack([ax.r, ax.T0[:3, 3]])
    bot = HPRobot(ax.w.copy(), np.vstack([pts[0], np.diff(pts, axis=0)]))
    assert bot.hasKnownDecomposition()
    R0 = ax.T0[:3, :3]

    def call(T):
        Tp = T.copy()
        Tp[:3, :3] = T[:3, :3] @ R0.T  # EAIK's end frame is the base frame's axes at q = 0
        return [np.asarray(q) for q in bot.IK(Tp).Q]
    return call


def _distinct_verified(model, T, sols, tol=1e-6):
    out: list[np.ndarray] = []
    for s in sols:
        F = kinestat.fk(model, s)
        if np.linalg.norm(F[:3, 3] - T[:3, 3]) > tol or np.linalg.norm(F[:3, :3] - T[:3, :3]) > tol:
            continue
        if all(wrapped_distance(s, d) > 1e-6 for d in out):
            out.append(s)
    return out


@pytest.mark.parametrize("key", KEYS, ids=_ids)
def test_count_equals_eaik(key):
    model = _arm(key)
    call = _eaik(model)
    q = np.random.default_rng(11).uniform(-PI, PI, (60, 6))
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    for i in range(len(q)):
        theirs = _distinct_verified(model, T[i], call(T[i]))
        mine = res.solutions((i,))
        assert len(mine) == len(theirs), f"pose {i}: {len(mine)} against EAIK's {len(theirs)}"
        for s in theirs:
            assert np.min(wrapped_distance(mine, s)) < 1e-6


@pytest.mark.parametrize("key", [RANDOM[0], RANDOM[1], RANDOM[3], RANDOM[4], RANDOM[6]],
                         ids=_ids)
def test_count_matches_many_start_newton(key):
    model = _arm(key)
    q = np.random.default_rng(5).uniform(-PI, PI, (3, 6))
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    for i, sols in enumerate(newton_solutions(model, T, starts=300)):
        assert res.n_solutions[i] == len(sols)


def test_quartic_roots_against_numpy():
    rng = np.random.default_rng(0)
    for _ in range(500):
        roots = rng.uniform(-3, 3, 4)
        if rng.random() < 0.5:  # a complex pair
            roots = np.array([roots[0], roots[1], complex(roots[2], 0.5 + rng.random()),
                              complex(roots[2], -0.5 - rng.random())])
        c = np.real(np.poly(roots)) * rng.uniform(0.1, 10)
        k, got = quartic_real_roots(*c)
        want = np.sort(np.real(roots[np.abs(np.imag(roots)) == 0]))
        assert k == len(want)
        assert np.allclose(np.sort(got[:k]), want, atol=1e-8)


def _same_solutions(a: np.ndarray, b: np.ndarray) -> bool:
    """The two sets of solutions ``(m, 6)`` are equal up to order (wrapped, 1e-9)."""
    return len(a) == len(b) and all(np.min(wrapped_distance(b, s)) < 1e-9 for s in a)


@pytest.mark.parametrize("key", [RANDOM[6], RANDOM[7]], ids=_ids)
def test_reversed_single_calls_equal_the_batch(key):
    """A spherical shoulder solved reversed: one pose per call (the bound single call after
    the first) gives the batch's solutions, family joints and method for every pose."""
    model = _arm(key)
    q = np.random.default_rng(7).uniform(-PI, PI, (40, 6))
    T = kinestat.fk(model, q)
    batch = ik_all(model, T)
    for i in range(len(q)):
        one = ik_all(model, T[i])
        assert one.q.shape == (8, 6) and one.method == batch.method
        assert _same_solutions(one.solutions(), batch.solutions((i,)))
        assert one.family_joints == batch.family_joints
        assert int(one.n_solutions) == int(batch.n_solutions[i])
        assert np.min(wrapped_distance(one.solutions(), q[i])) < 1e-6
    pos, dR = slot_residuals(model, one, T[-1])
    assert pos.max() <= 1e-9 and dR.max() <= 1e-9
