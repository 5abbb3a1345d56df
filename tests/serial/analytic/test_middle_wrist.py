"""6R arms whose axes 2, 3, 4 (or 3, 4, 5) meet: the closed form against the Raghavan–Roth
eigenvalue method, forward kinematics, many-start Newton and its own source run interpreted."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import kinestat
from kinestat.serial.analytic import ik_all, method_for
from kinestat.serial.analytic.middle_wrist import middle_point

from .arms import PI, middle_arm, newton_solutions, slot_residuals, wrapped_distance

_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(__file__))))


@pytest.mark.parametrize("first,seed", [(2, 1), (2, 2), (2, 3), (3, 1), (3, 4)])
def test_closed_form_equals_raghavan_roth_and_reproduces_poses(first, seed):
    model = middle_arm(seed, first)
    assert method_for(model) == "middle-wrist"
    assert (middle_point(model) is not None) == (first == 2)
    q = np.random.default_rng(seed).uniform(-PI, PI, (150, 6))
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    assert res.method == "middle-wrist"
    d = wrapped_distance(res.q, q[:, None, :])
    assert np.all(np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1))
    pos, rot = slot_residuals(model, res, T)
    assert pos.max() <= 1e-9 and rot.max() <= 1e-9
    rr = ik_all(model, T[:50], method="raghavan-roth")
    np.testing.assert_array_equal(res.n_solutions[:50], rr.n_solutions)
    for i in range(50):
        mine = res.solutions((i,))
        for s in rr.solutions((i,)):
            assert np.min(wrapped_distance(mine, s)) < 1e-6
    one = ik_all(model, T[0])
    assert one.shape == () and int(one.n_solutions) == res.n_solutions[0]


def test_counts_match_many_start_newton():
    model = middle_arm(5)
    q = np.random.default_rng(9).uniform(-PI, PI, (15, 6))
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    oracle = newton_solutions(model, T, starts=300, iters=50, seed=3)
    for i, sols in enumerate(oracle):
        assert len(sols) == res.n_solutions[i]
        for s in sols:
            assert np.min(wrapped_distance(res.solutions((i,)), s)) < 1e-6


def test_unreachable_pose_has_no_solution_and_a_reason():
    model = middle_arm(2)
    T = np.eye(4)
    T[:3, 3] = [50.0, 0.0, 0.0]
    res = ik_all(model, T)
    assert int(res.n_solutions) == 0 and "out of reach" in str(res.reason)


_SCRIPT = """
import json, sys
import numpy as np
sys.path[:0] = [{root!r}, {root!r} + "/tests/serial"]
import kinestat
from analytic.arms import middle_arm
from kinestat.serial.analytic.middle_wrist import solve_middle
m = middle_arm(3)
T = np.ascontiguousarray(kinestat.fk(m, np.random.default_rng(1).uniform(-3, 3, (4, 6))))
r = solve_middle(m, T)
print(json.dumps([np.where(r.valid[..., None], r.q, 0.0).tolist(), r.valid.tolist()]))
"""


def test_interpreted_source_gives_the_same_slots():
    from kinestat.serial.analytic.middle_wrist import solve_middle

    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=_ROOT)
    run = subprocess.run([sys.executable, "-c", _SCRIPT.format(root=_ROOT)], capture_output=True,
                         text=True, env=env, timeout=600, check=True)
    q, valid = (np.array(x) for x in json.loads(run.stdout.strip().splitlines()[-1]))
    m = middle_arm(3)
    T = np.ascontiguousarray(kinestat.fk(m, np.random.default_rng(1).uniform(-3, 3, (4, 6))))
    r = solve_middle(m, T)
    np.testing.assert_array_equal(valid, r.valid)
    np.testing.assert_allclose(q, np.where(r.valid[..., None], r.q, 0.0), atol=1e-12)
