"""The deflated companion of the general-6R kernel against the full 24x24 companion's
eigenvalues (NumPy), and the kernel's solutions against FK and many-start numerical IK."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.serial.analytic import general6r as g
from kinestat.serial.analytic._rr_deflate import (
    deflate_scratch,
    deflated_eigvals,
    model_basis,
    no_basis,
    spurious_basis,
)

from .arms import arm


def _pencils(name, n, seed):
    model = arm(name)
    form, _ = g.formulation(model)
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (n, 6))
    T = kinestat.fk(model, q)
    A, *_ = g._pencil(form.links(np.asarray(model.constants), T), n)
    return A / np.max(np.abs(A), axis=(1, 2, 3))[:, None, None, None]


def _model_basis(name):
    model = arm(name)
    return model_basis(g._compiled_data(model, g.formulation(model)[0])[3])


def _match(a, b):
    """Largest distance from each of a to its nearest in b (a greedy one-to-one matching)."""
    b = list(b)
    worst = 0.0
    for z in sorted(a, key=lambda z: (z.real, z.imag)):
        d = np.abs(np.array(b) - z)
        k = int(np.argmin(d))
        worst = max(worst, d[k] / (1.0 + abs(z)))
        b.pop(k)
    return worst


@pytest.mark.parametrize("name", ["random1", "random2", "jaco6"])
def test_model_basis_spans_every_poses_null_space_at_i(name):
    """The per-model basis (from the pose-independent equations) against each pose's pencil:
    its vectors are null vectors of A(i) and span the same space as the per-pose basis."""
    basis, index = _model_basis(name)
    assert index[0] == 8
    p = index[1:9]
    # Gauss–Jordan form on the pivots. (Complete pivoting does not bound the other entries by
    # 1: later eliminations change earlier rows, and the pivots follow LAPACK's null basis.)
    assert np.allclose(basis[:, p], np.eye(8), atol=1e-12)
    for A in _pencils(name, 10, 5):
        Ai = A[0] - A[2] + 1j * A[1]
        v = basis[:, :12] - 1j * basis[:, 12:]  # [x; y] ↦ x − i y: the complex null vectors
        assert np.abs(Ai @ v.T).max() < 1e-12
        S = deflate_scratch()
        assert spurious_basis(A.copy(), S) == 8
        # same row space: each per-pose basis vector is its pivot-column combination
        Bt = S[3]
        assert np.abs(Bt - Bt[:, p] @ basis).max() < 1e-9


@pytest.mark.parametrize("name", ["random1", "jaco6"])
@pytest.mark.parametrize("per_model", [False, True])
def test_deflated_eigenvalues_equal_the_full_companion(name, per_model):
    basis = _model_basis(name) if per_model else no_basis()
    for A in _pencils(name, 12, 3):
        X = np.linalg.solve(A[2], np.concatenate([A[0], A[1]], axis=1))
        C = np.zeros((24, 24))
        C[:12, 12:] = np.eye(12)
        C[12:] = -X
        full = np.linalg.eigvals(C)
        wr, wi = np.empty(24), np.empty(24)
        S = deflate_scratch()
        assert deflated_eigvals(A.copy(), X.copy(), wr, wi, np.empty(1), S, *basis) == 0
        assert spurious_basis(A.copy(), S) == 8  # four null vectors of A(i): ±i, 4-fold each
        w = wr + 1j * wi
        assert np.sum(np.abs(w - 1j) == 0) == 4 and np.sum(np.abs(w + 1j) == 0) == 4
        # the 16 others are the full companion's eigenvalues away from ±i
        rest = full[np.minimum(np.abs(full - 1j), np.abs(full + 1j)) > 1e-5]
        assert rest.size == 16
        assert _match(w[:16], rest) < 1e-8


@pytest.mark.parametrize("name", ["random1", "jaco6"])
def test_compiled_solutions_reproduce_pose_and_cover_numerical_ik(name):
    model = arm(name)
    rng = np.random.default_rng(11)
    q0 = rng.uniform(-np.pi, np.pi, (20, 6))
    T = kinestat.fk(model, q0)
    res = g.solve_general_6r(model, T)
    ref = g.solve_general_6r(model, T, backend="numpy")
    assert np.array_equal(res.n_solutions, ref.n_solutions)
    for i in range(len(T)):
        sols = res.solutions((i,))
        assert sols.shape[0] <= g.MAX_SOLUTIONS and sols.shape[0] % 2 == 0
        err = np.abs(kinestat.fk(model, sols) - T[i]).max() if len(sols) else 0.0
        assert err < 1e-8
        d = np.abs(np.mod(sols - q0[i] + np.pi, 2 * np.pi) - np.pi).max(axis=1)
        assert d.min() < 1e-6  # the generating configuration is among them
        # numerical IK from many starts finds nothing the closed form lacks
        starts = rng.uniform(-np.pi, np.pi, (40, 6))
        num = kinestat.ik(model, np.repeat(T[i][None], 40, axis=0), starts)
        for qn in num.q[num.success]:
            dn = np.abs(np.mod(sols - qn + np.pi, 2 * np.pi) - np.pi).max(axis=1)
            assert dn.min() < 1e-5


@pytest.mark.parametrize("name", ["random1", "jaco6"])
def test_structured_null_vector_equals_the_svd_null_vector(name):
    """At each real eigenvalue x of the pencil, the block-structured null vector of A(x) is the
    matrix's smallest right singular vector (NumPy's SVD), or the kernel declines it."""
    from kinestat.serial.analytic._rr_null import _null_structured

    used = 0
    for A in _pencils(name, 8, 7):
        X = np.linalg.solve(A[2], np.concatenate([A[0], A[1]], axis=1))
        C = np.zeros((24, 24))
        C[:12, 12:] = np.eye(12)
        C[12:] = -X
        for x in np.linalg.eigvals(C):
            if abs(x.imag) > 1e-9 * (1 + abs(x)):
                continue
            x = x.real
            S = (A[0] + x * A[1] + x * x * A[2]) / max(1.0, x * x)
            v = np.empty((12, 1))
            W = np.empty((16, 12))
            W[:6, :9] = S[:6, :9]  # E(x): the structured path reads only these
            if not _null_structured(v, W, np.empty(12, np.int64)):
                continue
            used += 1
            u = np.linalg.svd(S)[2][-1]
            assert abs(abs(u @ v[:, 0]) - 1.0) < 1e-6
    assert used > 0
