"""The compiled eigenvalue routine on random and structured matrices: backward error,
trace, and NumPy's (LAPACK) eigenvalues where they are well separated."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.serial.analytic._hqr import eigvals


def _matched(w, ref):
    """The largest distance from each of w to its own nearest of ref (one-to-one)."""
    ref = list(ref)
    worst = 0.0
    for z in w:
        d = np.abs(np.array(ref) - z)
        k = int(np.argmin(d))
        worst = max(worst, float(d[k]))
        ref.pop(k)
    return worst


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 16, 24])
def test_eigenvalues_backward_stable_and_equal_lapacks(n):
    rng = np.random.default_rng(n)
    for k in range(60):
        a = rng.standard_normal((n, n)) * 10.0 ** rng.uniform(-3, 3, (n, 1))
        if k % 3 == 0:
            a[rng.random((n, n)) < 0.5] = 0.0  # sparse: zero subdiagonals, split blocks
        wr, wi = np.zeros(n), np.zeros(n)
        assert eigvals(a.copy(), n, wr, wi)
        w = wr + 1j * wi
        scale = max(1.0, np.abs(a).max())
        # each eigenvalue makes a − λI singular (backward error; defective ones included) ...
        for lam in w:
            s = np.linalg.svd(a - lam * np.eye(n), compute_uv=False)
            assert s[-1] <= 1e-10 * n * scale
        # ... their sum is the trace, and where LAPACK's are well separated they agree
        assert abs(w.sum() - np.trace(a)) <= 1e-10 * n * scale
        ref = np.linalg.eigvals(a)
        gaps = np.where(np.eye(n, dtype=bool), np.inf, np.abs(ref[:, None] - ref[None, :]))
        if n == 1 or gaps.min() > 1e-3 * scale:
            assert _matched(w, ref) <= 1e-8 * scale
        # real eigenvalues come out exactly real, complex ones in conjugate pairs
        assert np.allclose(np.sort(wi), np.sort(-wi))


def test_companion_and_triangular_matrices():
    roots = np.array([-3.0, -1.0, 0.5, 2.0, 7.0])
    c = np.poly(roots)
    C = np.zeros((5, 5))
    C[0] = -c[1:]
    C[np.arange(1, 5), np.arange(4)] = 1.0
    wr, wi = np.zeros(5), np.zeros(5)
    assert eigvals(C, 5, wr, wi)
    assert np.allclose(np.sort(wr), roots) and np.all(wi == 0.0)
    U = np.triu(np.arange(1.0, 17.0).reshape(4, 4))
    assert eigvals(U.copy(), 4, wr, wi)
    assert np.allclose(np.sort(wr[:4]), np.sort(np.diag(U)))


def test_non_finite_input_is_refused():
    a = np.eye(3)
    a[1, 2] = np.nan
    assert not eigvals(a, 3, np.zeros(3), np.zeros(3))


@pytest.mark.parametrize("scale", [1e-150, 1e-120, 1e120, 1e150])
def test_eigenvalues_scale_with_the_matrix(scale):
    """Eigenvalues of s·a are s times those of a, at scales where the squares of the entries
    (the reflectors' norms) are far outside 1e±100, where the sweep rescales its reflector."""
    rng = np.random.default_rng(7)
    n = 16
    a = rng.standard_normal((n, n))
    wr, wi = np.zeros(n), np.zeros(n)
    assert eigvals(a.copy(), n, wr, wi)
    w = wr + 1j * wi
    assert eigvals(a * scale, n, wr, wi)
    ws = (wr + 1j * wi) / scale
    assert _matched(ws, w) <= 1e-10 * np.abs(w).max()
