"""PUMA 762 closed form (Vibhute 2011 §2.2): forward against independent products, reverse
against the forward analysis, the generic chain and Crane's own formulation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import kinestat
from kinestat.errors import InputError, JointLimitError, UnreachableError
from kinestat.robots.puma762 import closed_form as P
from kinestat.spatial.transforms import rot_x, rot_z, trans_x, trans_z

TWO_PI = 2 * math.pi


def wrap(x):
    return (np.asarray(x) + math.pi) % TWO_PI - math.pi


def random_axis_in_limits(rng, n, limits_deg=P.AXIS_LIMITS_DEG):
    L = np.radians(np.asarray(limits_deg))
    return L[:, 0] + rng.random((n, 6)) * (L[:, 1] - L[:, 0])


def random_q_in_limits(rng, n, limits_deg=P.AXIS_LIMITS_DEG):
    return P.from_axis_angles(random_axis_in_limits(rng, n, limits_deg))


@pytest.fixture(scope="module")
def chain():
    return kinestat.load("puma762")


# -- forward ---------------------------------------------------------------------------------
@settings(max_examples=30, deadline=None)
@given(st.floats(-10, 10), st.integers(0, 4))
def test_link_transform_is_eq_2_26(theta, k):
    """Eq. 2-26 written out equals the product Rx(α) Tx(a) Rz(θ) Tz(S)."""
    al = math.radians(P.ALPHA_DEG[k])
    ref = rot_x(al) @ trans_x(P._A[k]) @ rot_z(theta) @ trans_z(P._S[k])
    got = P.link_transform(P._CA[k], P._SA[k], P._A[k], theta, P._S[k])
    assert np.allclose(got, ref, atol=1e-12)


def test_forward_matches_generic_chain(chain):
    rng = np.random.default_rng(1)
    q = rng.uniform(-2 * math.pi, 2 * math.pi, (500, 6))
    f = P.forward(q)
    assert np.max(np.abs(f.pose - kinestat.fk(chain, q))) <= 1e-10
    # the 4x4 product written out (eq. 2-33) agrees too
    T = rot_z(q[:, 0])
    for k in range(5):
        T = T @ P.link_transform(P._CA[k], P._SA[k], P._A[k], q[:, k + 1], P._S[k])
    assert np.max(np.abs(f.pose - T)) <= 1e-10


def test_forward_matches_roboticstoolbox():
    rtb = pytest.importorskip("roboticstoolbox")
    links = [
        rtb.RevoluteMDH(alpha=0.0, a=0.0, d=0.0),
        rtb.RevoluteMDH(alpha=math.pi / 2, a=0.0, d=190.0),
        rtb.RevoluteMDH(alpha=0.0, a=650.0, d=0.0),
        rtb.RevoluteMDH(alpha=3 * math.pi / 2, a=0.0, d=600.0),
        rtb.RevoluteMDH(alpha=math.pi / 2, a=0.0, d=0.0),
        rtb.RevoluteMDH(alpha=math.pi / 2, a=0.0, d=125.0),
    ]
    robot = rtb.DHRobot(links, name="puma762")
    rng = np.random.default_rng(2)
    for q in rng.uniform(-math.pi, math.pi, (20, 6)):
        ref = np.asarray(robot.fkine(q).A)
        assert np.max(np.abs(P.forward(q).pose - ref)) <= 1e-10


def test_forward_outputs_are_the_pose_columns():
    rng = np.random.default_rng(3)
    q = rng.uniform(-math.pi, math.pi, (4, 5, 6))
    p6 = rng.normal(0, 100, (4, 5, 3))
    f = P.forward(q, p6)
    assert f.pose.shape == (4, 5, 4, 4) and f.tool_point.shape == (4, 5, 3)
    assert np.allclose(f.s6, f.pose[..., :3, 2]) and np.allclose(f.a67, f.pose[..., :3, 0])
    ref = np.einsum("...ij,...j->...i", f.pose[..., :3, :3], p6) + f.pose[..., :3, 3]
    assert np.allclose(f.tool_point, ref, atol=1e-9)
    # geometry the mechanism imposes: the wrist centre never enters the S2 cylinder and lies
    # within a23 + S4 of the shoulder
    W = P.wrist_center(f.pose)
    assert np.all(np.hypot(W[..., 0], W[..., 1]) >= P.S2 - 1e-9)


def test_forward_rejects_bad_q():
    with pytest.raises(InputError):
        P.forward([0.0] * 5)
    with pytest.raises(InputError):
        P.forward([0.0, 0.0, float("nan"), 0.0, 0.0, 0.0])


# -- reverse: acceptance ---------------------------------------------------------------------
def test_reverse_contains_generating_configuration_1e4(chain):
    """10^4 random configurations within the limits: the closed form's solution set contains
    the generating one (mod 2π) and every branch reproduces the pose (checked by the generic
    chain, not by the module's own forward analysis)."""
    rng = np.random.default_rng(4)
    n = 10_000
    q = random_q_in_limits(rng, n)
    p6 = rng.normal(0, 150, (n, 3))
    f = P.forward(q, p6)
    b = P.reverse_batch(f.tool_point, f.s6, f.a67, p6)
    assert b.q.shape == (n, 8, 6) and b.valid.shape == (n, 8)
    d = np.max(np.abs(wrap(b.q - q[:, None, :])), axis=-1)
    assert np.all(np.nanmin(d, axis=1) < 1e-6)
    assert np.all(b.valid)  # random poses: all eight branches exist
    T = kinestat.fk(chain, b.q.reshape(-1, 6)).reshape(n, 8, 4, 4)
    tool = np.einsum("nkij,nj->nki", T[..., :3, :3], p6) + T[..., :3, 3]
    assert np.max(np.linalg.norm(tool - f.tool_point[:, None], axis=-1)) <= 1e-9
    assert np.max(np.abs(T[..., :3, 2] - f.s6[:, None])) <= 1e-9
    assert np.max(np.abs(T[..., :3, 0] - f.a67[:, None])) <= 1e-9


def test_reverse_single_returns_eight_distinct_solutions():
    q = np.radians([30.0, 20.0, -40.0, 50.0, 60.0, -70.0])
    f = P.forward(q, [10.0, 20.0, 30.0])
    res = P.reverse(f.tool_point, f.s6, f.a67, [10.0, 20.0, 30.0])
    assert res.solutions.shape == (8, 6) and res.families == () and res.reason is None
    for i in range(8):
        for j in range(i):
            assert np.max(np.abs(wrap(res.solutions[i] - res.solutions[j]))) > 1e-6
    g = P.forward(res.solutions, [10.0, 20.0, 30.0])
    assert np.allclose(g.tool_point, f.tool_point, atol=1e-9)
    assert np.allclose(g.s6, f.s6, atol=1e-12) and np.allclose(g.a67, f.a67, atol=1e-12)


def test_solution_tree_structure():
    """Figure 2-14: φ1 shared by branches 0-3 / 4-7, θ3 by pairs, θ5 flips sign in each pair
    (and θ4, θ6 shift by π: the wrist flip)."""
    rng = np.random.default_rng(5)
    q = random_q_in_limits(rng, 50)
    f = P.forward(q)
    b = P.reverse_batch(f.tool_point, f.s6, f.a67)
    Q = b.q
    assert np.allclose(Q[:, :4, 0], Q[:, :1, 0]) and np.allclose(Q[:, 4:, 0], Q[:, 4:5, 0])
    assert np.allclose(Q[:, 0::2, 2], Q[:, 1::2, 2])
    assert np.allclose(Q[:, 0::2, 4], -Q[:, 1::2, 4])
    assert np.allclose(np.abs(wrap(Q[:, 0::2, 3] - Q[:, 1::2, 3])), math.pi)
    assert np.allclose(np.abs(wrap(Q[:, 0::2, 5] - Q[:, 1::2, 5])), math.pi)


def test_crane_equation_10_8_gives_the_same_phi1():
    """Independent route to φ1 (Crane's C++ eq. 10.8 = Vibhute eq. 2-47, signs restored):
    (S6 Y7 − S7 s71) c1 + (S6 X7 + a71) s1 + S2 = 0 with X7 = s7, Y7 = −c71 c7 and
    φ1 = θ1 − γ1, from the closed-loop parameters."""
    rng = np.random.default_rng(6)
    q = rng.uniform(-math.pi, math.pi, (300, 6))
    p6 = rng.normal(0, 100, (300, 3))
    f = P.forward(q, p6)
    L = P.close_loop(f.tool_point, f.s6, f.a67, p6)
    A = P.S6 * (-np.cos(L.alpha71) * np.cos(L.theta7)) - L.S7 * np.sin(L.alpha71)
    B = P.S6 * np.sin(L.theta7) + L.a71_len
    # solve A c + B s + S2 = 0: two roots
    base = np.arctan2(B, A)
    delta = np.arccos(np.clip(-P.S2 / np.hypot(A, B), -1, 1))
    th1 = np.stack([base + delta, base - delta], axis=-1)
    phi1 = th1 - L.gamma1[:, None]
    b = P.reverse_batch(f.tool_point, f.s6, f.a67, p6)
    ours = b.q[:, [0, 4], 0]
    d = np.abs(wrap(phi1[:, :, None] - ours[:, None, :]))
    assert np.all(np.min(d, axis=2) < 1e-8) and np.all(np.min(d, axis=1) < 1e-8)


def test_close_loop_closes():
    rng = np.random.default_rng(7)
    q = rng.uniform(-math.pi, math.pi, (200, 6))
    p6 = rng.normal(0, 100, (200, 3))
    f = P.forward(q, p6)
    L = P.close_loop(f.tool_point, f.s6, f.a67, p6)
    P6 = P.frame6(f.tool_point, f.s6, f.a67, p6)[:, :3, 3]
    k = np.array([0.0, 0.0, 1.0])
    loop = P6 + L.S7[:, None] * L.s7 + L.a71_len[:, None] * L.a71 + L.S1[:, None] * k
    assert np.max(np.abs(loop)) < 1e-9
    assert np.allclose(np.sum(L.s7 * f.s6, -1), 0, atol=1e-12)  # α67 = 90°
    assert np.allclose(np.sum(L.a71 * L.s7, -1), 0, atol=1e-12)
    assert np.allclose(L.a71[:, 2], 0, atol=1e-12)
    # S7 parallel to S1: a71 is still a unit normal and the loop still closes
    Lp = P.close_loop([500.0, 300.0, 200.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    loop = (np.array([500.0, 300.0, 200.0]) + Lp.S7 * Lp.s7 + Lp.a71_len * Lp.a71
            + Lp.S1 * k)
    assert np.allclose(loop, 0, atol=1e-9) and abs(np.linalg.norm(Lp.a71) - 1) < 1e-12


# -- reverse: the thesis example and singular families ------------------------------------------
def test_appendix_c_example(chain):
    """Crane's example: P_tool_6 = 0, P_tool_F = (725, 190, 650), S6_F = i, a67_F = k."""
    res = P.reverse([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    assert res.solutions.shape == (6, 6)
    assert len(res.families) == 1
    fam = res.families[0]
    # the robot's "ready" posture: arm up, forearm forward, wrist straight (θ5 = 180° here)
    assert fam.kind == "sum"
    assert math.isclose(abs(fam.theta5), math.pi, abs_tol=1e-9)
    assert np.allclose(np.degrees([fam.phi1, fam.theta2, fam.theta3]) % 360, [180, 90, 0],
                       atol=1e-9)
    assert abs(wrap(fam.value - math.pi)) < 1e-9
    # every isolated solution and every member of the family reproduces the pose
    target = P.frame6([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    members = np.array([fam.member(t) for t in np.linspace(-3, 3, 7)])
    for qs in (res.solutions, members):
        T = kinestat.fk(chain, qs)
        assert np.max(np.abs(T - target)) < 1e-9


@pytest.mark.parametrize("theta5", [0.0, math.pi])
def test_wrist_singular_family(theta5, chain):
    rng = np.random.default_rng(8)
    for q in random_q_in_limits(rng, 20):
        q[4] = theta5
        f = P.forward(q)
        res = P.reverse(f.tool_point, f.s6, f.a67)
        fams = [fm for fm in res.families
                if np.max(np.abs(wrap(np.array([fm.phi1, fm.theta2, fm.theta3]) - q[:3]))) < 1e-7]
        assert len(fams) == 1
        fm = fams[0]
        assert fm.kind == ("difference" if theta5 == 0.0 else "sum")
        rel = q[5] - q[3] if fm.kind == "difference" else q[3] + q[5]
        assert abs(wrap(fm.value - rel)) < 1e-7
        assert np.max(np.abs(kinestat.fk(chain, fm.member(0.7)) - f.pose)) < 1e-9
        # the other arm configurations are regular here: isolated solutions
        assert len(res.solutions) + 2 * len(res.families) == 8


def test_near_singular_branches_still_reproduce():
    rng = np.random.default_rng(9)
    q = random_q_in_limits(rng, 300)
    q[:, 4] = rng.choice([1e-13, 1e-11, 1e-9, 1e-7, math.pi - 1e-9], 300)
    f = P.forward(q)
    b = P.reverse_batch(f.tool_point, f.s6, f.a67)
    assert np.all(b.valid)
    assert np.nanmax(b.position_error) <= 1e-9 and np.nanmax(b.rotation_error) <= 1e-9


# -- reverse: out of reach, bad input ---------------------------------------------------------
def _tool_for_wrist(W, s6=(0.0, 0.0, 1.0), a67=(1.0, 0.0, 0.0)):
    return np.asarray(W, dtype=float) + P.S6 * np.asarray(s6), s6, a67


@pytest.mark.parametrize(
    "W, status, words",
    [
        ((50.0, 100.0, 300.0), P.STATUS_INSIDE_CYLINDER, ("φ1", "cylinder")),
        ((1500.0, 0.0, 600.0), P.STATUS_TOO_FAR, ("θ3", "too far")),
        ((20.0, -190.0, 0.0), P.STATUS_TOO_NEAR, ("θ3", "too near")),
    ],
)
def test_unreachable_explained(W, status, words):
    p, s6, a67 = _tool_for_wrist(W)
    b = P.reverse_batch(p, s6, a67)
    assert int(b.status) == status and not np.any(b.valid)
    with pytest.raises(UnreachableError) as ei:
        P.reverse(p, s6, a67)
    for w in words:
        assert w in str(ei.value)


def test_reach_boundary_is_inclusive():
    """A wrist centre exactly on the S2 cylinder or the outer sphere is reachable (double
    roots), within the rounding of the input."""
    q = np.array([0.3, 0.0, math.pi / 2 - math.pi, 0.1, 1.0, 0.2])  # arm stretched: s3 = -1
    f = P.forward(q)
    res = P.reverse(f.tool_point, f.s6, f.a67)
    assert len(res.solutions) >= 4
    # shoulder boundary: θ2 chosen so that ux = 0
    q = np.array([0.5, 0.0, 0.4, 0.3, 1.1, -0.2])
    q[1] = math.pi / 2 - math.atan2(600 * math.cos(q[2]), 650 - 600 * math.sin(q[2]))
    f = P.forward(q)
    res = P.reverse(f.tool_point, f.s6, f.a67)
    assert len(res.solutions) >= 4
    assert np.all(res.batch.position_error[res.batch.valid] <= 1e-9)


def test_batch_status_is_all_or_nothing():
    rng = np.random.default_rng(10)
    pts = rng.uniform(-1600, 1600, (2000, 3))
    R = np.linalg.qr(rng.normal(size=(2000, 3, 3)))[0]
    R *= np.sign(np.linalg.det(R))[:, None, None]
    b = P.reverse_batch(pts, R[:, :, 2], R[:, :, 0])
    reach = b.status == P.STATUS_OK
    assert 0 < reach.mean() < 1
    assert np.array_equal(np.all(b.valid, axis=1), reach)
    assert np.array_equal(np.any(b.valid, axis=1), reach)


@pytest.mark.parametrize(
    "args, msg",
    [
        (([700.0, 0, 600], [1.0, 0, 0.1], [0, 0, 1.0]), "unit"),
        (([700.0, 0, 600], [1.0, 0, 0], [0.1, 0, 0.99498743710662]), "perpendicular"),
        (([700.0, float("nan"), 600], [1.0, 0, 0], [0, 0, 1.0]), "NaN"),
        (([700.0, 600], [1.0, 0, 0], [0, 0, 1.0]), "shape"),
    ],
)
def test_bad_input(args, msg):
    with pytest.raises(InputError, match=msg):
        P.reverse(*args)
    with pytest.raises(InputError):
        P.reverse_batch(*args)


def test_slightly_non_unit_input_is_tolerated_and_cleaned():
    s6 = np.array([1.0, 0.0, 0.0]) * (1 + 5e-7)
    res = P.reverse([725.0, 190.0, 650.0], s6, [0.0, 0.0, 1.0])
    assert res.solutions.shape == (6, 6)


# -- axis angles, limits, selection -----------------------------------------------------------
def test_axis_angles_round_trip():
    rng = np.random.default_rng(11)
    q = rng.uniform(-7, 7, (50, 6))
    a = P.to_axis_angles(q)
    assert np.allclose(a[:, 0], q[:, 0] + math.pi) and np.allclose(a[:, 1:], q[:, 1:])
    back = P.from_axis_angles(a)
    assert np.allclose(back[:, 1:], q[:, 1:]) and np.allclose(wrap(back[:, 0] - q[:, 0]), 0)
    assert np.all((back[:, 0] >= -math.pi) & (back[:, 0] < math.pi))
    q1 = wrap(q)
    assert np.allclose(P.from_axis_angles(P.to_axis_angles(q1)), q1)


def test_axis_limits_agree_with_the_embedded_model(chain):
    """The model's joint-1 limits [20°, 340°] are the axis limits ±160° shifted by 180°."""
    rng = np.random.default_rng(12)
    q = rng.uniform(-2 * math.pi, 2 * math.pi, (3000, 6))
    lo, hi = chain.lower, chain.upper
    # the model accepts q after some 2π shift of each joint iff the axis limits do
    shifts = np.arange(-3, 4) * TWO_PI
    cand = q[..., None] + shifts
    ok_model = np.all(np.any((cand >= lo[:, None]) & (cand <= hi[:, None]), axis=-1), axis=-1)
    assert np.array_equal(ok_model, P.within_limits(q))


@settings(max_examples=200, deadline=None)
@given(
    st.floats(-20, 20), st.floats(-5, 5), st.floats(-5, 0), st.floats(0, 5),
)
def test_wrap_into_limits(angle, current, lo, hi):
    shifts = angle + np.arange(-10, 11) * TWO_PI
    assume(np.min(np.abs(np.concatenate([shifts - lo, shifts - hi]))) > 1e-9)  # not on a limit
    w, ok = P.wrap_into_limits(angle, current, lo, hi)
    assert abs(wrap(w - angle)) < 1e-9
    inside = shifts[(shifts >= lo - 1e-12) & (shifts <= hi + 1e-12)]
    assert bool(ok) == (inside.size > 0)
    if inside.size:
        assert lo - 1e-9 <= w <= hi + 1e-9
        assert abs(w - current) <= np.min(np.abs(inside - current)) + 1e-9


def test_selection_is_nearest_within_limits():
    rng = np.random.default_rng(13)
    n = 400
    a_true = random_axis_in_limits(rng, n)
    q = P.from_axis_angles(a_true)
    f = P.forward(q)
    b = P.reverse_batch(f.tool_point, f.s6, f.a67)
    a_cur = a_true + rng.normal(0, 0.05, q.shape)
    sel = P.select_batch(b, current_axis=a_cur)
    assert np.all(sel.ok)  # the generating configuration is within the limits
    lim = np.radians(P.AXIS_LIMITS_DEG)
    assert np.all((sel.axis >= lim[:, 0] - 1e-12) & (sel.axis <= lim[:, 1] + 1e-12))
    g = P.forward(sel.q)
    assert np.allclose(g.pose, f.pose, atol=1e-9)
    # least total axis motion among the in-limit candidates, and no worse than going back to
    # the generating configuration
    motion = np.abs(sel.axis - a_cur).sum(-1)
    assert np.allclose(motion, sel.motion)
    cm = np.where(sel.candidates_ok,
                  np.abs(sel.candidates_axis - a_cur[:, None]).sum(-1), np.inf)
    assert np.allclose(sel.motion, cm.min(axis=1))
    assert np.all(sel.motion <= np.abs(a_true - a_cur).sum(-1) + 1e-9)
    # the current configuration as joint angles: the same choice whenever axis 1 is inside
    # its limits (joint angles do not carry axis 1's turn)
    inside = np.abs(a_cur[:, 0]) <= np.radians(160)
    sel_q = P.select_batch(b, P.from_axis_angles(a_cur))
    assert np.allclose(sel_q.axis[inside], sel.axis[inside])


def test_selection_uses_more_than_one_turn_on_joints_4_and_6():
    q = np.radians([-30.0, 10.0, 20.0, 250.0, 40.0, -250.0])  # axis 1 = 150°
    f = P.forward(q)
    res = P.reverse(f.tool_point, f.s6, f.a67)
    sel = P.select(res, q)
    assert np.allclose(sel.q, q, atol=1e-7) and sel.motion < 1e-7
    assert abs(np.degrees(sel.axis[3]) - 250.0) < 1e-6


def test_selection_on_a_family_splits_the_motion():
    wide = [[-180, 180], [-180, 180], [-180, 180], [-266, 266], [-190, 190], [-266, 266]]
    res = P.reverse([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    cur = res.families[0].member(0.4)
    sel = P.select(res, cur, wide)
    assert sel.motion < 1e-9 and np.allclose(wrap(sel.q - cur), 0, atol=1e-9)
    cur2 = cur.copy()
    cur2[3] += 0.2  # off the family by 0.2 rad in θ4 + θ6: each moves 0.1
    sel = P.select(res, cur2, wide)
    assert abs(sel.motion - 0.2) < 1e-9
    assert np.allclose(np.abs(sel.q[[3, 5]] - cur2[[3, 5]]), 0.1, atol=1e-9)


def test_no_solution_within_limits_raises():
    tight = [[-1, 1]] * 6
    res = P.reverse([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    with pytest.raises(JointLimitError, match="axis limits"):
        P.select(res, None, tight)
    with pytest.raises(InputError):
        P.select(res, None, [[0, 1]] * 5)
