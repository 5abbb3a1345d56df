"""Screw axis of a finite displacement (Nadkarni ch. III): round trips, conventions, invariants,
independent routes (the thesis's own equations, the matrix exponential, pinocchio), the
thesis's Illustration 1 and bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

from kinestat.errors import InputError
from kinestat.spatial.displacement import (
    frame_from_points,
    frame_from_triple,
    interpolate_screw,
    pose_from_screw,
    relative_displacement,
    screw_from_displacement,
    screw_from_points,
    screw_from_poses,
    screws_between,
)
from kinestat.spatial.screws import twist_matrix
from kinestat.spatial.transforms import apply, inv, make_pose, trans

from .strategies import poses, unit_vectors, vec3

# Nadkarni 1977, Appendix II, Illustration 1 (Table A2-1): three positions of a body, each by
# three points (origin, a point on +z, a point in the z-x half plane), 2 decimals.
ILLUSTRATION_1 = np.array([
    [[25.00, 0.00, 20.00], [30.00, 0.00, 20.00], [25.00, 0.00, 10.00]],
    [[-20.30, -7.83, -6.66], [-20.65, -8.29, -5.85], [-21.06, -7.18, -6.62]],
    [[-24.50, 5.30, 4.00], [-24.67, 5.47, 4.97], [-25.00, 6.00, 4.00]],
])

angles = st.one_of(
    st.floats(-np.pi, np.pi),
    st.sampled_from([0.0, np.pi, -np.pi, np.pi - 1e-12, -np.pi + 1e-9, 1e-300]),
    st.floats(1e-14, 1e-6).flatmap(lambda a: st.sampled_from([a, -a])),
    st.floats(np.pi - 1e-6, np.pi),
)


@st.composite
def displacements(draw):
    """(D, u, theta, rho, d): a screw displacement built directly from its parameters."""
    u = draw(unit_vectors())
    theta = draw(angles)
    c = draw(vec3)
    d = draw(st.one_of(st.floats(-100, 100), st.just(0.0)))
    Q = Rotation.from_rotvec(theta * u).as_matrix()
    q = c - Q @ c + d * u  # rotation about the line through c, then translation along u
    return make_pose(Q, q), u, theta, c, d


ROUND_TRIP = settings(max_examples=300, deadline=None)


@ROUND_TRIP
@given(T1=poses(), disp=displacements())
def test_round_trip_and_conventions(T1, disp):
    D = disp[0]
    T2 = D @ T1
    sc = screw_from_poses(T1, T2)
    np.testing.assert_allclose(sc.pose() @ T1, T2, atol=1e-9)
    np.testing.assert_allclose(
        pose_from_screw(sc.axis, sc.point, sc.theta, sc.d), relative_displacement(T1, T2),
        atol=1e-9,
    )
    u = sc.axis
    assert np.isclose(np.linalg.norm(u), 1.0)
    assert u[2] >= -1e-12
    if abs(u[2]) <= 1e-12:
        assert u[1] >= -1e-12
    assert -np.pi < sc.theta <= np.pi
    assert abs(sc.point @ u) <= 1e-9 * max(1.0, np.linalg.norm(sc.point))
    if sc.is_translation:
        assert sc.theta == 0.0 and np.isinf(sc.pitch)
    else:
        assert np.isclose(sc.pitch, sc.d / sc.theta)


@ROUND_TRIP
@given(disp=displacements())
def test_recovers_the_constructed_screw(disp):
    D, u, theta, c, d = disp
    sc = screw_from_displacement(D)
    if abs(theta) <= 1e-12 or abs(theta) > np.pi - 1e-9:
        return  # translation, or a half turn (either sense)
    # same screw up to the sign convention (u, theta, d) -> (-u, -theta, -d)
    s = np.sign(sc.axis @ u)
    np.testing.assert_allclose(s * sc.axis, u, atol=1e-9 / abs(theta))
    assert np.isclose(s * sc.theta, theta, atol=1e-12)
    if abs(theta) > 1e-6:
        assert np.isclose(s * sc.d, d, atol=1e-9)
        foot = c - (c @ u) * u
        np.testing.assert_allclose(sc.point, foot, atol=1e-8 / abs(np.sin(theta / 2)))


@settings(max_examples=100, deadline=None)
@given(disp=displacements(), X=st.lists(vec3, min_size=3, max_size=3))
def test_screw_invariants(disp, X):
    """Every body point's displacement projects on u equally (= d); points on the axis move by
    d u only; distances are preserved."""
    D = disp[0]
    sc = screw_from_displacement(D)
    X1 = np.array(X)
    X2 = apply(D, X1)
    np.testing.assert_allclose((X2 - X1) @ sc.axis, sc.d, atol=1e-9)
    if not sc.is_translation:
        on_axis = sc.point + np.array([[-7.0], [0.0], [13.0]]) * sc.axis
        np.testing.assert_allclose(apply(D, on_axis) - on_axis, np.tile(sc.d * sc.axis, (3, 1)),
                                   atol=1e-8)
    Dr = sc.pose()
    Y = apply(Dr, X1)
    for i, j in [(0, 1), (1, 2), (0, 2)]:
        assert np.isclose(np.linalg.norm(Y[i] - Y[j]), np.linalg.norm(X1[i] - X1[j]), atol=1e-9)


@settings(max_examples=100, deadline=None)
@given(disp=displacements())
def test_twist_exponential_and_pinocchio_log(disp):
    """expm of the screw's twist is D (scipy.linalg.expm), and the twist is pinocchio's log6
    (reordered [w; v]) except at a half turn, where the sense is a convention."""
    D = disp[0]
    sc = screw_from_displacement(D)
    np.testing.assert_allclose(expm(twist_matrix(sc.twist)), D, atol=1e-9)
    if abs(sc.theta) < np.pi - 1e-6 and np.linalg.norm(sc.twist) < 1e6:
        nu = pin.log6(pin.SE3(D[:3, :3], D[:3, 3])).vector
        np.testing.assert_allclose(sc.twist, np.r_[nu[3:], nu[:3]], atol=1e-7)


@settings(max_examples=100, deadline=None)
@given(disp=displacements())
def test_agrees_with_thesis_equations(disp):
    """Nadkarni's own route: u from (3-27)/(3-28) (least squares), rho_n and d from the 4x4
    system (3-41), cos from (3-50)/(3-51) and sin from (3-52) (u3 != 0, well away from 0 and
    pi)."""
    D, u_true, theta_true, _, _ = disp
    if not (0.05 < abs(theta_true) < np.pi - 0.05 and abs(u_true[2]) > 0.2):
        return
    Q, q = D[:3, :3], D[:3, 3]
    A = np.array([[Q[0, 0] - 1, Q[1, 0]], [Q[0, 1], Q[1, 1] - 1], [Q[0, 2], Q[1, 2]]])
    rhs = -np.array([Q[2, 0], Q[2, 1], Q[2, 2] - 1])
    u1p, u2p = np.linalg.lstsq(A, rhs, rcond=None)[0]
    u3 = 1.0 / np.sqrt(u1p**2 + u2p**2 + 1.0)  # corrected (3-28): a square root
    u = np.array([u1p * u3, u2p * u3, u3])
    M = np.zeros((4, 4))
    M[:3, :3] = Q - np.eye(3)
    M[:3, 3] = -u
    M[3, :3] = u
    rho1, rho2, rho3, d = np.linalg.solve(M, np.r_[-q, 0.0])
    i = np.argmin(np.abs(u))  # the best conditioned of (3-50), (3-51)
    cos = (Q[i, i] - u[i] ** 2) / (1 - u[i] ** 2)
    sin = (u[0] * u[1] * (1 - cos) - Q[0, 1]) / u[2]
    sc = screw_from_displacement(D)
    np.testing.assert_allclose(sc.axis, u, atol=1e-9)
    np.testing.assert_allclose(sc.point, [rho1, rho2, rho3], atol=1e-7)
    assert np.isclose(sc.d, d, atol=1e-8)
    assert np.isclose(sc.theta, np.arctan2(sin, cos), atol=1e-9)


def test_special_cases():
    ident = screw_from_poses(np.eye(4), np.eye(4))
    assert ident.is_translation and ident.theta == 0.0 and ident.d == 0.0
    np.testing.assert_array_equal(ident.axis, [0, 0, 1])
    np.testing.assert_array_equal(ident.point, [0, 0, 0])
    assert np.isinf(ident.pitch)

    down = screw_from_displacement(trans([0.0, 0.0, -5.0]))  # u3 < 0 is flipped: d < 0
    assert down.is_translation
    np.testing.assert_allclose(down.axis, [0, 0, 1])
    assert down.d == -5.0 and down.theta == 0.0 and np.isinf(down.pitch)

    diag = screw_from_displacement(trans([3.0, -4.0, 0.0]))  # u3 = 0: then u2 >= 0
    np.testing.assert_allclose(diag.axis, [-0.6, 0.8, 0.0])
    assert diag.d == -5.0

    # half turn about the x axis through (0, 2, 0): u3 = u2 = 0, so u1 > 0 and theta = +pi
    D = make_pose(Rotation.from_rotvec([-np.pi, 0, 0]).as_matrix(), [0, 4.0, 0])
    half = screw_from_displacement(D)
    np.testing.assert_allclose(half.axis, [1, 0, 0])
    assert half.theta == np.pi
    np.testing.assert_allclose(half.point, [0, 2, 0], atol=1e-12)

    # quarter turn about -y: reported about +y with theta = -pi/2 and d flipped
    D = make_pose(Rotation.from_rotvec([0, -np.pi / 2, 0]).as_matrix(), [0, -3.0, 0])
    qt = screw_from_displacement(D)
    np.testing.assert_allclose(qt.axis, [0, 1, 0], atol=1e-15)
    assert np.isclose(qt.theta, -np.pi / 2) and np.isclose(qt.d, -3.0)
    assert np.isclose(qt.angle_deg, -90.0)

    # tiny rotation with a sideways translation: a real (far) axis, still exact round trip
    D = make_pose(Rotation.from_rotvec([0, 0, 1e-9]).as_matrix(), [1.0, 0, 0.5])
    tiny = screw_from_displacement(D)
    assert not tiny.is_translation
    np.testing.assert_allclose(tiny.axis, [0, 0, 1], atol=1e-6)
    assert np.linalg.norm(tiny.point) > 1e8
    np.testing.assert_allclose(tiny.pose(), D, atol=1e-12)
    np.testing.assert_allclose(tiny.d, 0.5)


def test_frame_from_points_eqs_3_1_to_3_3():
    rng = np.random.default_rng(5)
    p1, p2, p3 = rng.normal(size=(3, 3)) * 10
    T = frame_from_points(p1, p2, p3)
    R = T[:3, :3]
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(R), 1.0)
    np.testing.assert_allclose(T[:3, 3], p1)
    local2, local3 = apply(inv(T), p2), apply(inv(T), p3)
    np.testing.assert_allclose(local2[:2], 0, atol=1e-12)  # p2 on +z
    assert local2[2] > 0
    assert abs(local3[1]) < 1e-12 and local3[0] > 0  # p3 in the z-x half plane, x > 0
    # points 2' on +z and 3' in the same half plane give the same frame (Nadkarni p. 17)
    T2 = frame_from_points(p1, p1 + 0.3 * (p2 - p1), p3 + 2.0 * (p2 - p1))
    np.testing.assert_allclose(T2, T, atol=1e-12)
    # batched triples
    Tb = frame_from_triple(np.stack([np.stack([p1, p2, p3])] * 4))
    assert Tb.shape == (4, 4, 4)


def test_screws_between_and_interpolation():
    rng = np.random.default_rng(9)
    P = np.stack([make_pose(Rotation.from_rotvec(rng.normal(size=3)).as_matrix(),
                            rng.normal(size=3) * 10) for _ in range(5)])
    sc = screws_between(P)
    assert sc.shape == (4,)
    for i in range(4):
        one = screw_from_poses(P[i], P[i + 1])
        np.testing.assert_allclose(sc[i].axis, one.axis)
        np.testing.assert_allclose(sc.pose()[i] @ P[i], P[i + 1], atol=1e-9)
    T1, T2 = P[0], P[1]
    s = np.linspace(0, 1, 5)
    path = interpolate_screw(T1, T2, s)
    assert path.shape == (5, 4, 4)
    np.testing.assert_allclose(path[0], T1, atol=1e-12)
    np.testing.assert_allclose(path[-1], T2, atol=1e-9)
    # equal steps: each step is the same displacement (a screw motion is a one-parameter
    # subgroup), and it is pinocchio's exp6(s * log6(D)).
    steps = path[1:] @ inv(path[:-1])
    np.testing.assert_allclose(steps, np.broadcast_to(steps[0], steps.shape), atol=1e-9)
    D = relative_displacement(T1, T2)
    nu = pin.log6(pin.SE3(D[:3, :3], D[:3, 3])).vector
    half = pin.exp6(0.5 * nu).homogeneous
    np.testing.assert_allclose(path[2], half @ T1, atol=1e-9)


def test_illustration_1():
    """Nadkarni Appendix II, Illustration 1 (MS = 1). The published results are withheld; check
    against the thesis's own equations solved independently, and for self-consistency."""
    F = frame_from_triple(ILLUSTRATION_1)
    sc = screws_between(F)
    assert sc.shape == (2,)
    # the screws carry each body frame onto the next
    np.testing.assert_allclose(sc.pose() @ F[:-1], F[1:], atol=1e-12)
    # the composition of the two displacements is the direct displacement 1 -> 3
    direct = screw_from_poses(F[0], F[2])
    np.testing.assert_allclose(sc.pose()[1] @ sc.pose()[0], direct.pose(), atol=1e-12)
    # Chasles: the data's point 1 (each frame's origin) moves along u by exactly d
    for k in range(2):
        step = ILLUSTRATION_1[k + 1, 0] - ILLUSTRATION_1[k, 0]
        assert np.isclose(step @ sc[k].axis, sc[k].d, atol=1e-12)
    # independent route (the thesis's equations) for both screws
    for k in range(2):
        D = relative_displacement(F[k], F[k + 1])
        Q, q = D[:3, :3], D[:3, 3]
        w, V = np.linalg.eig(Q.T)
        u = np.real(V[:, np.argmin(np.abs(w - 1))])
        u = u * np.sign(u[2]) / np.linalg.norm(u)
        M = np.zeros((4, 4))
        M[:3, :3] = Q - np.eye(3)
        M[:3, 3] = -u
        M[3, :3] = u
        x = np.linalg.solve(M, np.r_[-q, 0.0])
        cos = (Q[2, 2] - u[2] ** 2) / (1 - u[2] ** 2)
        sin = (u[0] * u[1] * (1 - cos) - Q[0, 1]) / u[2]
        np.testing.assert_allclose(sc[k].axis, u, atol=1e-12)
        np.testing.assert_allclose(sc[k].point, x[:3], atol=1e-10)
        assert np.isclose(sc[k].d, x[3], atol=1e-10)
        assert np.isclose(sc[k].theta, np.arctan2(sin, cos), atol=1e-12)
    # same answer straight from the point triples
    sp = screw_from_points(ILLUSTRATION_1[:-1], ILLUSTRATION_1[1:])
    np.testing.assert_allclose(sp.axis, sc.axis)


def test_bad_input():
    with pytest.raises(InputError, match="points 1 and 2 coincide"):
        frame_from_points([1.0, 2, 3], [1.0, 2, 3], [0, 0, 0])
    with pytest.raises(InputError, match="points 1 and 3 coincide"):
        frame_from_points([1.0, 2, 3], [0, 0, 0], [1.0, 2, 3])
    with pytest.raises(InputError, match="points 2 and 3 coincide"):
        frame_from_points([1.0, 2, 3], [0, 0, 0], [0, 0, 0])
    with pytest.raises(InputError, match="collinear"):
        frame_from_points([0, 0, 0], [0, 0, 1.0], [0, 0, -4.0])
    with pytest.raises(InputError, match=r"collinear at batch index \(1,\)"):
        frame_from_triple([np.eye(3), [[0, 0, 0], [1, 1, 1], [2, 2, 2.0]]])
    with pytest.raises(InputError, match="NaN"):
        frame_from_points([np.nan, 0, 0], [0, 0, 1.0], [1.0, 0, 0])
    with pytest.raises(InputError, match="NaN"):
        screw_from_poses(np.full((4, 4), np.nan), np.eye(4))
    skewed = np.eye(4)
    skewed[0, 1] = 0.1
    with pytest.raises(InputError, match="pose 2 is not a rigid pose"):
        screw_from_poses(np.eye(4), skewed)
    mirror = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(InputError, match="pose 1 is not a rigid pose"):
        screw_from_poses(mirror, np.eye(4))
    bottom = np.eye(4)
    bottom[3, 0] = 1.0
    with pytest.raises(InputError, match="last row"):
        screw_from_poses(np.eye(4), bottom)
    with pytest.raises(InputError, match="at least two poses"):
        screws_between(np.eye(4)[None])
    with pytest.raises(InputError, match="zero vector"):
        pose_from_screw([0, 0, 0], [0, 0, 0], 1.0, 0.0)
    with pytest.raises(InputError, match="trailing shape"):
        screw_from_points(np.zeros((3, 2)), np.zeros((3, 2)))
