"""ik_all on arms with prismatic joints (the decoupled solver: three R/P positioning joints and a
spherical wrist): completeness, accuracy, and the solution count against an independent
many-start Newton oracle, on random chains of every R/P combination and on real arm types."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import kinestat
from kinestat.errors import ModelError
from kinestat.mechanism.chain import from_standard_dh
from kinestat.serial.analytic import ik_all, method_for, select_nearest
from kinestat.serial.analytic.decoupled import plan

from .arms import PI, newton_solutions, slot_residuals, wrapped_distance

H = PI / 2
COMBOS = ["".join(c) for c in itertools.product("RP", repeat=3)]
KIND = {"R": "revolute", "P": "prismatic"}


def random_decoupled(kinds: str, seed: int):
    """A random chain: joints 1-3 of the given kinds in general position (standard DH rows
    uniform: angles in [-π, π], lengths in [-1, 1] m), then a spherical wrist with random
    twists (a4 = a5 = d5 = 0) and a random tool."""
    rng = np.random.default_rng(seed)
    rows = np.column_stack([rng.uniform(-PI, PI, 6), rng.uniform(-1, 1, 6),
                            rng.uniform(-1, 1, 6), rng.uniform(-PI, PI, 6)])
    rows[3, 2] = rows[4, 1] = rows[4, 2] = 0.0
    return from_standard_dh(rows, [KIND[k] for k in kinds] + ["revolute"] * 3,
                            name=f"random-{kinds}-{seed}", length_unit="m")


def _wrist(d6: float = 0.1):
    return [[0.0, 0.0, 0.0, -H], [0.0, 0.0, 0.0, H], [0.0, d6, 0.0, 0.0]]


def named(name: str):
    """Real prismatic arm types (Spong, Hutchinson & Vidyasagar 2006, ch. 3), each with a
    spherical wrist: the Stanford arm (embedded model), a cylindrical RPP arm, a Cartesian PPP
    gantry, a SCARA-type RRP (axes 1, 2 parallel, boom along them), a linear track carrying an
    RR arm (PRR, track across axis 2) and a turret with a lift (RPR, lift along axis 1)."""
    if name == "stanford":
        return kinestat.load("stanford")
    table = {
        "cylindrical": ("RPP", [[0, 0.5, 0, 0], [0, 0.2, 0, -H], [0, 0.3, 0, 0]]),
        "cartesian": ("PPP", [[0, 0.1, 0, -H], [-H, 0.2, 0, -H], [0, 0.3, 0, 0]]),
        "scara": ("RRP", [[0, 0.4, 0.35, 0], [0, 0, 0.3, PI], [0, 0.1, 0, 0]]),
        "track": ("PRR", [[0, 0.3, 0, -H], [0, 0.2, 0.4, H], [0, 0.1, 0.3, H]]),
        "lift": ("RPR", [[0, 0.3, 0.2, 0], [0, 0.1, 0.25, -H], [0, 0, 0.3, H]]),
    }
    kinds, rows = table[name]
    return from_standard_dh(np.array(rows + _wrist()), [KIND[k] for k in kinds] + ["revolute"] * 3,
                            name=name, length_unit="m")


NAMED = ["stanford", "cylindrical", "cartesian", "scara", "track", "lift"]
ARMS = [f"random-{c}-{s}" for c in COMBOS for s in (1, 2)] + NAMED


def arm(name: str):
    if name.startswith("random-"):
        _, kinds, seed = name.split("-")
        return random_decoupled(kinds, int(seed))
    return named(name)


def configs(model, n: int, seed: int) -> np.ndarray:
    """Random configurations: revolute in [-π, π], prismatic in [-1, 1] m (the Stanford arm's
    boom within its limits)."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-PI, PI, (n, 6))
    q = np.where(model.prismatic, q / PI, q)
    if model.name == "stanford":
        q[:, 2] = rng.uniform(model.lower[2], model.upper[2], n)
    return q


def _regular(model, q, tol=1e-6):
    s = np.linalg.svd(kinestat.jacobian(model, q), compute_uv=False)
    return s[..., -1] > tol * s[..., 0]


def _found(model, res, q):
    d = wrapped_distance(res.q, q[:, None, :], ~model.prismatic)
    return np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1)


@pytest.mark.parametrize("name", ARMS)
def test_generating_configuration_found_and_residuals(name):
    model = arm(name)
    # auto picks the decoupled solver when a prismatic joint is present; an RRR arm with a
    # spherical wrist is a pieper arm (offset shoulder or not), decoupled is forced
    assert method_for(model) == ("decoupled" if model.prismatic.any() else "pieper")
    q = configs(model, 1000, seed=len(name))
    q = q[_regular(model, q)]
    T = kinestat.fk(model, q)
    res = ik_all(model, T, method="decoupled")
    assert res.method == "decoupled" and res.q.shape == (q.shape[0], 8, 6)
    found = _found(model, res, q)
    assert found.all(), f"{name}: generating configuration missed in {np.sum(~found)} poses"
    pos, dR = slot_residuals(model, res, T)  # recomputed with kinestat.fk
    assert pos.max() <= 1e-9 and dR.max() <= 1e-9
    assert np.all(res.n_solutions == res.valid.sum(-1))
    assert np.all(res.reason[res.n_solutions > 0] == "")
    # prismatic values are lengths, not wrapped; revolute ones are in [-π, π)
    qr = res.q[..., ~model.prismatic][res.valid]
    assert np.all((qr >= -PI) & (qr < PI))
    if not model.prismatic.any():  # two derivations, one count
        assert np.array_equal(ik_all(model, T).n_solutions, res.n_solutions)


@pytest.mark.parametrize("name", ARMS)
def test_count_matches_many_start_newton(name):
    model = arm(name)
    q = configs(model, 10, seed=11)
    T = kinestat.fk(model, q)
    res = ik_all(model, T, method="decoupled")
    oracle = newton_solutions(model, T, starts=400, iters=50, seed=3, span=3.0)
    rot = ~model.prismatic
    for i, sols in enumerate(oracle):
        assert len(sols) == res.n_solutions[i], (name, i, len(sols), res.n_solutions[i])
        mine = res.solutions((i,))
        for s in sols:  # every Newton solution is one of ik_all's
            assert np.min(wrapped_distance(mine, s, rot)) < 1e-6


@pytest.mark.parametrize("name", ["puma560", "random-RRR"])
def test_forced_on_revolute_arms_agrees_with_the_other_methods(name):
    """method="decoupled" on 6R arms with a spherical wrist: the PUMA 560 (axes 1, 2 meet:
    against the pieper closed form) and a random RRR shoulder (against many-start Newton)."""
    model = kinestat.load("puma560") if name == "puma560" else random_decoupled("RRR", 5)
    q = configs(model, 200 if name == "puma560" else 10, seed=4)
    q = q[_regular(model, q)]
    T = kinestat.fk(model, q)
    res = ik_all(model, T, method="decoupled")
    assert res.method == "decoupled" and _found(model, res, q).all()
    pos, dR = slot_residuals(model, res, T)
    assert pos.max() <= 1e-9 and dR.max() <= 1e-9
    if name == "puma560":
        other = [ik_all(model, T, backend="numpy").solutions((i,)) for i in range(len(q))]
    else:
        other = newton_solutions(model, T, starts=400, iters=50, seed=3)
    for i, sols in enumerate(other):
        assert len(sols) == res.n_solutions[i]
        for s in sols:
            assert np.min(wrapped_distance(res.solutions((i,)), s)) < 1e-6


def test_unreachable_pose_gives_empty_set_with_reason():
    # the Stanford arm's wrist centre stays d2 = 0.154 m or more away from axis 1
    model = kinestat.load("stanford")
    T = np.eye(4)
    T[:3, 3] = [0.05, 0.0, 1.0 + 0.263]  # wrist centre 0.05 m from axis 1
    res = ik_all(model, T)
    assert int(res.n_solutions) == 0 and not res.valid.any() and np.all(np.isnan(res.q))
    assert "no real solution" in res.reason[()]
    # arms whose reach is bounded across their prismatic axes (or that have none): far away
    far = np.eye(4)
    far[:3, 3] = [50.0, 0.0, 0.0]  # across the track's axis (base z)
    for m in (random_decoupled("RRR", 5), named("track")):
        res = ik_all(m, far, method="decoupled")
        assert int(res.n_solutions) == 0 and "no real solution" in res.reason[()]


@pytest.mark.parametrize("q", [[0.4, -0.7, 0.8, 0.9, 0.0, -0.3], [0.0, 0.0, 0.6, 0.0, 0.0, 0.0]])
def test_wrist_singular_family_on_the_stanford_arm(q):
    """θ5 = 0 (axes 4 and 6 aligned); the second is the home pose, where also the wrist centre
    is at distance d2 from axis 1 (a double root of the position)."""
    model = kinestat.load("stanford")
    q = np.array(q)
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    assert res.family_joints == (3, 5) and res.singular.any()
    hit = False
    for k in np.flatnonzero(res.singular):
        sig, val = res.family_sign[k], res.family_value[k]
        for t in np.linspace(-3, 3, 5):  # every member reproduces the pose
            qm = res.family_members((), int(k), t)[0]
            np.testing.assert_allclose(kinestat.fk(model, qm), T, atol=1e-9)
        same = np.abs(np.delete(res.q[k] - q, [3, 5])) < 1e-9
        rel = np.mod(q[3] + sig * q[5] - val + PI, 2 * PI) - PI
        hit |= bool(same.all() and abs(rel) < 1e-9)
    assert hit  # the generating configuration is a member of one of the families


def test_batch_shape_single_pose_and_selection_within_limits():
    model = kinestat.load("stanford")
    rng = np.random.default_rng(8)
    q = rng.uniform(model.lower, model.upper, (2, 3, 6))
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    assert res.valid.shape == (2, 3, 8) and res.q.shape == (2, 3, 8, 6)
    one = ik_all(model, T[1, 2])
    assert one.valid.shape == (8,) and int(one.n_solutions) == int(res.n_solutions[1, 2])
    np.testing.assert_allclose(one.solutions(), res.solutions((1, 2)), atol=1e-12)
    sel = select_nearest(model, res, q)
    assert sel.ok.all()
    np.testing.assert_allclose(sel.q, q, atol=1e-7)  # the generator: nearest, within limits
    assert np.all((sel.q[..., 2] >= model.lower[2]) & (sel.q[..., 2] <= model.upper[2]))


def _rows(n=6):
    return np.column_stack([np.zeros(n), np.full(n, 0.1), np.full(n, 0.2), np.full(n, 0.5)])


def test_errors_name_why_a_chain_is_outside_the_class():
    with pytest.raises(ModelError, match="joint 5 .* prismatic.*spherical wrist"):
        ik_all(from_standard_dh(_rows(), ["revolute"] * 4 + ["prismatic", "revolute"]),
               np.eye(4))
    with pytest.raises(ModelError, match="axes 4, 5, 6 of model 'chain' do not meet"):
        ik_all(from_standard_dh(_rows(), ["prismatic"] + ["revolute"] * 5), np.eye(4))
    cart = np.array([[0, 0, 0, 0], [0, 0.2, 0, 0], [0, 0.3, 0, -H]] + _wrist())
    with pytest.raises(ModelError, match="prismatic joints 1 and 2 .* parallel"):
        ik_all(from_standard_dh(cart, ["prismatic"] * 3 + ["revolute"] * 3), np.eye(4))
    flat = np.array([[0, 0, 0, -H], [0, 0.2, 0, H], [0, 0.3, 0, 0]] + _wrist())  # P3 ∥ P1
    with pytest.raises(ModelError, match="three independent directions"):
        ik_all(from_standard_dh(flat, ["prismatic"] * 3 + ["revolute"] * 3), np.eye(4))
    coaxial = np.array([[0, 0.1, 0.3, H], [0, 0, 0.4, 0], [0, 0, 0.3, H], [0, 0, 0, -H],
                        [0, 0, 0, 0], [0, 0.1, 0, 0]])  # α5 = 0: axis 6 on axis 5
    with pytest.raises(ModelError, match="axes 5 and 6 .* coincide"):
        ik_all(from_standard_dh(coaxial, ["revolute", "prismatic"] + ["revolute"] * 4),
               np.eye(4))
    with pytest.raises(ModelError, match="screw"):
        ik_all(from_standard_dh(np.array([[0, 0.1, 0.3, H], [0, 0, 0.4, 0], [0, 0, 0, H]]
                                         + _wrist()), ["screw"] + ["revolute"] * 5,
                                pitches=[0.01] + [0] * 5), np.eye(4))
    stanford = kinestat.load("stanford")
    with pytest.raises(ModelError, match="does not apply"):
        ik_all(stanford, np.eye(4), method="pieper")
    with pytest.raises(ModelError, match="does not apply"):
        ik_all(stanford, np.eye(4), method="raghavan-roth")
    ur5 = kinestat.load("ur5")
    with pytest.raises(ModelError, match="'decoupled' does not apply"):
        ik_all(ur5, np.eye(4), method="decoupled")
    assert math.isfinite(float(stanford.upper[2]))


def test_orientation_out_of_the_wrists_reach_names_the_wrist():
    """A wrist with oblique twists cannot turn to every orientation: with the wrist centre kept
    where joints 1-3 reach it and a random rotation, a pose either has solutions or the reason
    names the wrist; many-start Newton finds nothing on the latter."""
    model = random_decoupled("RPR", 3)
    rng = np.random.default_rng(0)
    q = configs(model, 60, seed=5)
    T = kinestat.fk(model, q)
    T0 = kinestat.fk(model, np.zeros(6))
    w_flange = np.linalg.solve(T0, np.append(plan(model).wrist, 1.0))[:3]
    p = T[:, :3, :3] @ w_flange + T[:, :3, 3]  # the wrist centre of each pose
    A = rng.normal(size=(60, 3, 3))
    R, _ = np.linalg.qr(A)
    R *= np.sign(np.linalg.det(R))[:, None, None]
    T[:, :3, :3] = R
    T[:, :3, 3] = p - R @ w_flange
    res = ik_all(model, T)
    none = res.n_solutions == 0
    assert none.any() and (~none).any()
    assert all("spherical wrist cannot turn" in r for r in res.reason[none])
    idx = np.flatnonzero(none)[:4]
    for sols in newton_solutions(model, T[idx], starts=200, iters=50, seed=1, span=3.0):
        assert len(sols) == 0


def test_a_wrist_centre_out_of_reach_is_named_as_such():
    """A pose whose wrist centre joints 1-3 cannot place (checked by sampling them) is
    refused as out of the position stage's reach, not of the wrist's."""
    model = kinestat.load("stanford")
    T = np.eye(4)  # the flange at the base origin
    w_flange = np.linalg.solve(kinestat.fk(model, np.zeros(6)), np.append(plan(model).wrist, 1))
    g = np.meshgrid(np.linspace(-np.pi, np.pi, 60), np.linspace(-np.pi, np.pi, 60),
                    np.linspace(-2.0, 2.0, 60), indexing="ij")
    q = np.zeros((g[0].size, 6))
    q[:, 0], q[:, 1], q[:, 2] = (a.ravel() for a in g)
    centres = kinestat.fk(model, q) @ w_flange
    assert np.min(np.linalg.norm(centres[:, :3] - (T @ w_flange)[:3], axis=1)) > 0.05
    res = kinestat.ik_all(model, T)
    assert res.n_solutions == 0 and "out of reach of joints 1-3" in str(res.reason)
