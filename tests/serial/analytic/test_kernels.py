"""The allocation-free compiled kernels of ik_all against the NumPy references and against
themselves (parallel chunks vs one pose per call), and their shared scalar steps."""

from __future__ import annotations

import math

import numpy as np
import pytest

import kinestat
from kinestat.serial.analytic import ik_all
from kinestat.serial.analytic._solution_kernels import angle_distance, polish, scratch, wrap

from .arms import PI, arm, slot_residuals, wrapped_distance


def _configs(name, n, seed):
    q = np.random.default_rng(seed).uniform(-PI, PI, (n, 6))
    if name in ("puma560", "puma762", "kr16"):
        q[:10, 4] = 0.0  # wrist-singular: axes 4 and 6 aligned (families)
    return q


@pytest.mark.parametrize("name", ["ur5", "puma560", "puma762", "jaco6", "random2", "random3"])
def test_kernels_equal_numpy_references_both_ways(name):
    model = arm(name)
    q = _configs(name, 120, seed=5)
    T = kinestat.fk(model, q)
    a = ik_all(model, T)
    b = ik_all(model, T, backend="numpy")
    assert a.method == b.method
    np.testing.assert_array_equal(a.n_solutions, b.n_solutions)
    np.testing.assert_array_equal(a.singular.sum(-1), b.singular.sum(-1))
    for i in range(q.shape[0]):
        sa, sb = a.solutions((i,)), b.solutions((i,))
        for s in sb:
            assert np.min(wrapped_distance(sa, s)) < 1e-6, (name, i)
        for s in sa:
            assert np.min(wrapped_distance(sb, s)) < 1e-6, (name, i)
        fa = np.sort(a.family_value[i][a.singular[i]])
        fb = np.sort(b.family_value[i][b.singular[i]])
        np.testing.assert_allclose(fa, fb, atol=1e-6)
    # every slot the kernels fill reproduces its pose (independent FK here)
    pos, dR = slot_residuals(model, a, T)
    assert pos.max() <= 1e-9 and dR.max() <= 1e-9


@pytest.mark.parametrize("name", ["ur5", "puma560", "kr16", "random1"])
def test_parallel_batch_equals_one_pose_per_call(name):
    """The prange path (chunks, per-chunk scratch) computes what single calls do: the same
    slots and, to a few ulp, the same angles (the closed forms' batches take them by one
    vectorised arctan2 of the cosines and sines a single call passes to libm's atan2)."""
    model = arm(name)
    n = 300 if name != "random1" else 70  # not a multiple of the chunk size
    q = _configs(name, n, seed=9)
    T = kinestat.fk(model, q)
    batch = ik_all(model, T)
    for i in range(0, n, 7):
        one = ik_all(model, T[i])
        np.testing.assert_array_equal(np.isnan(one.q), np.isnan(batch.q[i]))
        d = np.abs(np.mod(one.q - batch.q[i] + PI, 2 * PI) - PI)
        assert np.nanmax(d) <= 4 * np.spacing(PI), (name, i, np.nanmax(d))
        np.testing.assert_array_equal(one.valid, batch.valid[i])
        np.testing.assert_array_equal(one.singular, batch.singular[i])
        f = np.abs(np.mod(one.family_value - batch.family_value[i] + PI, 2 * PI) - PI)
        assert np.all(f[one.singular] <= 1e-12), (name, i)


def test_wrap_and_angle_distance():
    x = np.array([-7.0, -PI, -3.0, 0.0, 3.0, PI, 7.0, 40.0, -123.4])
    ref = np.mod(x + PI, 2 * PI) - PI
    got = np.array([wrap(v) for v in x])
    np.testing.assert_allclose(np.mod(got - ref + PI, 2 * PI) - PI, 0.0, atol=1e-12)
    assert np.all((got >= -PI) & (got <= PI))
    a, b = 3.0, -3.0
    assert math.isclose(angle_distance(a, b), 2 * PI - 6.0, rel_tol=1e-12)
    assert angle_distance(0.5, 0.25) == 0.25


def test_polish_converges_from_a_perturbed_solution():
    model = arm("random2")
    C = np.ascontiguousarray(model.constants)
    q0 = np.array([0.3, -1.1, 0.8, 2.0, -0.4, 1.3])
    T = kinestat.fk(model, q0)
    q = q0 + np.array([2e-3, -1e-3, 3e-3, 1e-3, -2e-3, 1e-3])
    pos, rot = polish(C, T, q, 8, *scratch())
    assert pos < 1e-12 and rot < 1e-12
    np.testing.assert_allclose(q, q0, atol=1e-9)


@pytest.mark.parametrize("name", ["ur5", "puma560", "puma762"])
def test_closed_form_kernels_report_the_fk_residuals_of_their_angles(name):
    """The closed-form kernels verify each solution by the chain product at the cosine and sine
    they carry with each angle (no cos/sin calls): the residuals they report must be those of
    kinestat.fk at the stored angles, to rounding of the pose's size."""
    model = arm(name)
    q = _configs(name, 300, seed=21)
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    v = res.valid
    assert v.sum() > 2000
    pos, dR = slot_residuals(model, res, T)
    rot = 2.0 * np.arcsin(np.minimum(dR / math.sqrt(8.0), 1.0))
    size = np.abs(T[:, :3, 3]).max()
    assert np.max(np.abs(res.position_error[v] - pos[v])) < 1e-14 * size
    assert np.max(np.abs(res.rotation_error[v] - rot[v])) < 1e-14
