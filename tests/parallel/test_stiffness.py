"""Spatial stiffness (Vibhute eq. 2-17): finite differences, symmetry, load asymmetry."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.errors import InputError, UnreachableError
from kinestat.io.library import prototype
from kinestat.parallel._refine import apply_twist
from kinestat.parallel.statics import forces_from_wrench, line_jacobian, spring_wrench
from kinestat.parallel.stiffness import (
    equilibrium_pose,
    load_asymmetry,
    stiffness,
    stiffness_terms,
)


def fd_stiffness(p, T, h=1e-5):
    """Central differences of the spring wrench along ray-order twists [δx; δφ]."""
    K = np.zeros((6, 6))
    for i in range(6):
        D = np.zeros(6)
        D[i] = h
        tw = np.r_[D[3:], D[:3]]
        K[:, i] = (spring_wrench(p, apply_twist(T, tw)) - spring_wrench(p, apply_twist(T, -tw)))
        K[:, i] /= 2 * h
    return K


POSES = {
    "home (unloaded)": np.zeros(6),
    "pushed down": np.r_[0, 0, 0, 0, 0, -2.0],
    "twisted and shifted": np.r_[0.05, -0.03, 0.08, 1.5, -2.0, 3.0],
    "tilted": np.r_[-0.07, 0.06, -0.02, -2.5, 1.0, -1.5],
}


@pytest.mark.parametrize("name", list(POSES))
def test_stiffness_equals_finite_differences(name):
    p = prototype()
    T = apply_twist(p.home_pose, POSES[name])
    K, Kfd = stiffness(p, T), fd_stiffness(p, T)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(Kfd).max()


def test_symmetric_unloaded_nonsymmetric_loaded():
    p = prototype()
    K0 = stiffness(p, p.home_pose)
    assert np.abs(K0 - K0.T).max() <= 1e-12 * np.abs(K0).max()
    T = apply_twist(p.home_pose, POSES["twisted and shifted"])
    K = stiffness(p, T)
    assert np.abs(K - K.T).max() > 1e-3 * np.abs(K).max()
    # the asymmetry is fixed by the load alone
    np.testing.assert_allclose(K - K.T, load_asymmetry(spring_wrench(p, T)),
                               atol=1e-9 * np.abs(K).max())


def test_unloaded_stiffness_is_j_k_jT():
    p = prototype()
    j = line_jacobian(p, p.home_pose)
    np.testing.assert_allclose(stiffness(p, p.home_pose), j @ np.diag(p.stiffness) @ j.T,
                               atol=1e-9)


def test_geometric_term_is_eq_2_17_angle_derivatives():
    """The symmetric load term equals Σ k(1−ρ) (jφ jφᵀ + jψ jψᵀ), jφ, jψ the derivatives of each
    leg's Plücker coordinates w.r.t. two angles of its direction, base point held (eq. 2-17)."""
    p = prototype()
    T = apply_twist(p.home_pose, POSES["tilted"])
    terms = stiffness_terms(p, T)
    X = T[:3, :3] @ p.top_points.T
    X = X.T + T[:3, 3]
    d = X - p.base_points
    l = np.linalg.norm(d, axis=1)
    rho = p.free_lengths / l
    G = np.zeros((6, 6))
    h = 1e-6
    for i in range(6):
        B = p.base_points[i]
        phi, psi = np.arctan2(d[i, 1], d[i, 0]), np.arccos(d[i, 2] / l[i])

        def line(a, b, B=B):
            S = np.array([np.sin(b) * np.cos(a), np.sin(b) * np.sin(a), np.cos(b)])
            return np.r_[S, np.cross(B, S)]

        jphi = (line(phi + h, psi) - line(phi - h, psi)) / (2 * h) / np.sin(psi)
        jpsi = (line(phi, psi + h) - line(phi, psi - h)) / (2 * h)
        G += p.stiffness[i] * (1 - rho[i]) * (np.outer(jphi, jphi) + np.outer(jpsi, jpsi))
    np.testing.assert_allclose(terms["geometric"], G, atol=1e-6 * np.abs(G).max())


def test_stiffness_under_a_given_load():
    """Forces from j⁻¹ w at the equilibrium pose of w give the springs' own stiffness there."""
    p = prototype()
    w = np.r_[1.0, -2.0, -8.0, 40.0, 25.0, -10.0]
    T = equilibrium_pose(p, w)
    np.testing.assert_allclose(spring_wrench(p, T), w, atol=1e-8)
    f = forces_from_wrench(p, T, w)
    np.testing.assert_allclose(stiffness(p, T, f), stiffness(p, T), atol=1e-8)
    K = stiffness(p, p.home_pose, forces_from_wrench(p, p.home_pose, w))
    np.testing.assert_allclose(K - K.T, load_asymmetry(w), atol=1e-9)


def test_axis_order_swaps_columns():
    p = prototype()
    T = apply_twist(p.home_pose, POSES["tilted"])
    Kr, Ka = stiffness(p, T), stiffness(p, T, twist_order="axis")
    np.testing.assert_allclose(Ka, np.c_[Kr[:, 3:], Kr[:, :3]])
    with pytest.raises(InputError):
        stiffness(p, T, twist_order="xyz")


def test_batched_stiffness():
    p = prototype()
    rng = np.random.default_rng(0)
    T = apply_twist(np.broadcast_to(p.home_pose, (5, 4, 4)),
                    rng.normal(size=(5, 6)) * np.r_[0.03, 0.03, 0.03, 1, 1, 1])
    K = stiffness(p, T)
    assert K.shape == (5, 6, 6)
    np.testing.assert_allclose(K[3], stiffness(p, T[3]))


def test_equilibrium_refuses_an_impossible_load():
    with pytest.raises(UnreachableError):
        equilibrium_pose(prototype(), [0, 0, -1e7, 0, 0, 0], max_iter=10)
