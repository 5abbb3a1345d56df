"""The compiled decoupled solver against the NumPy reference (counts, solution sets, reasons,
families), against forward kinematics, and against its own source run interpreted
(``NUMBA_DISABLE_JIT``)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import kinestat
from kinestat.serial.analytic import decoupled, ik_all
from kinestat.serial.analytic.decoupled_compiled import solve_decoupled_compiled

from .arms import wrapped_distance
from .test_decoupled import ARMS, arm, configs

_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(__file__))))


def _same_sets(model, a, b, i):
    sa, sb = a.solutions((i,)), b.solutions((i,))
    if len(sa) != len(sb):
        return False
    rot = ~model.prismatic
    return all(np.min(wrapped_distance(sb, s, rot)) < 1e-6 for s in sa)


@pytest.mark.parametrize("name", ARMS)
def test_compiled_equals_the_numpy_reference(name):
    model = arm(name)
    q = configs(model, 120, 5)
    T = np.ascontiguousarray(kinestat.fk(model, q))
    ref = decoupled.solve_decoupled(model, T)
    for res in (solve_decoupled_compiled(model, T), solve_decoupled_compiled(model, T[:40])):
        n = res.n_solutions.shape[0]
        np.testing.assert_array_equal(res.n_solutions, ref.n_solutions[:n])
        np.testing.assert_array_equal(res.reason, ref.reason[:n])
        assert all(_same_sets(model, res, ref, i) for i in range(n))
        # every solution reproduces its pose; the generating configuration is among them
        sols = res.q[res.valid]
        F = kinestat.fk(model, sols)
        Tr = np.broadcast_to(T[:n, None], res.valid.shape + (4, 4))[res.valid]
        assert np.abs(F - Tr).max() < 1e-8
        d = wrapped_distance(res.q, q[:n, None, :], ~model.prismatic)
        assert np.all(np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1))
        assert np.array_equal(res.singular.sum(), ref.singular[:n].sum())


def test_ik_all_single_and_batched_calls_use_it():
    model = arm("stanford")
    q = configs(model, 5, 6)
    T = np.ascontiguousarray(kinestat.fk(model, q))
    batch = ik_all(model, T)
    for i in range(5):
        one = ik_all(model, T[i])
        again = ik_all(model, T[i])  # the bound single call
        assert one.shape == () and again.method == "decoupled"
        assert int(one.n_solutions) == int(again.n_solutions) == batch.n_solutions[i]
    ref = ik_all(model, T, backend="numpy")
    np.testing.assert_array_equal(batch.n_solutions, ref.n_solutions)


_SCRIPT = """
import json, sys
import numpy as np
sys.path[:0] = [{root!r}, {root!r} + "/tests/serial"]
import kinestat
from analytic.test_decoupled import arm, configs
from kinestat.serial.analytic.decoupled_compiled import solve_decoupled_compiled
out = {{}}
for name in {names!r}:
    m = arm(name)
    T = np.ascontiguousarray(kinestat.fk(m, configs(m, 4, 7)))
    r = solve_decoupled_compiled(m, T)
    out[name] = [np.where(r.valid[..., None], r.q, 0.0).tolist(), r.valid.tolist()]
print(json.dumps(out))
"""


def test_interpreted_source_gives_the_same_slots():
    names = ["stanford", "random-RPR-1", "random-PPP-2", "track"]
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=_ROOT)
    run = subprocess.run([sys.executable, "-c", _SCRIPT.format(root=_ROOT, names=names)],
                         capture_output=True, text=True, env=env, timeout=600, check=True)
    interpreted = json.loads(run.stdout.strip().splitlines()[-1])
    for name in names:
        m = arm(name)
        T = np.ascontiguousarray(kinestat.fk(m, configs(m, 4, 7)))
        r = solve_decoupled_compiled(m, T)
        q, valid = (np.array(x) for x in interpreted[name])
        np.testing.assert_array_equal(valid, r.valid)
        np.testing.assert_allclose(q, np.where(r.valid[..., None], r.q, 0.0), atol=1e-12)
