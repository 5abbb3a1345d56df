"""Plücker lines: construction, feet, distance, common normal, classification, errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError
from kinestat.spatial.plucker import (
    COINCIDENT,
    INTERSECTING,
    PARALLEL,
    SKEW,
    classify_lines,
    common_normal,
    is_line,
    line_distance,
    line_from_point_direction,
    line_from_points,
    mutual_moment,
    normalize_line,
    point_on_line,
    transform_line,
)
from kinestat.spatial.transforms import apply

from .strategies import poses, unit_vectors, vec3

FAST = settings(max_examples=60, deadline=None)


def _closest_points_lstsq(p1, s1, p2, s2):
    """Independent: minimise |p1 + t1 s1 - p2 - t2 s2| by least squares."""
    A = np.stack([s1, -s2], axis=1)
    t, *_ = np.linalg.lstsq(A, p2 - p1, rcond=None)
    return p1 + t[0] * s1, p2 + t[1] * s2


@FAST
@given(p1=vec3, p2=vec3)
def test_line_from_points(p1, p2):
    assume(np.linalg.norm(p2 - p1) > 1e-3)
    L = line_from_points(p1, p2)
    S, S0 = L[:3], L[3:]
    assert np.isclose(np.linalg.norm(S), 1.0)
    assert is_line(L)
    for p in (p1, p2):  # r x S = S0 for every point on the line (Vibhute eq. A-6)
        np.testing.assert_allclose(np.cross(p, S), S0, atol=1e-9)


@FAST
@given(p=vec3, s=unit_vectors(), t=st.floats(-50, 50))
def test_point_on_line_is_foot_of_perpendicular(p, s, t):
    L = line_from_point_direction(p + t * s, 3.0 * s)
    foot = point_on_line(L)
    # on the line, perpendicular to it, and the closest point to the origin
    np.testing.assert_allclose(np.cross(foot - p, s), 0.0, atol=1e-9)
    assert abs(foot @ s) <= 1e-9
    expected = p - (p @ s) * s
    np.testing.assert_allclose(foot, expected, atol=1e-9)


@FAST
@given(p1=vec3, s1=unit_vectors(), p2=vec3, s2=unit_vectors())
def test_distance_and_common_normal_against_lstsq(p1, s1, p2, s2):
    assume(np.linalg.norm(np.cross(s1, s2)) > 1e-3)
    l1, l2 = line_from_point_direction(p1, s1), line_from_point_direction(p2, s2)
    f1, f2 = _closest_points_lstsq(p1, s1, p2, s2)
    assert np.isclose(line_distance(l1, l2), np.linalg.norm(f2 - f1), atol=1e-7)
    cn = common_normal(l1, l2)
    np.testing.assert_allclose(cn.foot1, f1, atol=1e-6)
    np.testing.assert_allclose(cn.foot2, f2, atol=1e-6)
    assert abs(cn.direction @ s1) < 1e-9 and abs(cn.direction @ s2) < 1e-9
    assert np.isclose(np.linalg.norm(cn.direction), 1.0)
    # mutual moment = (r1 - r2) . (S1 x S2) = -a sin(alpha) with a = signed normal length
    mm = mutual_moment(l1, l2)
    assert np.isclose(mm, (p1 - p2) @ np.cross(s1, s2), atol=1e-7)
    n = np.cross(s1, s2) / np.linalg.norm(np.cross(s1, s2))
    a = (cn.foot2 - cn.foot1) @ n
    sin_alpha = np.cross(s1, s2) @ n
    assert np.isclose(mm, -a * sin_alpha, atol=1e-7)


@FAST
@given(p=vec3, s=unit_vectors(), T=poses())
def test_transform_line_matches_transformed_points(p, s, T):
    L = line_from_point_direction(p, s)
    expected = line_from_points(apply(T, p), apply(T, p + 5.0 * s))
    np.testing.assert_allclose(transform_line(T, L), expected, atol=1e-9)


@st.composite
def line_pairs(draw):
    """Two lines with a known relation, placed by a random rigid motion.

    Line 1 is the x axis; line 2 passes through (0, 0, a) with direction rotated by alpha about
    z from x: skew when a != 0 and alpha != 0, and so on.
    """
    kind = draw(st.sampled_from([SKEW, PARALLEL, INTERSECTING, COINCIDENT]))
    a = draw(st.floats(0.5, 50.0)) if kind in (SKEW, PARALLEL) else 0.0
    if kind in (SKEW, INTERSECTING):
        alpha = draw(st.floats(0.05, np.pi - 0.05))
    else:
        alpha = draw(st.sampled_from([0.0, np.pi]))
    t1, t2 = draw(st.floats(-20, 20)), draw(st.floats(-20, 20))
    T = draw(poses())
    s2 = np.array([np.cos(alpha), np.sin(alpha), 0.0])
    ex = np.array([1.0, 0, 0])
    l1 = line_from_point_direction(np.array([t1, 0, 0]), ex)
    l2 = line_from_point_direction(np.array([0, 0, a]) + t2 * s2, s2)
    return kind, a, alpha, T, transform_line(T, l1), transform_line(T, l2)


@settings(max_examples=120, deadline=None)
@given(case=line_pairs())
def test_classify_constructed_pairs(case):
    kind, a, alpha, T, l1, l2 = case
    res = classify_lines(l1, l2, tol=1e-7, angle_tol=1e-7)
    assert int(res.kind) == kind
    assert res.kind_name == ["skew", "parallel", "intersecting", "coincident"][kind]
    assert np.isclose(res.distance, a, atol=1e-7)
    assert np.isclose(res.angle, alpha, atol=1e-7)
    if kind in (SKEW, INTERSECTING):
        # the common normal is the z axis of the construction: feet (0,0,0) and (0,0,a)
        np.testing.assert_allclose(res.foot1, apply(T, np.zeros(3)), atol=1e-6)
        np.testing.assert_allclose(res.foot2, apply(T, np.array([0, 0, a])), atol=1e-6)
    if kind == INTERSECTING:
        np.testing.assert_allclose(res.point, apply(T, np.zeros(3)), atol=1e-6)


def test_classify_batched_and_parallel_normal():
    ex = np.array([1.0, 0, 0])
    l1 = line_from_point_direction(np.zeros(3), ex)
    l2 = np.stack([
        line_from_point_direction([0, 0, 2.0], [0, 1.0, 0]),  # skew, distance 2
        line_from_point_direction([0, 3.0, 0], -ex),  # parallel, distance 3
        line_from_point_direction([5.0, 0, 0], [0, 1.0, 0]),  # intersecting at (5, 0, 0)
        line_from_point_direction([7.0, 0, 0], -2 * ex),  # coincident, opposite sense
    ])
    res = classify_lines(l1, l2)
    assert list(res.kind_name) == ["skew", "parallel", "intersecting", "coincident"]
    np.testing.assert_allclose(res.distance, [2, 3, 0, 0], atol=1e-12)
    np.testing.assert_allclose(res.point[2], [5, 0, 0], atol=1e-12)
    cn = common_normal(l1, l2)
    np.testing.assert_allclose(cn.direction[1], [0, 1, 0], atol=1e-12)
    # coincident: some unit perpendicular to the line
    assert np.isclose(np.linalg.norm(cn.direction[3]), 1) and abs(cn.direction[3] @ ex) < 1e-12
    with pytest.raises(ValueError):
        res.distance[0] = 1.0  # results are read-only


def test_homogeneous_scaling_and_normalise():
    L = line_from_points([1.0, 2, 3], [4.0, 6, 3])
    np.testing.assert_allclose(normalize_line(-7.5 * L), -L)
    np.testing.assert_allclose(point_on_line(3 * L), point_on_line(L))


def test_errors():
    with pytest.raises(InputError, match="coincide"):
        line_from_points([1.0, 2, 3], [1.0, 2, 3])
    with pytest.raises(InputError, match=r"coincide at batch index \(1,\)"):
        line_from_points(np.zeros((2, 3)), [[1.0, 0, 0], [0, 0, 0]])
    with pytest.raises(InputError, match="zero vector"):
        line_from_point_direction([0, 0, 0], [0, 0, 0])
    with pytest.raises(InputError, match="NaN"):
        line_from_points([np.nan, 0, 0], [1, 0, 0])
    with pytest.raises(InputError, match="Plücker condition"):
        normalize_line([1, 0, 0, 1, 0, 0])
    with pytest.raises(InputError, match="zero direction"):
        point_on_line([0, 0, 0, 1, 0, 0])
    with pytest.raises(InputError, match="trailing shape"):
        classify_lines([1, 0, 0], [0, 1, 0])
