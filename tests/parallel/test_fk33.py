"""Closed-form 3-3 forward kinematics: polynomial, all modes, mirror pairs."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinestat.errors import InputError
from kinestat.parallel._refine import refine
from kinestat.parallel.fk33 import LEGS_33, fk33_polynomial, fk_33, pair_coefficients
from kinestat.spatial.transforms import apply, make_pose

BASE = np.array([[0.0, 0.0, 0.0], [120.0, 0.0, 0.0], [60.0, 60.0 * np.sqrt(3), 0.0]])
TOP = np.array([[0.0, 0.0, 0.0], [60.0, 0.0, 0.0], [30.0, 30.0 * np.sqrt(3), 0.0]])
BP = BASE[[b for b, _ in LEGS_33]]
TP = TOP[[t for _, t in LEGS_33]]


def legs33(T):
    X = apply(np.asarray(T)[..., None, :, :], TP)
    return np.linalg.norm(X - BP, axis=-1)


def random_pose(rng, n=None):
    shape = () if n is None else (n,)
    R = Rotation.from_rotvec(rng.normal(size=shape + (3,)) * 0.3).as_matrix()
    p = np.array([60.0, 34.0, 60.0]) + rng.normal(size=shape + (3,)) * 10
    return make_pose(R, p)


def test_polynomial_matches_sympy_resultant():
    """Our resultant (power sums + FFT) equals sympy's two Sylvester resultants."""
    sp = pytest.importorskip("sympy")
    rng = np.random.default_rng(3)
    f = [tuple(float(v) for v in rng.integers(-9, 10, size=5)) for _ in range(3)]
    ours = fk33_polynomial(*[tuple(np.array(v) for v in c) for c in f])
    x, y, z = sp.symbols("x y z")

    def eq(c, u, v):
        A, B, C, D, E = (sp.Integer(int(t)) for t in c)
        return A * u**2 * v**2 + B * u**2 + C * v**2 + D * u * v + E

    f1, f2, f3 = eq(f[0], x, y), eq(f[1], z, x), eq(f[2], y, z)
    G = sp.resultant(f1, f3, y)
    R = sp.Poly(sp.expand(sp.resultant(f2, G, z)), x)
    coeffs = np.array([float(R.coeff_monomial(x**k)) for k in range(17)])
    assert np.any(coeffs != 0)
    assert np.max(np.abs(coeffs[1::2])) <= 1e-9 * np.max(np.abs(coeffs))  # even in x
    ref = coeffs[::2]
    np.testing.assert_allclose(ours, ref, rtol=1e-8, atol=1e-10 * np.max(np.abs(ref)))


def test_pair_coefficients_reproduce_distance():
    rng = np.random.default_rng(0)
    cu, cv = np.r_[rng.normal(size=2), 0.0], np.r_[rng.normal(size=2), 0.0]
    nu = np.r_[rng.normal(size=2), 0.0]
    nu /= np.linalg.norm(nu)
    nv = np.r_[rng.normal(size=2), 0.0]
    nv /= np.linalg.norm(nv)
    ru, rv, tu, tv = 0.7, 1.3, 0.4, -1.1
    U = cu + ru * (np.cos(tu) * nu + np.sin(tu) * np.r_[0, 0, 1.0])
    V = cv + rv * (np.cos(tv) * nv + np.sin(tv) * np.r_[0, 0, 1.0])
    d2 = float(np.sum((U - V) ** 2))
    A, B, C, D, E, _ = pair_coefficients(cu, nu, ru, cv, nv, rv, d2)
    u, v = np.tan(tu / 2), np.tan(tv / 2)
    assert abs(A * u * u * v * v + B * u * u + C * v * v + D * u * v + E) < 1e-12


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_fk33_contains_the_pose(seed):
    T = random_pose(np.random.default_rng(seed))
    poses, ok = fk_33(BASE, TOP, legs33(T))
    assert ok.sum() % 2 == 0 and ok.sum() >= 2
    d = np.abs(poses[ok] - T).max(axis=(-1, -2))
    assert d.min() < 1e-7
    np.testing.assert_allclose(legs33(poses[ok]), np.broadcast_to(legs33(T), (ok.sum(), 6)),
                               atol=1e-9)


def test_fk33_batch_shapes_and_mirror_pairs():
    rng = np.random.default_rng(7)
    T = random_pose(rng, 12).reshape(3, 4, 4, 4)
    poses, ok = fk_33(BASE, TOP, legs33(T))
    assert poses.shape == (3, 4, 16, 4, 4) and ok.shape == (3, 4, 16)
    D = np.diag([1.0, 1.0, -1.0, 1.0])
    for i in np.ndindex(3, 4):
        for s in range(0, 16, 2):
            if ok[i][s] and ok[i][s + 1]:
                # the two members are reflections through the base plane (z = 0):
                # reflect the points, then reflect the top frame through its own plane
                np.testing.assert_allclose(poses[i][s + 1], D @ poses[i][s] @ D, atol=1e-8)


def test_fk33_finds_every_newton_solution():
    """Multi-start Newton (an independent search) finds no mode the closed form misses."""
    rng = np.random.default_rng(11)
    L = legs33(random_pose(rng))
    poses, ok = fk_33(BASE, TOP, L)
    M = 3000
    starts = make_pose(Rotation.random(M, random_state=5).as_matrix(),
                       rng.uniform(-150, 250, size=(M, 3)))
    T, r = refine(BP, TP, np.broadcast_to(L, (M, 6)), starts, iterations=60)
    found = T[np.abs(r).max(axis=-1) < 1e-9]
    assert len(found) >= 10
    d = np.abs(found[:, None] - poses[ok][None]).max(axis=(-1, -2)).min(axis=1)
    assert d.max() < 1e-6


def test_fk33_rejects_negative_lengths():
    with pytest.raises(InputError):
        fk_33(BASE, TOP, [-1, 70, 70, 70, 70, 70])
    with pytest.raises(InputError):
        fk_33(BASE, TOP, [np.nan, 70, 70, 70, 70, 70])


def test_fk33_impossible_lengths_have_no_modes():
    poses, ok = fk_33(BASE, TOP, [1.0, 1.0, 1.0, 1.0, 1.0, 1.0])
    assert not ok.any()
