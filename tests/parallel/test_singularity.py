"""Singular poses and architecturally singular designs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinestat.errors import ModelError
from kinestat.io.library import prototype
from kinestat.parallel._refine import apply_twist, refine
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import Platform, special_6_6, triangle_points
from kinestat.parallel.singularity import (
    check_design,
    is_architecturally_singular,
    reduction_conditioning,
    singularity_measure,
)


def _midpoint_platform():
    """The Griffis–Duffy layout with every edge point at its edge's midpoint, built by hand."""
    b, t = triangle_points(120.0), triangle_points(60.0)
    base = np.array([b[0], b[1], b[2], (b[2] + b[0]) / 2, (b[0] + b[1]) / 2, (b[1] + b[2]) / 2])
    top = np.array([(t[0] + t[1]) / 2, (t[1] + t[2]) / 2, (t[2] + t[0]) / 2, t[0], t[1], t[2]])
    home = prototype().home_pose
    return Platform(base_points=base, top_points=top, stiffness=np.full(6, 2.627),
                    free_lengths=np.full(6, 70.0), home_pose=home, name="midpoints")


def test_midpoint_layout_has_a_self_motion():
    q = _midpoint_platform()
    rng = np.random.default_rng(0)
    T = apply_twist(np.broadcast_to(q.home_pose, (20, 4, 4)),
                    rng.normal(size=(20, 6)) * np.r_[0.3, 0.3, 0.3, 10, 10, 10])
    assert np.all(singularity_measure(q, T) < 1e-12)  # singular at every pose
    # a self-motion: follow the null space of jᵀ from home; the leg lengths do not change
    pose = q.home_pose
    L0 = leg_lengths(q, pose)
    from kinestat.parallel.statics import line_jacobian

    v_prev = None
    for _ in range(100):  # predictor (null space of jᵀ) + corrector (Newton on the legs)
        _, _, vt = np.linalg.svd(line_jacobian(q, pose).T)  # δl = jᵀ [δx; δφ]
        v = vt[-1] if v_prev is None or vt[-1] @ v_prev > 0 else -vt[-1]
        v_prev = v
        pose = apply_twist(pose, 0.02 * np.r_[v[3:], v[:3]])
        pose, _ = refine(q.base_points, q.top_points, L0, pose, iterations=2)
    moved = np.abs(pose - q.home_pose).max()
    assert moved > 0.5
    np.testing.assert_allclose(leg_lengths(q, pose), L0, atol=1e-9)
    assert is_architecturally_singular(q)
    with pytest.raises(ModelError, match="architecturally singular"):
        check_design(q)


def test_builder_refuses_singular_layouts():
    with pytest.raises(ModelError, match="midpoint"):
        special_6_6(base_offset=60.0, top_offset=30.0)
    # not midpoints, but prod(1 - t) = prod(t): 0.7 on the base edges, 0.3 on the top edges
    with pytest.raises(ModelError, match="architecturally singular"):
        special_6_6(base_offset=0.7 * 120, top_offset=0.3 * 60)


def test_prototype_is_fine():
    p = prototype()
    assert reduction_conditioning(p.layout.t) > 0.1
    assert not is_architecturally_singular(p)
    assert singularity_measure(p, p.home_pose) > 0.1


def test_singular_home_pose_is_refused():
    with pytest.raises(ModelError, match="home pose"):
        special_6_6(twist=math.radians(30.0))
