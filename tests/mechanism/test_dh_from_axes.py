"""DH table from joint axes (lecture notes' frame assignment): round trips and peer checks."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import kinestat
from kinestat.errors import InputError
from kinestat.mechanism.chain import from_standard_dh
from kinestat.mechanism.dh_from_axes import (
    RELATIONS,
    assign_dh_frames,
    dh_from_axes,
    dh_link,
    dh_row_from_frames,
)
from kinestat.serial.fk import fk, fk_frames, joint_axes
from tests._independent import dh_matrix

REL = st.sampled_from(RELATIONS)
KIND = st.sampled_from(["revolute", "revolute", "prismatic", "screw"])



def random_pose(rng, spread=1.0):
    A = rng.normal(size=(3, 3))
    Q, R = np.linalg.qr(A)
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] *= -1
    T = np.eye(4)
    T[:3, :3] = Q
    T[:3, 3] = rng.uniform(-spread, spread, 3)
    return T


def generating_row(rng, rel):
    """A standard-DH row whose z_{i-1}, z_i pair has the relation ``rel``."""
    theta = rng.uniform(-np.pi, np.pi)
    d = rng.uniform(-1, 1)
    twist = rng.choice([-1, 1]) * rng.uniform(0.2, np.pi - 0.2)
    flat = rng.choice([0.0, np.pi])
    a = 0.0 if rel in ("intersecting", "coincident") else rng.uniform(0.1, 1.5)
    alpha = flat if rel in ("parallel", "coincident") else twist
    return [theta, d, a, alpha]


def generated_chain(seed, rels, kinds):
    rng = np.random.default_rng(seed)
    rows = [generating_row(rng, r) for r in rels]
    pitches = [rng.uniform(-0.3, 0.3) + 0.5 if k == "screw" else 0.0 for k in kinds]
    model = from_standard_dh(rows, kinds, pitches=pitches, base=random_pose(rng),
                             tool=random_pose(rng, 0.5))
    q0 = rng.uniform(-2, 2, len(rels))
    return model, q0, rng


def given_axes(model, q0, rng):
    """The model's joint axes at q0 as (point, direction), with arbitrary points on the lines and
    arbitrary positive direction lengths."""
    u, rho = joint_axes(model, q0)
    pts = rho + rng.uniform(-3, 3, (model.n, 1)) * u
    dirs = u * rng.uniform(0.1, 5, (model.n, 1))
    return np.stack([pts, dirs], axis=1), u, rho


def line_offset(points, u, feet):
    """Distance of ``points`` from the lines (feet, unit u)."""
    r = points - feet
    return np.linalg.norm(r - np.sum(r * u, -1, keepdims=True) * u, axis=-1)


def wrap(x):
    return (np.asarray(x) + np.pi) % (2 * np.pi) - np.pi


chains = st.tuples(
    st.integers(0, 2**32 - 1),
    st.lists(st.tuples(REL, KIND), min_size=1, max_size=7),
)


@settings(max_examples=60, deadline=None)
@given(chains)
def test_round_trip_reproduces_axes_and_obeys_dh_rules(case):
    seed, spec = case
    rels = [r for r, _ in spec]
    kinds = [k for _, k in spec]
    orig, q0, rng = generated_chain(seed, rels, kinds)
    axes, u, rho = given_axes(orig, q0, rng)
    res = dh_from_axes(axes, kinds, pitches=[j.pitch for j in orig.joints], tool=fk(orig, q0))
    n = orig.n
    # FK of the recovered model at q = 0 puts every joint axis on its line, same direction.
    u2, rho2 = joint_axes(res.model, np.zeros(n))
    np.testing.assert_allclose(u2, u, atol=1e-9)
    assert np.all(line_offset(rho2, u, rho) <= 1e-9)
    np.testing.assert_allclose(fk(res.model, np.zeros(n)), fk(orig, q0), atol=1e-9)
    # The relations of neighbouring axes are those the generating table was built with.
    assert res.relations[: n - 1] == tuple(rels[: n - 1])
    th, d, a, al = res.table.T
    assert np.all(a >= 0)
    for i, rel in enumerate(rels[: n - 1]):
        cos_between = float(u[i] @ u[i + 1])
        assert np.cos(al[i]) == pytest.approx(cos_between, abs=1e-9)
        assert a[i] == pytest.approx(orig.parameters[i, 2], abs=1e-9)  # intrinsic distance
        if rel in ("parallel", "coincident"):
            assert d[i] == 0.0  # the notes' rule: x_i through o_{i-1}
            assert al[i] == (0.0 if cos_between > 0 else np.pi)
        if rel in ("intersecting", "coincident"):
            assert a[i] == 0.0
        if rel == "intersecting":
            assert 0 < al[i] < np.pi
        if rel == "coincident":
            assert th[i] == 0.0
    # The frames reported are the DH frames: x_i normal to z_{i-1} and z_i and meeting z_{i-1};
    # z_{i-1} on joint i's line.
    F = res.frames
    np.testing.assert_allclose(F[:n], fk_frames(res.model, np.zeros(n))[:n], atol=1e-12)
    for i in range(1, n + 1):
        x, o = F[i, :3, 0], F[i, :3, 3]
        zp, op = F[i - 1, :3, 2], F[i - 1, :3, 3]
        assert abs(x @ zp) <= 1e-9 and abs(x @ F[i, :3, 2]) <= 1e-9
        assert abs((o - op) @ np.cross(x, zp)) <= 1e-9  # coplanar and not parallel: they meet
        np.testing.assert_allclose(zp, u[i - 1], atol=1e-9)
        assert line_offset(op, u[i - 1], rho[i - 1]) <= 1e-9


@settings(max_examples=40, deadline=None)
@given(chains)
def test_recovered_chain_moves_like_the_original(case):
    seed, spec = case
    kinds = [k for _, k in spec]
    orig, q0, rng = generated_chain(seed, [r for r, _ in spec], kinds)
    axes, _, _ = given_axes(orig, q0, rng)
    res = dh_from_axes(axes, kinds, pitches=[j.pitch for j in orig.joints], tool=fk(orig, q0))
    q = rng.uniform(-3, 3, (5, orig.n))
    np.testing.assert_allclose(fk(res.model, q - q0), fk(orig, q), atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.lists(KIND, min_size=2, max_size=7))
def test_skew_chain_table_equals_generating_table(seed, kinds):
    """With frame 0 given and every neighbour pair skew, every x_i is forced, so the table is the
    generating one with the configuration folded into the offsets."""
    n = len(kinds)
    orig, q0, rng = generated_chain(seed, ["skew"] * n, kinds)
    axes, _, _ = given_axes(orig, q0, rng)
    frame_n = fk_frames(orig, q0)[-1] @ np.linalg.inv(orig.tool)  # frame n, before the tool
    res = dh_from_axes(axes, kinds, base=orig.base, tool=frame_n,
                       pitches=[j.pitch for j in orig.joints])
    P = np.asarray(orig.parameters)
    pris = np.array(kinds) == "prismatic"
    screw = np.array(kinds) == "screw"
    pitch = np.array([j.pitch for j in orig.joints])
    want_th = np.where(pris, P[:, 0], P[:, 0] + q0)
    want_d = P[:, 1] + np.where(pris, q0, 0.0) + np.where(screw, pitch * q0, 0.0)
    np.testing.assert_allclose(wrap(res.table[:, 0] - want_th), 0, atol=1e-9)
    np.testing.assert_allclose(res.table[:, 1], want_d, atol=1e-9)
    np.testing.assert_allclose(res.table[:, 2], P[:, 2], atol=1e-9)
    np.testing.assert_allclose(wrap(res.table[:-1, 3] - P[:-1, 3]), 0, atol=1e-9)
    assert res.table[-1, 3] == 0.0  # end frame: z_n along z_{n-1}; the twist goes to the tool
    from kinestat.spatial.transforms import rot_x

    np.testing.assert_allclose(res.tool, rot_x(P[-1, 3]), atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), REL, st.integers(2, 5))
def test_default_base_zeroes_first_offsets(seed, rel, n):
    orig, q0, rng = generated_chain(seed, [rel] + ["skew"] * (n - 1), ["revolute"] * n)
    axes, u, rho = given_axes(orig, q0, rng)
    res = dh_from_axes(axes)
    B = res.base
    np.testing.assert_allclose(B[:3, 2], u[0], atol=1e-12)
    assert line_offset(B[:3, 3], u[0], rho[0]) <= 1e-9
    th1, d1 = res.table[0, :2]
    if rel == "coincident":
        np.testing.assert_allclose(B[:3, 3], rho[0], atol=1e-12)
    else:
        assert abs(th1) <= 1e-12
        assert abs(d1) <= 1e-9


def test_plucker_input_and_point_choice_give_the_same_table(rng):
    for _ in range(10):
        n = int(rng.integers(1, 8))
        rels = list(rng.choice(RELATIONS, n))
        orig, q0, r2 = generated_chain(int(rng.integers(2**31)), rels, ["revolute"] * n)
        axes, u, rho = given_axes(orig, q0, r2)
        plucker = np.c_[u, np.cross(axes[:, 0], u)] * rng.uniform(0.2, 4, (n, 1))
        T = fk(orig, q0)
        a = dh_from_axes(axes, tool=T)
        b = dh_from_axes(plucker, tool=T)
        c = dh_from_axes(np.stack([rho, u], axis=1), tool=T)
        np.testing.assert_allclose(a.table, b.table, atol=1e-9)
        np.testing.assert_allclose(a.table, c.table, atol=1e-9)
        assert a.relations == b.relations == c.relations


def test_batch_equals_one_chain_at_a_time(rng):
    orig, _, _ = generated_chain(7, ["skew", "parallel", "intersecting", "coincident", "skew"],
                                 ["revolute"] * 5)
    q = rng.uniform(-2, 2, (2, 3, 5))
    u, rho = joint_axes(orig, q)
    axes = np.stack([rho, u], axis=-2)
    T = fk(orig, q)
    table, frames, rels, tool = assign_dh_frames(axes, tool=T)
    assert table.shape == (2, 3, 5, 4) and frames.shape == (2, 3, 6, 4, 4)
    assert rels.shape == (2, 3, 5) and tool.shape == (2, 3, 4, 4)
    for i in range(2):
        for j in range(3):
            one = dh_from_axes(axes[i, j], tool=T[i, j])
            np.testing.assert_allclose(table[i, j], one.table, atol=1e-12)
            np.testing.assert_allclose(frames[i, j], one.frames, atol=1e-12)
            assert tuple(RELATIONS[k] for k in rels[i, j]) == one.relations


def test_relations_agree_with_plucker_classification(rng):
    plucker = pytest.importorskip("kinestat.spatial.plucker")
    for _ in range(20):
        n = int(rng.integers(2, 8))
        orig, q0, r2 = generated_chain(int(rng.integers(2**31)), list(rng.choice(RELATIONS, n)),
                                       ["revolute"] * n)
        u, rho = joint_axes(orig, q0)
        lines = np.c_[u, np.cross(rho, u)]
        kinds = plucker.classify_lines(lines[:-1], lines[1:], tol=1e-9).kind
        res = dh_from_axes(np.stack([rho, u], axis=1))
        assert res.relations[:-1] == tuple(plucker.LINE_KINDS[k] for k in kinds)


def test_single_joint_with_and_without_tool(rng):
    line = np.array([[[1.0, 2.0, 3.0], [0.0, 0.0, 2.0]]])
    bare = dh_from_axes(line)
    np.testing.assert_allclose(bare.table, np.zeros((1, 4)))
    np.testing.assert_allclose(bare.base[:3, 2], [0, 0, 1])
    np.testing.assert_allclose(bare.base[:3, 0], [1, 0, 0])  # world x projected
    np.testing.assert_allclose(bare.base[:3, 3], [1, 2, 0])  # foot from the world origin
    assert bare.relations == ("coincident",)
    T = random_pose(rng, 4.0)
    res = dh_from_axes(line, tool=T)
    np.testing.assert_allclose(fk(res.model, [0.0]), T, atol=1e-12)
    np.testing.assert_allclose(res.frames[1][:3, 3], T[:3, 3], atol=1e-12)  # o_n: tool point
    assert res.relations == ("parallel",)
    assert res.table[0, 0] == pytest.approx(0.0, abs=1e-12)  # x_0 turned onto x_1
    q = rng.uniform(-3, 3, 4)
    # rotating about the given line by q
    from kinestat.spatial.transforms import inv, rot_z, trans

    about = trans([1, 2, 0]) @ rot_z(q) @ inv(trans([1, 2, 0]))
    np.testing.assert_allclose(fk(res.model, q[:, None]), about @ T, atol=1e-12)


def test_tool_on_last_axis_uses_tool_x(rng):
    """Coincident end frame: x_n is the tool's x when the tool's z is along z_{n-1}, so the
    residual tool transform is the identity."""
    orig, q0, r2 = generated_chain(3, ["skew", "intersecting", "skew"], ["revolute"] * 3)
    u, rho = joint_axes(orig, q0)
    F = fk_frames(orig, q0)[2]
    T = F @ dh_matrix(0.7, 0.4, 0.0, 0.0)  # on axis 3, z along it
    res = dh_from_axes(np.stack([rho, u], axis=1), tool=T)
    assert res.relations[-1] == "coincident"
    np.testing.assert_allclose(res.tool, np.eye(4), atol=1e-12)
    assert res.table[-1, 1] == pytest.approx(0.4, abs=1e-12)
    T2 = F @ dh_matrix(0.7, 0.4, 0.0, 0.0) @ dh_matrix(0, 0, 0, np.pi / 2)  # tool y along
    T2 = T2 @ dh_matrix(np.pi / 2, 0, 0, 0) @ dh_matrix(0, 0, 0, np.pi / 2)
    res2 = dh_from_axes(np.stack([rho, u], axis=1), tool=T2)
    np.testing.assert_allclose(fk(res2.model, np.zeros(3)), T2, atol=1e-12)


def test_puma560_axes_reproduce_end_pose(rng):
    """The brief's known arm: PUMA 560 axes at a configuration → table → same end pose with the
    same tool, and the same motion for every other configuration."""
    m = kinestat.load("puma560")
    for _ in range(5):
        q0 = rng.uniform(m.lower, m.upper)
        u, rho = joint_axes(m, q0)
        res = dh_from_axes(np.stack([rho, u], axis=1), tool=fk(m, q0), base=m.base,
                           length_unit="m")
        q = rng.uniform(m.lower, m.upper, (20, 6))
        np.testing.assert_allclose(fk(res.model, q - q0), fk(m, q), atol=1e-12)
        P = np.asarray(m.parameters)
        np.testing.assert_allclose(res.table[:, 1:3], P[:, 1:3], atol=1e-12)
        np.testing.assert_allclose(np.abs(res.table[:, 3]), np.abs(P[:, 3]), atol=1e-12)
        assert res.relations == ("intersecting", "parallel", "skew", "intersecting",
                                 "intersecting", "coincident")


def test_peer_puma560_table_recovered_from_its_frames(rng):
    """Independent oracle: Robotics Toolbox's Puma560 link frames → our table = its table
    (a, d, |α|), and our chain reproduces its fkine."""
    rtb = pytest.importorskip("roboticstoolbox")
    robot = rtb.models.DH.Puma560()
    for _ in range(3):
        q0 = rng.uniform(-2, 2, 6)
        F = np.array([T.A for T in robot.fkine_all(q0)])
        axes = np.stack([F[:6, :3, 3], F[:6, :3, 2]], axis=1)
        res = dh_from_axes(axes, base=F[0], tool=robot.fkine(q0).A, length_unit="m")
        want_a = [L.a for L in robot.links]
        want_d = [L.d for L in robot.links]
        want_al = [abs(L.alpha) for L in robot.links]
        np.testing.assert_allclose(res.table[:, 2], want_a, atol=1e-12)
        np.testing.assert_allclose(res.table[:, 1], want_d, atol=1e-12)
        np.testing.assert_allclose(np.abs(res.table[:, 3]), want_al, atol=1e-12)
        for q in rng.uniform(-3, 3, (5, 6)):
            np.testing.assert_allclose(fk(res.model, q - q0), robot.fkine(q).A, atol=1e-12)


def test_link_transform_is_the_notes_closed_form(rng):
    """Seed check: Rz(θ) Tz(d) Tx(a) Rx(α) equals the notes' written-out H_i^{i-1}, and the
    row is read back from two frames by the notes' definitions of θ, d, a, α."""
    for _ in range(50):
        row = np.r_[rng.uniform(-np.pi, np.pi), rng.uniform(-2, 2), rng.uniform(0, 2),
                    rng.uniform(-np.pi, np.pi)]
        np.testing.assert_allclose(dh_link(row), dh_matrix(*row), atol=1e-14)
        B = random_pose(rng)
        np.testing.assert_allclose(dh_row_from_frames(B, B @ dh_matrix(*row)), row,
                                   atol=1e-12)


def test_result_is_read_only():
    res = dh_from_axes([[[0, 0, 0], [0, 0, 1]], [[1, 0, 0], [0, 1, 0]]])
    with pytest.raises(ValueError):
        res.table[0, 0] = 1.0
    assert res.n == 2
    assert res.relations == ("skew", "coincident")


@pytest.mark.parametrize(
    "axes, match",
    [
        ([[[0, 0, 0], [0, 0, 0]]], "zero direction"),
        ([[[0, 0, np.nan], [0, 0, 1]]], "NaN"),
        (np.zeros((0, 2, 3)), "at least one axis"),
        (np.zeros((0, 6)), "at least one axis"),
        ([[0, 0, 1]], "shape"),
        ([[0, 0, 1, 1, 0, 1]], "Plücker"),
        ([[0, 0, 0, 1, 0, 0]], "zero Plücker direction"),
        (np.zeros((2, 2, 2, 3)) + [0, 0, 1], "one chain"),
        # non-numbers used to raise NumPy's bare ValueError
        ("abc", "array of numbers"),
        ([[[0, 0, 0], [0, 0, 1]], [[0, 0], [0, 1, 0]]], "array of numbers"),
    ],
)
def test_bad_axes_raise_input_error(axes, match):
    with pytest.raises(InputError, match=match):
        dh_from_axes(axes)


def test_bad_base_tool_and_kinds_raise_input_error():
    axes = [[[0, 0, 0], [0, 0, 1]], [[1, 0, 0], [0, 1, 0]]]
    shifted = np.eye(4)
    shifted[0, 3] = 0.1
    with pytest.raises(InputError, match="origin"):
        dh_from_axes(axes, base=shifted)
    with pytest.raises(InputError, match="z axis"):
        dh_from_axes(axes, base=dh_matrix(0, 0, 0, np.pi))
    with pytest.raises(InputError, match="orthonormal"):
        dh_from_axes(axes, tool=np.diag([2.0, 1, 1, 1]))
    with pytest.raises(InputError, match="4x4"):
        dh_from_axes(axes, tool=np.eye(3))
    with pytest.raises(InputError, match="kinds"):
        dh_from_axes(axes, ["revolute"])
    with pytest.raises(InputError, match="pitch"):
        dh_from_axes(axes, ["revolute", "screw"])
    with pytest.raises(InputError, match="tol"):
        dh_from_axes(axes, tol=float("nan"))
