"""Paden–Kahan subproblems: each recovers the angles that generated its data."""

from __future__ import annotations

import numpy as np

from kinestat.serial.analytic.subproblems import rotate, rotation_matrix, sp1, sp2, sp3, sp4

N = 200


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _wrapdiff(a, b):
    return np.abs(np.mod(a - b + np.pi, 2 * np.pi) - np.pi)


def _data(seed):
    rng = np.random.default_rng(seed)
    return (rng, _unit(rng.normal(size=(N, 3))), rng.normal(size=(N, 3)),
            rng.normal(size=(N, 3)), rng.uniform(-np.pi, np.pi, N))


def test_rotation_matrix_is_a_rotation_about_its_axis():
    _, w, _, _, th = _data(0)
    R = rotation_matrix(w, th)
    np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-12)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", R, w), w, atol=1e-12)
    np.testing.assert_allclose(np.trace(R, axis1=1, axis2=2), 1 + 2 * np.cos(th), atol=1e-12)


def test_sp1():
    _, w, r, p, th = _data(1)
    t, ok, free = sp1(w, r, p, rotate(w, r, th, p))
    assert ok.all() and not free.any()
    assert _wrapdiff(t, th).max() < 1e-10
    _, ok, _ = sp1(w, r, p, rotate(w, r, th, p) + 0.1 * w)  # different height: no solution
    assert not ok.any()


def test_sp2():
    rng, w1, r, p, t1 = _data(2)
    w2 = _unit(rng.normal(size=(N, 3)))
    t2 = rng.uniform(-np.pi, np.pi, N)
    q = rotate(w1, r, t1, rotate(w2, r, t2, p))
    a, b, ok = sp2(w1, w2, r, p, q)
    assert ok.all()
    err = np.min(_wrapdiff(a, t1[:, None]) + _wrapdiff(b, t2[:, None]), axis=1)
    assert err.max() < 1e-8
    # both returned pairs solve the subproblem
    for k in range(2):
        back = rotate(w1, r, a[:, k], rotate(w2, r, b[:, k], p))
        assert np.abs(back - q).max() < 1e-8


def test_sp3():
    rng, w, r, p, th = _data(3)
    q = rng.normal(size=(N, 3))
    d = np.linalg.norm(rotate(w, r, th, p) - q, axis=-1)
    t, ok = sp3(w, r, p, q, d)
    assert ok.all()
    assert np.min(_wrapdiff(t, th[:, None]), axis=1).max() < 1e-6
    for k in range(2):
        np.testing.assert_allclose(np.linalg.norm(rotate(w, r, t[:, k], p) - q, axis=-1), d,
                                   atol=1e-9)
    _, ok = sp3(w, r, p, q, d + 100.0)
    assert not ok.any()


def test_sp4():
    rng, w, _, p, th = _data(4)
    h = _unit(rng.normal(size=(N, 3)))
    d = np.einsum("ni,nij,nj->n", h, rotation_matrix(w, th), p)
    t, ok = sp4(h, w, p, d)
    assert ok.all()
    assert np.min(_wrapdiff(t, th[:, None]), axis=1).max() < 1e-6
    for k in range(2):
        np.testing.assert_allclose(np.einsum("ni,nij,nj->n", h, rotation_matrix(w, t[:, k]), p),
                                   d, atol=1e-9)


def test_cross3_and_norm3_equal_numpy():
    from kinestat.serial.analytic.geometry import cross3, norm3

    rng = np.random.default_rng(3)
    for a, b in rng.normal(size=(50, 2, 3)) * rng.uniform(1e-6, 1e3, (50, 1, 1)):
        assert np.allclose(cross3(a, b), np.cross(a, b), rtol=1e-14, atol=0.0)
        assert abs(norm3(a) - np.linalg.norm(a)) <= 1e-15 * np.linalg.norm(a)
