"""ik_all on the test arms: completeness, accuracy and the solution count against an
independent many-start Newton oracle."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.errors import InputError, KinestatError, ModelError
from kinestat.mechanism.chain import from_standard_dh
from kinestat.serial.analytic import ik_all, method_for
from kinestat.serial.analytic.general6r import FORMULATIONS, solve_general_6r

from .arms import PI, arm, newton_solutions, slot_residuals, wrapped_distance

ARMS = {
    "ur5": "three-parallel",
    "puma560": "pieper",
    "puma762": "pieper",
    "jaco6": "raghavan-roth",
    "random1": "raghavan-roth",
    "random2": "raghavan-roth",
    "random3": "raghavan-roth",
}


def _configs(model, n, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(-PI, PI, (n, 6))


def _regular(model, q, tol=1e-6):
    """Away from singular sets: the Jacobian's smallest singular value is not tiny."""
    s = np.linalg.svd(kinestat.jacobian(model, q), compute_uv=False)
    return s[..., -1] > tol * s[..., 0]


@pytest.mark.parametrize("name", sorted(ARMS))
def test_generating_configuration_found_and_residuals(name):
    model = arm(name)
    assert method_for(model) == ARMS[name]
    n = 300 if ARMS[name] != "raghavan-roth" else 200
    q = _configs(model, n, seed=hash(name) % 1000)
    q = q[_regular(model, q)]
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    assert res.q.shape == (q.shape[0], res.valid.shape[1], 6)
    d = wrapped_distance(res.q, q[:, None, :])
    found = np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1)
    assert found.all(), f"{name}: generating configuration missed in {np.sum(~found)} poses"
    # every returned solution reproduces the pose (checked here independently of the solver)
    pos, dR = slot_residuals(model, res, T)
    assert pos.max() <= 1e-9 and dR.max() <= 1e-9
    assert np.all(res.n_solutions == res.valid.sum(-1))
    assert np.all(res.reason[res.n_solutions > 0] == "")


@pytest.mark.parametrize("name", sorted(ARMS))
def test_count_matches_many_start_newton(name):
    model = arm(name)
    q = _configs(model, 8, seed=7)
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    oracle = newton_solutions(model, T, starts=300, iters=50, seed=3)
    for i, sols in enumerate(oracle):
        assert len(sols) == res.n_solutions[i], (name, i, len(sols), res.n_solutions[i])
        mine = res.solutions((i,))
        for s in sols:  # every Newton solution is one of ik_all's
            assert np.min(wrapped_distance(mine, s)) < 1e-6


def test_eigenvalue_method_agrees_with_closed_forms():
    """The general method, forced on the special arms, finds the closed forms' solutions."""
    for name in ("ur5", "puma560"):
        model = arm(name)
        q = _configs(model, 60, seed=11)
        T = kinestat.fk(model, q)
        a = ik_all(model, T)
        b = ik_all(model, T, method="raghavan-roth")
        assert b.method.startswith("raghavan-roth")
        for i in range(q.shape[0]):
            sa, sb = a.solutions((i,)), b.solutions((i,))
            # RR may lose a solution at a degenerate root of a special geometry; never add one
            for s in sb:
                assert np.min(wrapped_distance(sa, s)) < 1e-6
        assert np.mean(b.n_solutions == a.n_solutions) > 0.95


def test_every_formulation_complete_on_a_general_arm():
    model = arm("random4")
    q = _configs(model, 20, seed=1)
    T = kinestat.fk(model, q)
    for form in FORMULATIONS:
        res = solve_general_6r(model, T, form=form)
        d = wrapped_distance(res.q, q[:, None, :])
        assert np.all(np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1)), form


def test_batch_shape_and_single_pose():
    model = arm("ur5")
    q = _configs(model, 6, seed=2).reshape(2, 3, 6)
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    assert res.valid.shape == (2, 3, 8) and res.q.shape == (2, 3, 8, 6)
    one = ik_all(model, T[1, 2])
    assert one.valid.shape == (8,)
    assert int(one.n_solutions) == int(res.n_solutions[1, 2])
    np.testing.assert_allclose(one.solutions(), res.solutions((1, 2)), atol=1e-12)


@pytest.mark.parametrize("name", ["puma560", "ur5", "jaco6", "random1"])
def test_unreachable_pose_gives_empty_set_with_reason(name):
    model = arm(name)
    T = np.eye(4)
    T[:3, 3] = [50.0, 0.0, 0.0]  # far outside any of these arms
    if name == "puma762":
        T[:3, 3] *= 1000
    res = ik_all(model, T)
    assert int(res.n_solutions) == 0 and not res.valid.any()
    assert "no real solution" in res.reason[()]
    assert np.all(np.isnan(res.q))


def test_puma_wrist_singular_family():
    model = kinestat.load("puma560")
    q = np.array([0.3, 0.8, -0.4, 0.7, 0.0, -0.5])  # θ5 = 0: axes 4 and 6 aligned
    res = ik_all(model, kinestat.fk(model, q))
    assert res.family_joints == (3, 5)
    assert res.singular.any()
    k = int(np.flatnonzero(res.singular)[0])
    sig, val = res.family_sign[k], res.family_value[k]
    assert sig in (-1.0, 1.0)
    # every member of the family reproduces the pose
    for t in np.linspace(-3, 3, 7):
        qm = res.q[k].copy()
        qm[3] += t
        qm[5] -= sig * t
        d = np.mod(qm[3] + sig * qm[5] - val + PI, 2 * PI) - PI
        assert abs(d) < 1e-9
        F = kinestat.fk(model, qm)
        np.testing.assert_allclose(F, kinestat.fk(model, q), atol=1e-9)
    # the generating configuration is a member of some singular family
    fam_val = q[3] + res.family_sign * q[5]
    hit = res.singular & (np.abs(np.mod(fam_val - res.family_value + PI, 2 * PI) - PI) < 1e-9)
    assert hit.any()


def test_errors():
    model = arm("ur5")
    with pytest.raises(ModelError, match="7 joints"):
        rows = np.zeros((7, 4))
        rows[:, 2] = 0.3
        ik_all(from_standard_dh(rows), np.eye(4))
    with pytest.raises(ModelError, match="prismatic"):
        rows = np.column_stack([np.zeros(6), np.full(6, 0.1), np.full(6, 0.2), np.full(6, 0.5)])
        ik_all(from_standard_dh(rows, ["revolute"] * 5 + ["prismatic"]), np.eye(4))
    with pytest.raises(ModelError, match="screw"):
        rows = np.column_stack([np.zeros(6), np.full(6, 0.1), np.full(6, 0.2), np.full(6, 0.5)])
        ik_all(from_standard_dh(rows, ["screw"] + ["revolute"] * 5, pitches=[0.01] + [0] * 5),
               np.eye(4))
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(InputError, match="T_base_flange is not a rigid pose"):
        ik_all(model, bad)
    with pytest.raises(InputError, match="shape"):
        ik_all(model, np.eye(3))
    with pytest.raises(InputError, match="NaN"):
        ik_all(model, np.full((4, 4), np.nan))
    with pytest.raises(KinestatError, match="does not apply"):
        ik_all(model, np.eye(4), method="pieper")
    with pytest.raises(ModelError, match="unknown method"):
        ik_all(model, np.eye(4), method="magic")


def test_top_level_export():
    assert kinestat.ik_all is ik_all


@pytest.mark.parametrize("name", ["ur5", "puma560", "random1"])
def test_rounded_pose_is_projected_onto_a_rotation(name):
    model = arm(name)
    q = np.array([0.3, -0.7, 1.1, 0.4, -0.9, 0.2])
    T = kinestat.fk(model, q)
    T32 = T.astype(np.float32)  # orthonormal only to ~1e-7
    res = ik_all(model, T32)
    assert int(res.n_solutions) == int(ik_all(model, T).n_solutions) > 0
    assert np.min(wrapped_distance(res.solutions(), q)) < 1e-5


@pytest.mark.parametrize("name", ["ur5", "puma560", "kr16"])
def test_closed_form_kernels_hand_unchecked_poses_to_the_checks(name):
    """The closed-form kernels check each float64 pose themselves: a pose orthonormal only to
    within 1e-6 (printed to 7 decimals) is still projected, in a batch and alone, and a pose
    that is not rigid still raises, naming its index in the batch."""
    model = arm(name)
    q = np.random.default_rng(4).uniform(-PI, PI, (5, 6))
    T = kinestat.fk(model, q)
    Tr = T.copy()
    Tr[2] = np.round(T[2], 7)
    exact, rounded = ik_all(model, T), ik_all(model, Tr)
    np.testing.assert_array_equal(rounded.n_solutions, exact.n_solutions)
    for i in range(5):
        assert np.min(wrapped_distance(rounded.solutions((i,)), q[i])) < 1e-4
    one = ik_all(model, np.ascontiguousarray(Tr[2]))
    np.testing.assert_array_equal(one.q, rounded.q[2])
    bad = T.copy()
    bad[3, 0, 0] += 1e-3
    with pytest.raises(InputError, match=r"T_base_flange \(pose \(3,\)\) is not a rigid pose"):
        ik_all(model, bad)
    with pytest.raises(InputError, match="not a rigid pose"):
        ik_all(model, np.ascontiguousarray(bad[3]))


#: Jaco2-type poses (seeds 1, 9, 10, 100, 122 of ``default_rng(seed).uniform(-π, π, (10000, 6))``,
#: indices 958, 402, 1231, 2595, 4251, 2486) away from singular sets (Jacobian σmin/σmax 4e-4
#: to 2e-2) whose real roots in x3 cluster (two to four solutions within 1e-2 of each other):
#: the standard companion alone lost solutions on each (docs/ik-all.md)
CLUSTERED_JACO2 = [
    [-2.9990693597623244, 2.851083638534363, -0.2933357539065655, -1.4712548427920535,
     -1.423546409551335e-05, 2.8023057158851117],
    [1.9908017746558668, 2.102751691031207, 0.04270623573529386, 1.9499435174410493,
     0.7600162212469774, -0.9131653312109211],
    [-0.46298639331932856, -1.576455216457984, -2.631875602055599, 1.28465839015698,
     -2.831596672919139, -0.9390962407344805],
    [-2.795838279438122, 2.6536384322725777, 1.5962027603915674, 1.5215279545921865,
     2.965037610130878, 1.305933511055482],
]
CLUSTERED_SEEDS = [(100, 4251), (122, 2486)]


def test_jaco2_poses_with_clustered_roots_are_complete():
    model = arm("jaco6")
    extra = [np.random.default_rng(s).uniform(-PI, PI, (10000, 6))[i] for s, i in CLUSTERED_SEEDS]
    q = np.vstack([CLUSTERED_JACO2, extra])
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    oracle = newton_solutions(model, T, starts=300, iters=50, seed=3)
    for i, sols in enumerate(oracle):
        mine = res.solutions((i,))
        assert len(mine) and np.min(wrapped_distance(mine, q[i])) < 1e-6, i
        assert len(sols) == res.n_solutions[i], (i, len(sols), res.n_solutions[i])
        for s in sols:
            assert np.min(wrapped_distance(mine, s)) < 1e-6, i
    pos, dR = slot_residuals(model, res, T)
    assert pos.max() <= 1e-9 and dR.max() <= 1e-9
