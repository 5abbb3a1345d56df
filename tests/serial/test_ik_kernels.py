"""The compiled IK kernels — PUMA 762 closed form and numerical IK — against the plain NumPy
reference implementations (``backend="numpy"``), on random inputs; and their building blocks
against independent computations (SciPy, SVD, LAPACK)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kinestat
from kinestat.errors import InputError, UnreachableError
from kinestat.mechanism.chain import from_modified_dh, from_standard_dh
from kinestat.robots.puma762 import closed_form as P
from kinestat.serial import _ik_kernels as K
from kinestat.serial._reference import fk_reference
from kinestat.serial.ik import ik, iter_ik, model_scale, pose_error, wrap_joints
from tests.serial._ik_checks import check_limits_respected_or_ignored

TWO_PI = 2 * math.pi


def wrap(x):
    return (np.asarray(x) + math.pi) % TWO_PI - math.pi


def q_in_limits(rng, n):
    L = np.radians(P.AXIS_LIMITS_DEG)
    return P.from_axis_angles(L[:, 0] + rng.random((n, 6)) * (L[:, 1] - L[:, 0]))


def random_rigid(rng, n, reach=1600.0):
    R = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
    R *= np.sign(np.linalg.det(R))[:, None, None]
    T = np.zeros((n, 4, 4))
    T[:, :3, :3] = R
    T[:, :3, 3] = rng.uniform(-reach, reach, (n, 3))
    T[:, 3, 3] = 1.0
    return T


# -- PUMA 762 closed form ------------------------------------------------------------------------
def assert_same_batch(a: P.ReverseBatch, b: P.ReverseBatch, *, exact_wrist: bool = True):
    """Same flags; same angles (mod 2π) where valid. At (near-)singular wrists θ4 and θ6 are
    ill-conditioned individually: there only the arm, θ5 and the family value are compared."""
    assert a.q.shape == b.q.shape and a.verified == b.verified
    for f in ("valid", "singular", "family_sum", "status"):
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
    np.testing.assert_array_equal(np.isnan(a.q), np.isnan(b.q))
    d = np.abs(wrap(a.q - b.q))
    cols = slice(None) if exact_wrist else [0, 1, 2, 4]
    assert np.nanmax(d[..., cols], initial=0.0) < 1e-9
    fv = np.abs(wrap(a.family_value - b.family_value))
    assert np.nanmax(fv, initial=0.0) < 1e-9
    np.testing.assert_array_equal(np.isnan(a.family_value), np.isnan(b.family_value))
    np.testing.assert_allclose(a.position_error, b.position_error, atol=1e-9, equal_nan=True)
    np.testing.assert_allclose(a.rotation_error, b.rotation_error, atol=1e-12, equal_nan=True)


@pytest.mark.parametrize("verify", [True, False])
def test_reverse_batch_matches_reference(verify):
    rng = np.random.default_rng(31)
    reach = P.forward(q_in_limits(rng, 3000)).pose  # reachable: all eight branches
    anywhere = random_rigid(rng, 3000)  # mostly unreachable
    # wrist centres within |a23 − S4| = 50 mm of the shoulder in the arm plane: too near
    near = random_rigid(rng, 200)
    ang = rng.uniform(-math.pi, math.pi, 200)
    W = np.c_[-P.S2 * np.sin(ang), P.S2 * np.cos(ang), rng.uniform(-49, 49, 200)]
    near[:, :3, 3] = W + P.S6 * near[:, :3, 2]
    anywhere = np.concatenate([anywhere, near])
    for T in (reach, anywhere):
        a = P.reverse_batch_pose(T, verify=verify)
        b = P.reverse_batch_pose(T, verify=verify, backend="numpy")
        assert_same_batch(a, b)
    statuses = set(P.reverse_batch_pose(anywhere).status.tolist())
    assert statuses == {P.STATUS_OK, P.STATUS_INSIDE_CYLINDER, P.STATUS_TOO_FAR,
                        P.STATUS_TOO_NEAR}


def test_reverse_batch_matches_reference_at_wrist_singularities():
    rng = np.random.default_rng(32)
    q = q_in_limits(rng, 2000)
    q[:, 4] = rng.choice([0.0, math.pi, 1e-13, 1e-11, 1e-9, math.pi - 1e-9, -1e-12], 2000)
    T = P.forward(q).pose
    a = P.reverse_batch_pose(T)
    assert_same_batch(a, P.reverse_batch_pose(T, backend="numpy"), exact_wrist=False)
    assert np.any(a.singular) and np.all(a.valid)
    # every branch, singular or not, reproduces the pose (checked by the generic chain)
    chain = kinestat.load("puma762")
    F = fk_reference(chain, a.q.reshape(-1, 6)).reshape(a.q.shape[:-1] + (4, 4))
    assert np.max(np.abs(F - T[:, None])) < 1e-9


def test_reverse_batch_from_vectors_and_shapes():
    rng = np.random.default_rng(33)
    q = q_in_limits(rng, 24).reshape(2, 3, 4, 6)
    p6 = rng.normal(0, 100, (3, 1, 3))  # broadcasts against (2, 3, 4)
    f = P.forward(q, p6)
    a = P.reverse_batch(f.tool_point, f.s6, f.a67, p6)
    b = P.reverse_batch(f.tool_point, f.s6, f.a67, p6, backend="numpy")
    assert a.q.shape == (2, 3, 4, 8, 6) and a.status.shape == (2, 3, 4)
    assert_same_batch(a, b)
    one = P.reverse_batch_pose(f.pose[0, 0, 0])
    assert one.q.shape == (8, 6) and one.status.shape == () and one.status.dtype == np.int8
    empty = P.reverse_batch_pose(np.zeros((0, 4, 4)))
    assert empty.q.shape == (0, 8, 6) and empty.valid.shape == (0, 8)


def test_iter_reverse_batch_pose_streams_the_same_answers():
    rng = np.random.default_rng(34)
    T = P.forward(q_in_limits(rng, 1000)).pose
    whole = P.reverse_batch_pose(T)
    parts = list(P.iter_reverse_batch_pose(T, chunk_rows=300))
    assert [r.start for r, _ in parts] == [0, 300, 600, 900]
    np.testing.assert_array_equal(np.concatenate([b.q for _, b in parts]), whole.q)
    np.testing.assert_array_equal(np.concatenate([b.valid for _, b in parts]), whole.valid)


def test_frame6_against_gram_schmidt():
    rng = np.random.default_rng(35)
    n = 200
    R = random_rigid(rng, n)[:, :3, :3]
    z = R[:, :, 2] * (1 + rng.uniform(-1e-7, 1e-7, (n, 1)))
    x = R[:, :, 0] + 1e-8 * rng.normal(size=(n, 3))
    p = rng.normal(0, 500, (n, 3))
    p6 = np.array([0.0, 0.0, 235.0])
    T = P.frame6(p, z, x, p6)
    zn = z / np.linalg.norm(z, axis=1, keepdims=True)
    xn = x - np.sum(x * zn, axis=1, keepdims=True) * zn
    xn /= np.linalg.norm(xn, axis=1, keepdims=True)
    Rr = np.stack([xn, np.cross(zn, xn), zn], axis=-1)
    assert np.allclose(T[:, :3, :3], Rr, atol=1e-15)
    assert np.allclose(T[:, :3, 3], p - Rr @ p6, atol=1e-12)
    assert np.allclose(T[:, 3], [0, 0, 0, 1])
    with pytest.raises(InputError, match="broadcast"):
        P.frame6(p, z[:5], x, p6)


def same_result(a: P.ReverseResult, b: P.ReverseResult):
    np.testing.assert_array_equal(a.branches, b.branches)
    assert a.solutions.shape == b.solutions.shape
    assert np.max(np.abs(wrap(a.solutions - b.solutions)), initial=0.0) < 1e-9
    assert a.reason == b.reason
    assert len(a.families) == len(b.families)
    for fa, fb in zip(a.families, b.families, strict=True):
        assert (fa.kind, fa.branch) == (fb.kind, fb.branch)
        assert abs(wrap(fa.value - fb.value)) < 1e-9
        assert abs(wrap(fa.phi1 - fb.phi1)) < 1e-9 and abs(wrap(fa.theta5 - fb.theta5)) < 1e-9
    assert_same_batch(a.batch, b.batch, exact_wrist=not a.families)


def test_reverse_single_matches_reference():
    rng = np.random.default_rng(36)
    cases = [([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0])]
    q = q_in_limits(rng, 40)
    q[:10, 4] = 0.0
    q[10:20, 4] = math.pi
    p6 = rng.normal(0, 100, (40, 3))
    f = P.forward(q, p6)
    cases += list(zip(f.tool_point, f.s6, f.a67, p6, strict=True))
    for p, z, x, t in cases:
        a = P.reverse(p, z, x, t)
        same_result(a, P.reverse(p, z, x, t, backend="numpy"))
        T = P.frame6(p, z, x, t)
        same_result(P.reverse_pose(T), P.reverse_pose(T, backend="numpy"))
        # the solutions are distinct and reproduce the pose
        assert np.allclose(P.forward(a.solutions, t).tool_point, p, atol=1e-9)
        for i in range(len(a.solutions)):
            for j in range(i):
                assert np.max(np.abs(wrap(a.solutions[i] - a.solutions[j]))) > 1e-6


@pytest.mark.parametrize(
    "args",
    [
        ([725.0, 190.0, 650.0], [1.0, 0.0, 0.1], [0.0, 0.0, 1.0]),  # not unit
        ([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 1.0, 1.0]),  # a67 not unit
        ([700.0, 0, 600], [1.0, 0, 0], [0.1, 0, 0.99498743710662]),  # not perpendicular
        ([700.0, math.nan, 600], [1.0, 0, 0], [0, 0, 1.0]),
        ([700.0, 0, 600], [1.0, 0, 0], [0, 0, 1.0], [0.0, math.inf, 0.0]),
        ([700.0, 600], [1.0, 0, 0], [0, 0, 1.0]),  # shape
        ("abc", [1.0, 0, 0], [0, 0, 1.0]),
        ([50.0, 100.0, 425.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),  # inside the S2 cylinder
        ([1500.0, 0.0, 725.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),  # too far
        ([20.0, -190.0, 125.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),  # too near
    ],
)
def test_single_errors_match_reference(args):
    errors = []
    for backend in ("numba", "numpy"):
        with pytest.raises((InputError, UnreachableError)) as ei:
            P.reverse(*args, backend=backend)
        errors.append((type(ei.value), str(ei.value)))
    assert errors[0] == errors[1]


def test_reverse_pose_errors_match_reference():
    bad = [np.diag([1.0, 1.0, -1.0, 1.0]), np.full((4, 4), np.nan), np.eye(3),
           np.diag([1.0, 1.0, 1.001, 1.0])]
    for T in bad:
        errors = []
        for backend in ("numba", "numpy"):
            with pytest.raises(InputError) as ei:
                P.reverse_pose(T, backend=backend)
            errors.append(str(ei.value))
        assert errors[0] == errors[1]
    with pytest.raises(InputError, match="backend"):
        P.reverse_batch_pose(np.eye(4), backend="fortran")


# -- numerical IK: building blocks ----------------------------------------------------------------
def test_rotvec_matches_scipy():
    rng = np.random.default_rng(41)
    axes = rng.normal(size=(400, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = np.concatenate([rng.uniform(0, math.pi, 300), [0.0, 1e-12, 1e-7, 1e-3, 2e-3],
                             math.pi - np.array([0.0, 1e-12, 1e-9, 1e-6, 1e-3]),
                             rng.uniform(0, 1e-3, 90)])
    R = Rotation.from_rotvec(angles[:, None] * axes).as_matrix()
    ref = Rotation.from_matrix(R).as_rotvec()
    got = np.array([K._rotvec(*m.ravel()) for m in R])
    # the same rotation (at π the vector's sign is arbitrary); the angle to rounding
    assert np.allclose(np.linalg.norm(got, axis=1), angles, atol=1e-12, rtol=0)
    same = Rotation.from_rotvec(got).as_matrix()
    assert np.max(np.abs(same - R)) < 1e-12
    away = angles < math.pi - 1e-6
    assert np.allclose(got[away], ref[away], atol=1e-12)


def test_nearest_rotation_is_the_polar_factor():
    rng = np.random.default_rng(42)
    for _ in range(100):
        M = np.eye(4)
        M[:3, :3] = Rotation.random(random_state=rng).as_matrix() + rng.uniform(-4e-7, 4e-7,
                                                                                 (3, 3))
        R = np.empty((3, 3))
        K._nearest_rotation(M, R)
        U, _, Vt = np.linalg.svd(M[:3, :3])
        assert np.max(np.abs(R - U @ Vt)) < 1e-14


def test_ldl_solve_matches_lapack():
    rng = np.random.default_rng(43)
    for n in (1, 2, 3, 5, 6, 7, 9):
        for _ in range(10):
            G = rng.normal(size=(n + 2, n))
            A = G.T @ G
            b = rng.normal(size=n)
            damp = 10.0 ** rng.uniform(-12, 0)
            L, x = np.tril(A).copy(), b.copy()
            assert K._ldl_solve(L, x, damp, n)
            assert np.allclose(x, np.linalg.solve(A + damp * np.eye(n), b), rtol=1e-8,
                               atol=1e-10)
    assert not K._ldl_solve(-np.eye(3), np.ones(3), 0.0, 3)  # not positive definite


def test_projection_is_wrap_joints():
    """The kernel's projection into the limits is the reference's ``wrap_joints``."""
    rng = np.random.default_rng(44)
    kinds = ["revolute", "prismatic", "screw", "revolute", "revolute", "revolute"]
    limits = [(-4.0, 4.0), (0.0, 2.0), (-1.0, 1.0), (0.35, 5.93), (-math.inf, math.inf),
              (-8.0, 8.0)]
    m = from_standard_dh(np.zeros((6, 4)), kinds, pitches=[0, 0, 0.1, 0, 0, 0], limits=limits)
    lo, hi = m.lower, m.upper
    codes = m.kind_codes
    q = rng.uniform(-15, 15, (2000, 6))
    ref = rng.uniform(-9, 9, (2000, 6))
    want = wrap_joints(m, q, ref)
    out = np.empty(6)
    for i in range(2000):
        K._project(q[i], ref[i], codes, lo, hi, True, out)
        assert np.allclose(out, want[i], atol=1e-12, rtol=0), (q[i], ref[i], out, want[i])
    K._project(q[0], ref[0], codes, lo, hi, False, out)
    np.testing.assert_array_equal(out, q[0])


def test_pose_checks_match_reference():
    m = kinestat.load("puma560")
    good = kinestat.fk(m, np.zeros((2, 3, 6)))
    flip = good.copy()
    flip[1, 2, :3, 2] *= -1  # left-handed
    row = good.copy()
    row[0, 1, 3, 0] = 1e-9
    nan = good.copy()
    nan[1, 0, 2, 3] = np.nan
    words = ("(pose (1, 2)) is not a rigid", "last row", "NaN", "shape", "shape")
    for bad, w in zip((flip, row, nan, np.eye(3), [[1, 2], [3, 4]]), words, strict=True):
        errors = []
        for backend in ("numba", "numpy"):
            with pytest.raises(InputError) as ei:
                ik(m, bad, backend=backend)
            errors.append(str(ei.value))
        assert errors[0] == errors[1] and w in errors[0]


# -- numerical IK: the kernel against the reference -----------------------------------------------
def random_chain(rng):
    n = int(rng.integers(2, 8))
    rows = np.c_[rng.uniform(-3, 3, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n),
                 rng.uniform(-3, 3, n)]
    kinds = list(rng.choice(["revolute", "prismatic", "screw"], n, p=[0.6, 0.2, 0.2]))
    pitches = [rng.uniform(-0.2, 0.2) if k == "screw" else 0.0 for k in kinds]
    limits = [(-0.5, 1.5) if k == "prismatic" else (-3.0, 3.0) for k in kinds]
    build = from_standard_dh if rng.random() < 0.5 else from_modified_dh
    return build(rows, kinds, pitches=pitches, limits=limits, length_unit="m")


def test_ik_matches_reference_from_nearby_starts():
    """Started near a solution, without restarts, both backends take the same iterations to
    the same answer (up to rounding) on random chains with all three joint kinds."""
    rng = np.random.default_rng(51)
    n_same_iter = n_total = 0
    for _ in range(25):
        m = random_chain(rng)
        q_true = m.lower + (0.1 + 0.8 * rng.random((12, m.n))) * (m.upper - m.lower)
        T = kinestat.fk(m, q_true)
        q0 = q_true + rng.normal(0, 0.02, q_true.shape)
        a = ik(m, T, q0, restarts=0)
        b = ik(m, T, q0, restarts=0, backend="numpy")
        both = a.success & b.success
        assert np.mean(both) >= 0.8
        d = np.where(m.prismatic, a.q - b.q, wrap(a.q - b.q))
        assert np.max(np.abs(d[both]), initial=0.0) < 1e-6
        n_same_iter += int(np.sum(a.iterations[both] == b.iterations[both]))
        n_total += int(np.sum(both))
        assert np.all(a.attempts == 1)
    assert n_same_iter >= 0.9 * n_total


@pytest.mark.parametrize("name", ["puma762", "puma560"])
def test_ik_success_rate_and_honesty(name):
    """Random reachable targets from one fixed start: the compiled path succeeds as often as
    the reference (≥ 99 % here), and every success is verified by the NumPy FK."""
    m = kinestat.load(name)
    rng = np.random.default_rng(52)
    q_true = m.lower + rng.random((300, 6)) * (m.upper - m.lower)
    T = kinestat.fk(m, q_true)
    a = ik(m, T)
    b = ik(m, T, backend="numpy")
    assert a.success.mean() >= 0.99 and abs(a.success.mean() - b.success.mean()) <= 0.01
    tol = 1e-9 * model_scale(m)
    pos, rot = pose_error(fk_reference(m, a.q), T)
    assert np.allclose(pos, a.position_error, atol=1e-12 * model_scale(m))
    assert np.all(pos[a.success] <= tol) and np.all(rot[a.success] <= 1e-9)
    assert np.all(m.within_limits(a.q[a.success]))
    assert np.all((pos[~a.success] > tol) | (rot[~a.success] > 1e-9)
                  | ~m.within_limits(a.q[~a.success]))
    assert a.iterations.dtype == b.iterations.dtype and a.attempts.dtype == b.attempts.dtype


def test_ik_answers_do_not_depend_on_batching_or_threads():
    m = kinestat.load("puma762")
    rng = np.random.default_rng(53)
    T = kinestat.fk(m, m.lower + rng.random((40, 6)) * (m.upper - m.lower))
    whole = ik(m, T, seed=5)
    assert np.any(whole.attempts > 1)  # restarts happened: their random streams matter
    parts = list(iter_ik(m, T, chunk_rows=7, seed=5))
    assert [r.start for r, _ in parts] == list(range(0, 40, 7))
    for f in ("q", "success", "iterations", "attempts", "position_error"):
        np.testing.assert_array_equal(np.concatenate([getattr(p, f) for _, p in parts]),
                                      getattr(whole, f))
    few = ik(m, T[:3], seed=5)  # fewer targets: the single-thread kernel
    np.testing.assert_array_equal(few.q, whole.q[:3])
    np.testing.assert_array_equal(ik(m, T, seed=5).q, whole.q)  # deterministic
    assert ik(m, T[:2], seed=None).q.shape == (2, 6)
    q0 = np.tile(m.q_home, (40, 1))
    streamed = np.concatenate([p.q for _, p in iter_ik(m, T, q0, chunk_rows=16, seed=5)])
    np.testing.assert_array_equal(streamed, whole.q)


def test_ik_limits_ignored_and_prismatic_joints():
    r2 = check_limits_respected_or_ignored()
    assert np.all((r2.q >= -math.pi) & (r2.q < math.pi))
    rpr = from_standard_dh(
        [[0, 0, 0, -math.pi / 2], [0, 0, 0, math.pi / 2], [0, 0.5, 0.2, 0]],
        kinds=["revolute", "prismatic", "revolute"],
        limits=[(-math.pi, math.pi), (0.0, 20.0), (-math.pi, math.pi)], length_unit="m")
    rng = np.random.default_rng(54)
    q_true = rpr.lower + rng.random((40, 3)) * (rpr.upper - rpr.lower)
    r = ik(rpr, kinestat.fk(rpr, q_true), q0=[0.0, 1.0, 0.0])
    assert r.success.mean() >= 0.95
    assert np.allclose(r.q[r.success, 1], q_true[r.success, 1], atol=1e-6)


def test_ik_bad_options():
    m = kinestat.load("puma560")
    T = kinestat.fk(m, m.q_home)
    with pytest.raises(InputError, match="backend"):
        ik(m, T, backend="torch")
    with pytest.raises(InputError, match="seed"):
        ik(m, T, seed=-1)
    with pytest.raises(InputError, match="chunk_rows"):
        next(iter_ik(m, T[None], chunk_rows=0))
