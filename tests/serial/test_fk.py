"""Forward kinematics against independent products and a peer library."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import kinestat
from kinestat.errors import InputError
from kinestat.mechanism.chain import from_modified_dh, from_standard_dh
from kinestat.serial.fk import fk_frames, joint_axes
from tests._independent import dh_matrix


def crane_duffy_matrix(alpha, a, theta, S):
    """Vibhute eq. 2-26 written out (transform from frame j to frame i)."""
    cj, sj, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([
        [cj, -sj, 0, a],
        [sj * ca, cj * ca, -sa, -sa * S],
        [sj * sa, cj * sa, ca, ca * S],
        [0, 0, 0, 1.0],
    ])


def random_table(rng, n):
    return np.c_[rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n),
                 rng.uniform(-2, 2, n), rng.uniform(-np.pi, np.pi, n)]


def test_standard_dh_matches_product_of_dh_matrices(rng):
    for _ in range(20):
        n = rng.integers(1, 9)
        rows = random_table(rng, n)
        kinds = rng.choice(["revolute", "prismatic"], n)
        m = from_standard_dh(rows, kinds)
        q = rng.uniform(-3, 3, n)
        T = np.eye(4)
        for (th, d, a, al), k, qi in zip(rows, kinds, q, strict=True):
            rev = k == "revolute"
            T = T @ (dh_matrix(th + qi, d, a, al) if rev else dh_matrix(th, d + qi, a, al))
        np.testing.assert_allclose(kinestat.fk(m, q), T, atol=1e-12)


def test_modified_dh_matches_crane_duffy_product(rng):
    m = kinestat.load("puma762")
    P = np.asarray(m.parameters)
    for _ in range(50):
        q = rng.uniform(-np.pi, np.pi, 6)
        T = np.eye(4)
        for (al, a, th, d), qi in zip(P, q, strict=True):
            T = T @ crane_duffy_matrix(al, a, th + qi, d)
        np.testing.assert_allclose(kinestat.fk(m, q), T, atol=1e-9)


def test_screw_joint_translates_with_pitch():
    m = from_standard_dh([[0, 0, 0, 0]], ["screw"], pitches=[0.5])
    T = kinestat.fk(m, [np.pi])
    np.testing.assert_allclose(T[:3, 3], [0, 0, 0.5 * np.pi], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], np.diag([-1, -1, 1]), atol=1e-12)


def test_batched_shapes_and_consistency(rng):
    m = kinestat.load("puma762")
    q = rng.uniform(-np.pi, np.pi, (3, 4, 6))
    T = kinestat.fk(m, q)
    assert T.shape == (3, 4, 4, 4)
    np.testing.assert_allclose(T[2, 1], kinestat.fk(m, q[2, 1]), atol=1e-12)
    F = fk_frames(m, q)
    assert F.shape == (3, 4, 7, 4, 4)
    np.testing.assert_allclose(F[..., -1, :, :], T, atol=1e-12)


def test_against_roboticstoolbox_puma560(rng):
    rtb = pytest.importorskip("roboticstoolbox")
    robot = rtb.models.DH.Puma560()
    rows = [[L.offset, L.d, L.a, L.alpha] for L in robot.links]
    m = from_standard_dh(rows, length_unit="m")
    ours = kinestat.load("puma560")
    for _ in range(200):
        q = rng.uniform(robot.qlim[0], robot.qlim[1])
        ref = robot.fkine(q).A
        np.testing.assert_allclose(kinestat.fk(m, q), ref, atol=1e-10)
        np.testing.assert_allclose(kinestat.fk(ours, q), ref, atol=1e-10)


def test_against_roboticstoolbox_modified_dh(rng):
    rtb = pytest.importorskip("roboticstoolbox")
    m = kinestat.load("puma762")
    P = np.asarray(m.parameters)
    links = [rtb.RevoluteMDH(alpha=al, a=a, d=d, offset=th) for al, a, th, d in P]
    robot = rtb.DHRobot(links)
    for _ in range(100):
        q = rng.uniform(-np.pi, np.pi, 6)
        np.testing.assert_allclose(kinestat.fk(m, q), robot.fkine(q).A, atol=1e-9)


@given(st.lists(st.floats(-10, 10), min_size=6, max_size=6))
def test_fk_is_rigid(q):
    T = kinestat.fk(kinestat.load("puma762"), q)
    R = T[:3, :3]
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert abs(np.linalg.det(R) - 1) < 1e-12


def test_joint_axes_are_lines_of_the_frames(rng):
    m = kinestat.load("puma560")
    q = rng.uniform(-1, 1, 6)
    u, rho = joint_axes(m, q)
    np.testing.assert_allclose(np.linalg.norm(u, axis=-1), 1, atol=1e-12)
    np.testing.assert_allclose(np.sum(u * rho, axis=-1), 0, atol=1e-12)


@pytest.mark.parametrize("bad", [[0, 0, 0], [np.nan] * 6, [[0] * 7]])
def test_bad_q(bad):
    with pytest.raises(InputError):
        kinestat.fk(kinestat.load("puma762"), bad)


def test_modified_and_standard_describe_the_same_arm(rng):
    """Standard DH of a chain rewritten in modified DH gives the same end pose."""
    rows = random_table(rng, 5)
    std = from_standard_dh(rows)
    # Craig: alpha_{i-1}, a_{i-1} move to the next link; the last link's a, alpha to the tool
    th, d, a, al = rows.T
    mod_rows = np.c_[np.r_[0, al[:-1]], np.r_[0, a[:-1]], th, d]
    tool = dh_matrix(0, 0, a[-1], al[-1])
    mod = from_modified_dh(mod_rows, tool=tool)
    q = rng.uniform(-3, 3, 5)
    np.testing.assert_allclose(kinestat.fk(std, q), kinestat.fk(mod, q), atol=1e-12)
