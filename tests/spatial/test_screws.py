"""Twists and wrenches: adjoint vs peers, power invariance, pitch and axis, errors."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError
from kinestat.spatial.plucker import line_from_point_direction, point_on_line
from kinestat.spatial.screws import (
    adjoint,
    pitch,
    power,
    reciprocal_product,
    screw_axis,
    screw_from_axis,
    screw_magnitude,
    transform_twist,
    transform_wrench,
    twist,
    wrench,
)
from kinestat.spatial.transforms import apply, apply_vector, inv

from .strategies import poses, unit_vectors, vec3

FAST = settings(max_examples=60, deadline=None)


@FAST
@given(T=poses())
def test_adjoint_against_pinocchio(T):
    """pinocchio orders motions [v; w] and forces [f; tau]."""
    M = pin.SE3(T[:3, :3], T[:3, 3])
    perm = np.r_[3:6, 0:3]
    motion = M.toActionMatrix()[np.ix_(perm, perm)]  # reorder to [w; v]
    np.testing.assert_allclose(adjoint(T), motion, atol=1e-9)
    np.testing.assert_allclose(adjoint(T), M.toDualActionMatrix(), atol=1e-9)


@FAST
@given(T=poses(), w=vec3, v=vec3, r=vec3)
def test_twist_transform_gives_point_velocities(T, w, v, r):
    """Velocity of a body point r (in B): v_B + w_B x r_B, rotated into A, must equal
    v_A + w_A x r_A computed from the transformed twist."""
    V_A = transform_twist(T, twist(w, v))
    vel_B = v + np.cross(w, r)
    vel_A = V_A[3:] + np.cross(V_A[:3], apply(T, r))
    np.testing.assert_allclose(vel_A, apply_vector(T, vel_B), atol=1e-7)


@FAST
@given(T=poses(), f=vec3, m=vec3, r=vec3)
def test_wrench_transform_gives_moments(T, f, m, r):
    """Moment about a point r: m_B - r_B x f_B in B equals the same in A."""
    W_A = transform_wrench(T, wrench(f, m))
    mom_B = m - np.cross(r, f)
    mom_A = W_A[3:] - np.cross(apply(T, r), W_A[:3])
    np.testing.assert_allclose(mom_A, apply_vector(T, mom_B), atol=1e-6)


@FAST
@given(T=poses(), V=st.tuples(vec3, vec3), W=st.tuples(vec3, vec3))
def test_power_is_frame_invariant(T, V, W):
    V, W = twist(*V), wrench(*W)
    p0 = power(V, W)
    p1 = power(transform_twist(T, V), transform_wrench(T, W))
    assert np.isclose(p0, p1, rtol=1e-9, atol=1e-6)
    # and it is the physical power: force . velocity of origin point + moment . w
    assert np.isclose(p0, W[:3] @ V[3:] + W[3:] @ V[:3])


@FAST
@given(p=vec3, s=unit_vectors(), h=st.floats(-20, 20), mag=st.floats(0.1, 10))
def test_screw_from_axis_round_trip(p, s, h, mag):
    L = line_from_point_direction(p, s)
    V = screw_from_axis(L, h, mag)
    assert np.isclose(pitch(V), h, atol=1e-9)
    assert np.isclose(screw_magnitude(V), mag)
    np.testing.assert_allclose(screw_axis(V), L, atol=1e-9)
    # points on the axis move along it only: v_P = v_O + w x P = h w
    P = point_on_line(L) + 3.0 * s
    np.testing.assert_allclose(V[3:] + np.cross(V[:3], P), h * V[:3], atol=1e-8)
    # a line is reciprocal to itself iff pitch 0: <V, V> = 2 h |w|^2
    assert np.isclose(reciprocal_product(V, V), 2 * h * mag**2, atol=1e-8)


def test_infinite_pitch_and_batch():
    L = line_from_point_direction([[1.0, 2, 3], [0, 0, 0]], [[0, 0, 2.0], [1.0, 0, 0]])
    V = screw_from_axis(L, np.array([np.inf, 0.5]), np.array([3.0, 2.0]))
    np.testing.assert_allclose(V[0], [0, 0, 0, 0, 0, 3])
    np.testing.assert_allclose(pitch(V), [np.inf, 0.5])
    np.testing.assert_allclose(screw_magnitude(V), [3.0, 2.0])
    ax = screw_axis(V)
    np.testing.assert_allclose(ax[0], [0, 0, 1, 0, 0, 0])  # through the origin by convention
    np.testing.assert_allclose(ax[1], L[1])


@FAST
@given(T=poses(), p=vec3, s=unit_vectors(), h=st.floats(-5, 5))
def test_axis_and_pitch_are_frame_covariant(T, p, s, h):
    V = screw_from_axis(line_from_point_direction(p, s), h, 2.0)
    V_A = transform_twist(T, V)
    assert np.isclose(pitch(V_A), h, atol=1e-9)
    P_A = apply(T, p)
    np.testing.assert_allclose(screw_axis(V_A), line_from_point_direction(P_A, apply_vector(T, s)),
                               atol=1e-8)
    # transforming back with the inverse pose recovers the twist
    np.testing.assert_allclose(transform_twist(inv(T), V_A), V, atol=1e-8)


def test_errors():
    with pytest.raises(InputError, match="zero screw"):
        pitch(np.zeros(6))
    with pytest.raises(InputError, match=r"zero.*batch index \(1,\)"):
        screw_axis(np.array([[1.0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0]]))
    with pytest.raises(InputError, match="NaN"):
        screw_from_axis([0, 0, 1, 0, 0, 0], np.nan)
    with pytest.raises(InputError, match="NaN"):
        twist([np.nan, 0, 0], [0, 0, 0])
    with pytest.raises(InputError, match=r"T must be .*shape \(\.\.\., 4, 4\)"):
        adjoint(np.eye(3))
