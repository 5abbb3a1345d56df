"""The general-6R kernel's QZ recheck: the QZ eigenvalues against SciPy's, the suspect-pose
trigger against rechecking every pose, and completeness on near-fold Jaco2 poses (where the
standard companion loses clustered roots) against the generating configuration and an
independent many-start Newton count."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import kinestat
from kinestat.serial.analytic import general6r as g
from kinestat.serial.analytic._rr_qz import pencil_eigvals_qz, qz_scratch

from .arms import PI, arm, newton_solutions, slot_residuals, wrapped_distance


def _companion_pencil(A):
    I, Z = np.eye(12), np.zeros((12, 12))
    return np.block([[Z, I], [-A[0], -A[1]]]), np.block([[I, Z], [Z, A[2]]])


@pytest.mark.parametrize("singular_lead", [False, True])
def test_qz_eigenvalues_equal_scipy_generalised_eigenvalues(singular_lead):
    rng = np.random.default_rng(4)
    A = rng.standard_normal((3, 12, 12))
    if singular_lead:  # rank-10 A2: 2 infinite eigenvalues, reported as NaN
        A[2] = A[2][:, :10] @ rng.standard_normal((10, 12))
    wr, wi = np.empty(24), np.empty(24)
    assert pencil_eigvals_qz(A, wr, wi, qz_scratch())
    w = wr + 1j * wi
    ref = scipy.linalg.eig(*_companion_pencil(A), right=False)
    finite = ref[np.isfinite(ref) & (np.abs(ref) < 1e8)]
    assert np.sum(np.isnan(w)) == (2 if singular_lead else 0)
    assert np.sum(~np.isnan(w)) == finite.size
    for r in finite:
        assert np.min(np.abs(w[~np.isnan(w)] - r)) <= 1e-8 * (1 + abs(r))
    # each finite eigenvalue makes the matrix quadratic singular (independent check)
    for x in w[~np.isnan(w)]:
        s = np.linalg.svd(A[2] * x * x + A[1] * x + A[0], compute_uv=False)
        assert s[-1] <= 1e-8 * s[0] * (1 + abs(x)) ** 2


def _near_fold_jaco2(n, seed, width=0.05):
    """Jaco2-type configurations with θ5 within ``width`` of 0 or π (its wrist nearly folds:
    solutions pair up, so the real roots cluster), kept away from singular sets."""
    model = arm("jaco6")
    rng = np.random.default_rng(seed)
    q = rng.uniform(-PI, PI, (n, 6))
    q[:, 4] = rng.choice([0.0, PI], n) + rng.uniform(-width, width, n)
    s = np.linalg.svd(kinestat.jacobian(model, q), compute_uv=False)
    return model, q[s[:, -1] > 1e-5 * s[:, 0]]


def _found(res_q, valid, q):
    d = wrapped_distance(res_q, q[:, None, :])
    return np.any(np.where(valid, d, np.inf) < 1e-6, axis=1)


def test_near_fold_jaco2_generating_configuration_always_found():
    """10⁴ near-fold poses (θ5 within 0.001 of the fold): the companion alone misses generators
    here (checked below), the default (QZ on suspect poses) misses none and equals rechecking
    every pose. The companion with its spurious ±i deflated misses few (5 of 10⁴ here, none
    within 0.01 of the fold), hence the narrow band; rounding differs between machines."""
    model, q = _near_fold_jaco2(10_000, seed=8, width=0.001)
    T = kinestat.fk(model, q)
    form, _ = g.formulation(model)
    runs = {m: g.run_kernel(model, T, form, 1e-9, 8, m) for m in ("never", "suspect", "always")}
    assert not _found(*runs["never"][:2], q).all()  # the test can fail without the recheck
    assert _found(*runs["suspect"][:2], q).all()
    np.testing.assert_array_equal(runs["suspect"][1].sum(1), runs["always"][1].sum(1))
    res = kinestat.ik_all(model, T)
    np.testing.assert_array_equal(res.n_solutions, runs["suspect"][1].sum(1))
    pos, dR = slot_residuals(model, res, T)
    assert pos.max() <= 1e-9 and dR.max() <= 1e-9


def test_near_fold_jaco2_counts_match_many_start_newton():
    model, q = _near_fold_jaco2(40, seed=21)
    T = kinestat.fk(model, q)
    res = kinestat.ik_all(model, T)
    oracle = newton_solutions(model, T, starts=300, iters=50, seed=3)
    for i, sols in enumerate(oracle):
        assert len(sols) == res.n_solutions[i], (i, len(sols), res.n_solutions[i])
        mine = res.solutions((i,))
        for s in sols:
            assert np.min(wrapped_distance(mine, s)) < 1e-6


@pytest.mark.parametrize("name", ["jaco6", "random1", "random2", "random3"])
def test_recheck_is_rare_and_loses_nothing(name):
    """On random poses the QZ pass runs on few poses (the speed of the typical pose), and
    running it only there finds exactly the solutions that running it everywhere finds."""
    model = arm(name)
    q = np.random.default_rng(13).uniform(-PI, PI, (3000, 6))
    T = kinestat.fk(model, q)
    form, _ = g.formulation(model)
    a = g.run_kernel(model, T, form, 1e-9, 8, "suspect")
    b = g.run_kernel(model, T, form, 1e-9, 8, "always")
    assert a[6][:, 4].mean() < 0.03, a[6][:, 4].mean()
    np.testing.assert_array_equal(a[1].sum(1), b[1].sum(1))
    for i in np.flatnonzero(a[1].sum(1)):
        sa, sb = a[0][i][a[1][i]], b[0][i][b[1][i]]
        for s in sb:
            assert np.min(wrapped_distance(sa, s)) < 1e-6


def test_recheck_option_of_the_solver():
    """``solve_general_6r(recheck=…)``: "always" equals the default on clustered poses; the
    companion alone ("never") finds no more, each reproducing its pose (whether it loses some
    there depends on the machine's rounding); a bad value is one clear error."""
    from .test_ik_all import CLUSTERED_JACO2

    model = arm("jaco6")
    T = kinestat.fk(model, np.array(CLUSTERED_JACO2))
    default = g.solve_general_6r(model, T)
    always = g.solve_general_6r(model, T, recheck="always")
    never = g.solve_general_6r(model, T, recheck="never")
    np.testing.assert_array_equal(default.n_solutions, always.n_solutions)
    assert np.all(never.n_solutions <= default.n_solutions)
    for i in range(len(T)):
        for s in never.solutions((i,)):
            assert np.allclose(kinestat.fk(model, s), T[i], atol=1e-8)
    with pytest.raises(kinestat.KinestatError, match="recheck"):
        g.solve_general_6r(model, T, recheck="sometimes")
