"""The thesis's PUMA 762 closed form as an instance of IKAllResult: it agrees with the generic
spherical-wrist solver (same solution set, same families) and with the thesis API."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.errors import ModelError
from kinestat.mechanism.chain import from_modified_dh
from kinestat.robots.puma762 import closed_form as P
from kinestat.robots.puma762.analytic import (
    ik_all_thesis,
    is_puma762,
    puma762_chain,
)
from kinestat.serial.analytic import ik_all
from tests.serial.analytic.arms import PI, slot_residuals, wrapped_distance


def _same_sets(a, b, i):
    sa, sb = a.solutions((i,)), b.solutions((i,))
    assert sa.shape == sb.shape, (i, sa, sb)
    for s in sa:
        assert np.min(wrapped_distance(sb, s)) < 1e-6, (i, s)


def _configs(n, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-PI, PI, (n, 6))
    q[: n // 10, 4] = 0.0  # wrist singular: θ5 = 0 ...
    q[n // 10: n // 5, 4] = -PI  # ... and θ5 = 180°
    return q


def test_chain_is_the_loaded_model():
    m = kinestat.load("puma762")
    c = puma762_chain()
    assert is_puma762(m) and is_puma762(c)
    q = np.random.default_rng(0).uniform(-PI, PI, (50, 6))
    np.testing.assert_allclose(kinestat.fk(c, q), kinestat.fk(m, q), atol=1e-9)
    np.testing.assert_allclose(kinestat.fk(c, q), P.forward(q).pose, atol=1e-9)
    for k in (0, 1, 5):  # a wrap-equivalent range for joint 1, the same for the others
        np.testing.assert_allclose(np.mod(c.lower[k] - m.lower[k], 2 * PI) % (2 * PI), 0,
                                   atol=1e-12)
        np.testing.assert_allclose(c.upper[k] - c.lower[k], m.upper[k] - m.lower[k], atol=1e-12)
    assert not is_puma762(kinestat.load("puma560"))
    rows = c.parameters * [1.0, 0.001, 1.0, 0.001]  # the same arm in metres: not the thesis's
    assert not is_puma762(from_modified_dh(rows, length_unit="m"))


def test_thesis_closed_form_agrees_with_generic_solver():
    m = kinestat.load("puma762")
    q = _configs(1000, seed=762)
    T = kinestat.fk(m, q)
    a = ik_all(m, T)  # the generic spherical-wrist solver (method "pieper")
    b = ik_all(m, T, method="puma762")
    assert a.method == "pieper" and b.method == "puma762"
    assert b.q.shape == (1000, 8, 6) and b.valid.shape == (1000, 8)
    np.testing.assert_array_equal(a.n_solutions, b.n_solutions)
    for i in range(q.shape[0]):
        _same_sets(a, b, i)
    # the generating configuration is among the thesis's solutions (or its family)
    d = wrapped_distance(b.q, q[:, None, :])
    fam = q[:, None, 3] + b.family_sign * q[:, None, 5]
    on_family = b.singular & (np.abs(np.mod(fam - b.family_value + PI, 2 * PI) - PI) < 1e-9)
    assert np.all(np.any(np.where(b.valid, d, np.inf) < 1e-6, axis=1) | on_family.any(1))
    # every valid slot reproduces the pose under the generic FK
    assert np.max(np.hypot(*slot_residuals(m, b, T))) < 1e-9
    # the wrist-singular families: same count, same relation θ4 + σ θ6 = value
    np.testing.assert_array_equal(a.singular.sum(-1), b.singular.sum(-1))
    assert b.family_joints == a.family_joints == (3, 5)
    assert b.singular[: 200].any(axis=1).all() and not b.singular[200:].any()
    for i in np.flatnonzero(b.singular.any(1)):
        for k in np.flatnonzero(b.singular[i]):
            sig, val = b.family_sign[i, k], b.family_value[i, k]
            for t in (-1.3, 0.4, 2.9):  # members reproduce the pose
                qm = b.q[i, k].copy()
                qm[3] += t
                qm[5] -= sig * t
                np.testing.assert_allclose(kinestat.fk(m, qm), T[i], atol=1e-8)
            match = a.singular[i] & (a.family_sign[i] == sig) & (
                np.abs(np.mod(a.family_value[i] - val + PI, 2 * PI) - PI) < 1e-9)
            assert match.any()


def test_thesis_inputs_adapter_and_existing_api():
    q = _configs(40, seed=3)
    f = P.forward(q)
    res = ik_all_thesis(f.tool_point, f.s6, f.a67)
    old = P.reverse_batch(f.tool_point, f.s6, f.a67)
    # the thesis API and the adapter: the same set of solutions
    for i in range(q.shape[0]):
        ref = old.q[i][old.valid[i] & ~old.singular[i]]
        got = res.solutions((i,))
        for s in ref:
            assert np.min(wrapped_distance(got, s)) < 1e-6
        # a thesis family member satisfies the adapter's family relation on joints 4 and 6
        for k in np.flatnonzero(old.valid[i] & old.singular[i]):
            s = old.q[i, k]
            rel = s[3] + res.family_sign[i] * s[5] - res.family_value[i]
            same = res.singular[i] & (np.abs(np.mod(rel + PI, 2 * PI) - PI) < 1e-9) & (
                wrapped_distance(res.q[i][:, [0, 1, 2, 4]], s[[0, 1, 2, 4]]) < 1e-6)
            assert same.any()
        assert got.shape[0] <= int(old.valid[i].sum())  # duplicates merged, never invented
    # a tool point off the flange (tool_point_6): the same pose of frame 6
    p6 = np.array([10.0, -20.0, 80.0])
    f2 = P.forward(q, tool_point_6=p6)
    res2 = ik_all_thesis(f2.tool_point, f2.s6, f2.a67, p6)
    np.testing.assert_array_equal(res2.n_solutions, res.n_solutions)
    for i in range(q.shape[0]):
        np.testing.assert_allclose(res2.solutions((i,)), res.solutions((i,)), atol=1e-9)


def test_unreachable_reason_and_wrong_model():
    m = kinestat.load("puma762")
    T = np.eye(4)
    T[:3, 3] = [5000.0, 0.0, 0.0]
    res = ik_all(m, T, method="puma762")
    assert int(res.n_solutions) == 0 and "θ3 has no real solution" in res.reason[()]
    T[:3, 3] = [0.0, 0.0, 300.0]  # on the first axis: inside the S2 cylinder
    res = ik_all(m, T, method="puma762")
    assert int(res.n_solutions) == 0 and "φ1 has no real solution" in res.reason[()]
    with pytest.raises(ModelError, match="PUMA 762"):
        ik_all(kinestat.load("puma560"), np.eye(4), method="puma762")


def test_numpy_backend_matches():
    m = kinestat.load("puma762")
    q = _configs(60, seed=9)
    T = kinestat.fk(m, q)
    a = ik_all(m, T, method="puma762")
    b = ik_all(m, T, method="puma762", backend="numpy")
    np.testing.assert_array_equal(a.n_solutions, b.n_solutions)
    for i in range(q.shape[0]):
        _same_sets(a, b, i)
