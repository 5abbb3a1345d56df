"""Statics: leg lines, line Jacobian, forces <-> wrench (Vibhute eqs. 2-2 to 2-8)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinestat.errors import InputError, SingularityError
from kinestat.io.library import prototype
from kinestat.parallel._refine import apply_twist
from kinestat.parallel.legs import leg_lengths, top_points_in_base
from kinestat.parallel.singularity import singularity_measure
from kinestat.parallel.statics import (
    forces_from_wrench,
    jacobian_det,
    leg_lines,
    line_jacobian,
    spring_forces,
    spring_wrench,
    wrench_from_forces,
    wrench_from_leg_lengths,
)
from kinestat.spatial.transforms import make_pose, rot_z


def loaded_pose(seed=0):
    rng = np.random.default_rng(seed)
    return apply_twist(prototype().home_pose, rng.normal(size=6) * np.r_[0.04, 0.04, 0.04, 2, 2, 2])


def test_leg_lines_are_plucker_lines():
    p = prototype()
    lines = leg_lines(p, loaded_pose())
    S, S0 = lines[..., :3], lines[..., 3:]
    np.testing.assert_allclose(np.linalg.norm(S, axis=-1), 1.0, atol=1e-15)
    np.testing.assert_allclose(np.sum(S * S0, axis=-1), 0.0, atol=1e-12)  # eq. A-8
    # the moment about O0 is the same from either end of the leg (eq. A-7)
    X = top_points_in_base(p, loaded_pose())
    np.testing.assert_allclose(np.cross(X, S), S0, atol=1e-12)
    np.testing.assert_allclose(line_jacobian(p, loaded_pose()), np.swapaxes(lines, -1, -2))


def test_forward_statics_sums_forces_and_moments():
    """w = j f equals Σ f_i S_i and Σ X_i × (f_i S_i) computed from the top points."""
    p = prototype()
    T = loaded_pose(1)
    f = np.array([3.0, -1.0, 2.5, 0.5, -4.0, 1.0])
    X = top_points_in_base(p, T)
    S = (X - p.base_points) / leg_lengths(p, T)[:, None]
    F = (f[:, None] * S).sum(axis=0)
    M = np.cross(X, f[:, None] * S).sum(axis=0)
    np.testing.assert_allclose(wrench_from_forces(p, T, f), np.r_[F, M], atol=1e-12)


def test_reverse_statics_inverts_forward():
    p = prototype()
    T = np.stack([loaded_pose(s) for s in range(4)])
    w = np.random.default_rng(0).normal(size=(4, 6)) * np.r_[5, 5, 5, 100, 100, 100]
    f = forces_from_wrench(p, T, w)
    np.testing.assert_allclose(wrench_from_forces(p, T, f), w, atol=1e-9)


def test_external_wrench_is_the_gradient_of_spring_energy():
    """The convention: w·δD (δD = [δx; δφ]) is the work done on the springs, U = ½ Σ k (l − l0)²."""
    p = prototype()
    T = loaded_pose(2)

    def U(pose):
        return 0.5 * np.sum(p.stiffness * (leg_lengths(p, pose) - p.free_lengths) ** 2)

    h = 1e-6
    grad = []
    for i in range(6):  # ray order: translation then rotation
        D = np.zeros(6)
        D[i] = h
        tw = np.r_[D[3:], D[:3]]
        grad.append((U(apply_twist(T, tw)) - U(apply_twist(T, -tw))) / (2 * h))
    np.testing.assert_allclose(spring_wrench(p, T), grad, rtol=1e-6, atol=1e-8)


def test_sign_convention_pushing_down_compresses():
    p = prototype()
    T = p.home_pose.copy()
    T[2, 3] -= 1.0  # the top pushed 1 mm toward the base
    f = spring_forces(p, leg_lengths(p, T))
    assert np.all(f < 0)  # compression
    w = spring_wrench(p, T)
    assert w[2] < 0  # the external force that holds it there points down
    np.testing.assert_allclose(spring_wrench(p, p.home_pose), 0.0, atol=1e-12)


def test_chain_from_leg_lengths():
    p = prototype()
    T = loaded_pose(3)
    pose, w = wrench_from_leg_lengths(p, leg_lengths(p, T), p.home_pose)
    np.testing.assert_allclose(pose, T, atol=1e-9)
    np.testing.assert_allclose(w, spring_wrench(p, T), atol=1e-9)
    f = np.array([1.0, 2.0, 3.0, -1.0, -2.0, -3.0])  # e.g. measured by calibrated sensors
    _, w2 = wrench_from_leg_lengths(p, leg_lengths(p, T), p.home_pose, forces=f)
    np.testing.assert_allclose(w2, wrench_from_forces(p, T, f), atol=1e-9)


def _singular_pose():
    # the home layout turned by +30° instead of −60° about the vertical: the six leg lines
    # are linearly dependent (found by scanning det j over the twist angle)
    p = prototype()
    base_c = p.base_points[:3].mean(axis=0)
    top_c = p.top_points[3:].mean(axis=0)
    R = rot_z(math.radians(30.0))[:3, :3]
    return make_pose(R, base_c + [0, 0, 60.0] - R @ top_c)


def test_singular_pose_is_refused():
    p = prototype()
    T = _singular_pose()
    assert singularity_measure(p, T) < 1e-9
    assert abs(jacobian_det(p, T)) < 1e-6 * abs(jacobian_det(p, p.home_pose))
    with pytest.raises(SingularityError, match="singular"):
        forces_from_wrench(p, T, [0, 0, -10, 0, 0, 0])


def test_bad_wrench_input():
    p = prototype()
    with pytest.raises(InputError):
        forces_from_wrench(p, p.home_pose, [1, 2, 3])
    with pytest.raises(InputError):
        forces_from_wrench(p, p.home_pose, [np.nan, 0, 0, 0, 0, 0])
