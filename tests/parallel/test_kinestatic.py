"""Kinestatic decomposition (Griffis & Duffy 1991; Vibhute §2.1.3.3): properties, an independent
direct-sum solve, finite differences of the platform's wrench, batching and degenerate cases."""

from __future__ import annotations

import doctest

import numpy as np
import pytest
import scipy.linalg

import kinestat.parallel.kinestatic as kmod
from kinestat.errors import InputError, SingularityError
from kinestat.io.library import prototype
from kinestat.parallel._refine import apply_twist
from kinestat.parallel.kinestatic import (
    DELTA,
    axis_stiffness,
    compliance_twists,
    compose_twist,
    contact_basis,
    decompose_twist,
    elliptic_product,
    freedom_basis,
    platform_stiffness_axis,
    reciprocal_products,
    wrench_coordinates,
)
from kinestat.parallel.statics import forces_from_wrench, spring_wrench
from kinestat.parallel.stiffness import stiffness

P = prototype()


def random_pose(rng, scale=1.0):
    """A loaded pose near home: rotation up to ~0.08 rad, shift up to ~3 mm."""
    tw = np.r_[rng.uniform(-0.08, 0.08, 3), rng.uniform(-3.0, 3.0, 3)] * scale
    return apply_twist(P.home_pose, tw)


def random_contact(rng, m):
    """m random contact wrenches [f; m_O] (N, N·mm), moments of arm ~50 mm."""
    return np.concatenate([rng.normal(size=(3, m)), 50.0 * rng.normal(size=(3, m))], axis=0)


def random_twist(rng):
    """A small axis-order twist [ω; v_O]: rad and mm."""
    return np.r_[0.01 * rng.normal(size=3), rng.normal(size=3)]


def cases(n=40, seed=7):
    rng = np.random.default_rng(seed)
    for i in range(n):
        T = random_pose(rng)
        K = stiffness(P, T, twist_order="axis")
        m = 1 + i % 5
        yield T, K, random_contact(rng, m), random_twist(rng)


def rel_recip(W, Tf, T):
    """|Wᵀ Δ T_f| relative to |w_i| |T|."""
    r = np.abs(W.T @ DELTA @ Tf)
    return np.max(r / (np.linalg.norm(W, axis=0) * np.linalg.norm(T)))


def test_doctests():
    assert doctest.testmod(kmod).failed == 0


def test_axis_stiffness_matches_the_platform_axis_order():
    rng = np.random.default_rng(1)
    T = random_pose(rng)
    K_ray = stiffness(P, T)
    np.testing.assert_array_equal(axis_stiffness(K_ray), stiffness(P, T, twist_order="axis"))
    np.testing.assert_array_equal(axis_stiffness(K_ray, "axis"), K_ray)
    # K_axis acts on [ω; v_O], K_ray on [δx; δφ]: the same wrench for the same motion
    tw = random_twist(rng)
    np.testing.assert_allclose(axis_stiffness(K_ray) @ tw, K_ray @ np.r_[tw[3:], tw[:3]])
    with pytest.raises(InputError, match="twist_order"):
        axis_stiffness(K_ray, "plucker")


def test_platform_stiffness_axis_under_an_external_wrench():
    rng = np.random.default_rng(2)
    T = random_pose(rng)
    w0 = np.r_[1.0, -2.0, -5.0, 30.0, 10.0, -20.0]
    K = platform_stiffness_axis(P, T, w0)
    ref = stiffness(P, T, forces_from_wrench(P, T, w0), twist_order="axis")
    np.testing.assert_array_equal(K, ref)
    np.testing.assert_array_equal(platform_stiffness_axis(P, T),
                                  stiffness(P, T, twist_order="axis"))


@pytest.mark.parametrize("case", list(range(40)))
def test_decomposition_properties(case):
    _, K, W, T = list(cases())[case]
    s = decompose_twist(K, W, T)
    m = W.shape[1]
    assert s.freedom.shape == (6,) and s.compliance.shape == (6,) and s.lam.shape == (m,)
    np.testing.assert_allclose(s.freedom + s.compliance, T, rtol=0, atol=1e-15 * 10)
    assert rel_recip(W, s.freedom, T) <= 1e-12
    # the compliance twist is K⁻¹ W λ: its wrench is W λ
    kc = K @ s.compliance
    assert np.linalg.norm(kc - W @ s.lam) <= 1e-10 * np.linalg.norm(kc)
    # one-sided elliptic orthogonality: the wrench of T_c does no work on T_f
    scale = np.linalg.norm(s.freedom) * np.linalg.norm(kc)
    assert abs(elliptic_product(K, s.freedom, s.compliance)) <= 1e-12 * scale


def test_decomposition_against_a_direct_sum_solve():
    """Independent: T_f = N μ with N = null(Wᵀ Δ) from scipy, and [K N, W] [μ; λ] = K T."""
    for _, K, W, T in cases(seed=11):
        N = scipy.linalg.null_space(W.T @ DELTA)
        A = np.concatenate([K @ N, W], axis=1)
        x = np.linalg.solve(A, K @ T)
        Tf, lam = N @ x[: N.shape[1]], x[N.shape[1]:]
        s = decompose_twist(K, W, T)
        np.testing.assert_allclose(s.freedom, Tf, atol=1e-9 * np.linalg.norm(T))
        np.testing.assert_allclose(s.lam, lam, atol=1e-9 * np.linalg.norm(K @ T)
                                   / np.linalg.norm(W, axis=0).min())


def test_compliance_twist_moves_the_platform_wrench_by_W_lambda():
    """Finite differences on the platform itself: moving by ε T_c changes the wrench by ε W λ."""
    rng = np.random.default_rng(5)
    for m in range(1, 6):
        pose = random_pose(rng)
        K = platform_stiffness_axis(P, pose)
        W, T = random_contact(rng, m), random_twist(rng)
        s = decompose_twist(K, W, T)
        eps = 1e-5
        dw = (spring_wrench(P, apply_twist(pose, eps * s.compliance))
              - spring_wrench(P, apply_twist(pose, -eps * s.compliance))) / (2 * eps)
        assert np.linalg.norm(dw - W @ s.lam) <= 1e-6 * np.linalg.norm(W @ s.lam)
        # with K left in the platform's default ray order the same check fails
        bad = decompose_twist(stiffness(P, pose), W, T)
        dwb = (spring_wrench(P, apply_twist(pose, eps * bad.compliance))
               - spring_wrench(P, apply_twist(pose, -eps * bad.compliance))) / (2 * eps)
        assert np.linalg.norm(dwb - W @ bad.lam) > 1e-2 * np.linalg.norm(W @ bad.lam)


def test_orthogonality_is_one_sided_under_load_and_symmetric_unloaded():
    rng = np.random.default_rng(3)
    loaded_other_side = []
    for _ in range(20):
        pose = random_pose(rng, scale=2.0)
        K = stiffness(P, pose, twist_order="axis")
        W, T = random_contact(rng, 2), random_twist(rng)
        s = decompose_twist(K, W, T)
        scale = np.linalg.norm(s.compliance) * np.linalg.norm(K @ s.freedom)
        loaded_other_side.append(abs(elliptic_product(K, s.compliance, s.freedom)) / scale)
    assert max(loaded_other_side) > 1e-4
    K0 = stiffness(P, P.home_pose, twist_order="axis")
    M0 = DELTA @ K0
    np.testing.assert_allclose(M0, M0.T, atol=1e-12 * np.abs(M0).max())
    assert np.all(np.linalg.eigvalsh(0.5 * (M0 + M0.T)) > 0)  # the elliptic metric, unloaded
    for _ in range(10):
        W, T = random_contact(rng, 3), random_twist(rng)
        s = decompose_twist(K0, W, T)
        scale = np.linalg.norm(s.compliance) * np.linalg.norm(K0 @ s.freedom)
        assert abs(elliptic_product(K0, s.compliance, s.freedom)) <= 1e-12 * scale


def test_compose_is_the_inverse_of_decompose():
    for _, K, W, T in cases(n=15, seed=13):
        s = decompose_twist(K, W, T)
        dw = W @ s.lam
        np.testing.assert_allclose(compose_twist(K, W, s.freedom, dw), T,
                                   atol=1e-10 * np.linalg.norm(T))
        np.testing.assert_allclose(wrench_coordinates(W, dw), s.lam,
                                   rtol=1e-8, atol=1e-12 * np.abs(s.lam).max())
        # a wanted wrench change and freedom: the composed twist decomposes back into them
        rng = np.random.default_rng(int(abs(T[0]) * 1e6))
        N = freedom_basis(W)
        Tf = N @ rng.normal(size=N.shape[1])
        lam = rng.normal(size=W.shape[1])
        T2 = compose_twist(K, W, Tf, W @ lam)
        s2 = decompose_twist(K, W, T2)
        np.testing.assert_allclose(s2.freedom, Tf, atol=1e-9 * np.linalg.norm(T2))
        np.testing.assert_allclose(W @ s2.lam, W @ lam, atol=1e-9 * np.linalg.norm(W @ lam))


def test_freedom_basis_is_reciprocal_and_orthonormal():
    rng = np.random.default_rng(4)
    for m in range(1, 6):
        W = random_contact(rng, m)
        N = freedom_basis(W)
        assert N.shape == (6, 6 - m)
        np.testing.assert_allclose(N.T @ N, np.eye(6 - m), atol=1e-12)
        assert np.abs(reciprocal_products(W, N.T)).max() <= 1e-12 * np.linalg.norm(W)


def test_batched_equals_one_by_one():
    rng = np.random.default_rng(9)
    poses = np.stack([random_pose(rng) for _ in range(6)]).reshape(2, 3, 4, 4)
    K = stiffness(P, poses, twist_order="axis")
    W = np.stack([random_contact(rng, 3) for _ in range(6)]).reshape(2, 3, 6, 3)
    T = np.stack([random_twist(rng) for _ in range(6)]).reshape(2, 3, 6)
    s = decompose_twist(K, W, T)
    assert s.freedom.shape == (2, 3, 6) and s.lam.shape == (2, 3, 3)
    for i in np.ndindex(2, 3):
        one = decompose_twist(K[i], W[i], T[i])
        np.testing.assert_allclose(s.freedom[i], one.freedom, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(s.lam[i], one.lam, rtol=1e-12)
    # broadcasting: one K and W, a batch of twists
    sb = decompose_twist(K[0, 0], W[0, 0], T.reshape(6, 6))
    for j in range(6):
        np.testing.assert_allclose(sb.freedom[j], decompose_twist(K[0, 0], W[0, 0],
                                                                  T.reshape(6, 6)[j]).freedom)
    assert compliance_twists(K, W).shape == (2, 3, 6, 3)
    np.testing.assert_allclose(compose_twist(K, W, s.freedom, np.einsum("...im,...m->...i",
                                                                        W, s.lam)), T,
                               atol=1e-10)


def test_single_wrench_as_a_vector():
    K = stiffness(P, P.home_pose, twist_order="axis")
    w = np.r_[0, 0, 1.0, 0, 0, 0]
    a = decompose_twist(K, w, np.r_[0.01, 0, 0, 1.0, 2.0, 3.0])
    b = decompose_twist(K, w[:, None], np.r_[0.01, 0, 0, 1.0, 2.0, 3.0])
    np.testing.assert_array_equal(a.freedom, b.freedom)
    assert abs(a.freedom[5]) < 1e-12  # no normal velocity at O for a pure z force through O


def test_degenerate_contact_sets():
    K = stiffness(P, P.home_pose, twist_order="axis")
    T = np.r_[0.0, 0, 0, 1, 0, 0]
    w = np.r_[0, 0, 1.0, 0, 0, 0]
    with pytest.raises(InputError, match="1 to 6"):
        decompose_twist(K, np.eye(6, 7), T)
    with pytest.raises(InputError, match="1 to 6"):
        decompose_twist(K, np.zeros((6, 0)), T)
    with pytest.raises(InputError, match="linearly dependent"):
        decompose_twist(K, np.stack([w, 2 * w], axis=1), T)
    with pytest.raises(InputError, match="linearly dependent"):
        decompose_twist(K, np.stack([w, np.r_[1.0, 0, 0, 0, 0, 0], w + 1e-12], axis=1), T)
    with pytest.raises(InputError, match="is zero"):
        decompose_twist(K, np.zeros((6, 1)), T)
    with pytest.raises(InputError, match=r"\(\.\.\., 6, m\)"):
        decompose_twist(K, np.ones((5, 2)), T)
    with pytest.raises(InputError, match="NaN"):
        decompose_twist(K, w, np.r_[np.nan, 0, 0, 0, 0, 0])
    with pytest.raises(InputError, match="trailing shape"):
        decompose_twist(K[:5], w, T)
    with pytest.raises(InputError, match="batch index"):
        contact_basis(np.stack([np.stack([w, np.r_[1.0, 0, 0, 0, 0, 0]], 1),
                                np.stack([w, w], 1)]))


def test_singular_stiffness_and_singular_gram():
    T = np.r_[0.0, 0, 0, 1, 0, 0]
    K = stiffness(P, P.home_pose, twist_order="axis")
    Ks = K.copy()
    Ks[:, 2] = 0.0
    with pytest.raises(SingularityError, match="K is singular"):
        decompose_twist(Ks, np.r_[0, 0, 1.0, 0, 0, 0], T)
    with pytest.raises(SingularityError, match="batch index"):
        decompose_twist(np.stack([K, Ks]), np.r_[0, 0, 1.0, 0, 0, 0], T)
    # K⁻¹ = Δ D with D = diag(1, −1, 1, 1, 1, 1): Wᵀ Δ K⁻¹ W = wᵀ D w = 0 for w = e1 + e2
    D = np.diag([1.0, -1, 1, 1, 1, 1])
    Kbad = D @ DELTA
    np.testing.assert_allclose(np.linalg.inv(Kbad), DELTA @ D)
    with pytest.raises(SingularityError, match="Wᵀ Δ K⁻¹ W is singular"):
        decompose_twist(Kbad, np.r_[1.0, 1.0, 0, 0, 0, 0], T)


def test_compose_rejects_bad_inputs():
    K = stiffness(P, P.home_pose, twist_order="axis")
    w = np.r_[0, 0, 1.0, 0, 0, 0]
    with pytest.raises(InputError, match="not reciprocal"):
        compose_twist(K, w, np.r_[0, 0, 0, 0, 0, 1.0], 3 * w)  # v_O,z pushes along the force
    with pytest.raises(InputError, match="not one the contact can exert"):
        compose_twist(K, w, np.r_[0, 0, 0, 1.0, 0, 0], np.r_[1.0, 0, 0, 0, 0, 0])


def test_six_contact_wrenches_leave_no_twist_of_freedom():
    """A tool held fast (six independent contact wrenches): T_f = 0, T_c = T, λ = W⁻¹ K T,
    and the freedom basis is empty; compose_twist takes only the zero twist of freedom."""
    rng = np.random.default_rng(3)
    K = stiffness(P, P.home_pose, twist_order="axis")
    for _ in range(20):
        W = rng.normal(size=(6, 6))
        T = rng.normal(size=6) * np.r_[0.01, 0.01, 0.01, 1.0, 1.0, 1.0]
        s = decompose_twist(K, W, T)
        assert np.linalg.norm(s.freedom) <= 1e-12 * np.linalg.norm(T)
        np.testing.assert_allclose(s.compliance, T, rtol=0, atol=1e-12 * np.linalg.norm(T))
        np.testing.assert_allclose(W @ s.lam, K @ T, rtol=1e-9, atol=1e-9)
        assert freedom_basis(W).shape == (6, 0)
        dw = W @ rng.normal(size=6)
        np.testing.assert_allclose(compose_twist(K, W, np.zeros(6), dw), np.linalg.solve(K, dw),
                                   rtol=1e-12, atol=1e-15)
