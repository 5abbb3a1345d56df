"""Forward kinematics of the platform: every assembly mode, tracking mode, general 6-6."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from kinestat.errors import InputError, ModelError, SingularityError, UnreachableError
from kinestat.io.library import prototype
from kinestat.parallel._refine import apply_twist, refine
from kinestat.parallel.fk import fk_all, fk_list, fk_numeric, fk_tracking, reduce_to_33
from kinestat.parallel.legs import leg_lengths, top_points_in_base
from kinestat.parallel.platform import Platform, special_6_6
from kinestat.parallel.singularity import singularity_measure
from kinestat.spatial.transforms import make_pose

# Appendix B, main.cpp: the prototype's example leg lengths L_oo, L_pp, L_qq, L_rr, L_ss, L_tt.
THESIS_LEGS = np.array([79.6804, 81.8285, 81.2669, 68.6500, 67.2037, 68.2854])
MIRROR = np.diag([1.0, 1.0, -1.0, 1.0])


def near_home(rng, n=None, rot=0.1, trans=5.0):
    p = prototype()
    shape = () if n is None else (n,)
    tw = rng.normal(size=shape + (6,)) * np.r_[[rot] * 3, [trans] * 3]
    return apply_twist(np.broadcast_to(p.home_pose, shape + (4, 4)), tw)


def test_thesis_example_all_modes_verified():
    p = prototype()
    sol = fk_all(p, THESIS_LEGS)
    assert sol.count == 8  # four mirror pairs
    modes = sol.poses[sol.valid]
    np.testing.assert_allclose(leg_lengths(p, modes), np.tile(THESIS_LEGS, (8, 1)), atol=1e-9)
    for T in modes:  # each mode's mirror image through the base plane is also a mode
        d = np.abs(modes - MIRROR @ T @ MIRROR).max(axis=(-1, -2))
        assert d.min() < 1e-8
    listed = fk_list(p, THESIS_LEGS)
    assert len(listed) == 8
    assert listed[0][2, 3] > 0 and np.allclose(listed[0][:3, 2], [0, 0, 1], atol=0.01)
    assert sum(T[2, 3] > 0 for T in listed) == 4


def test_thesis_example_newton_search_finds_nothing_else():
    """An independent search: Newton from many random poses lands only on the listed modes."""
    p = prototype()
    modes = fk_all(p, THESIS_LEGS)
    modes = modes.poses[modes.valid]
    rng = np.random.default_rng(2)
    M = 4000
    starts = make_pose(Rotation.random(M, random_state=3).as_matrix(),
                       rng.uniform(-100, 200, size=(M, 3)))
    T, r = refine(p.base_points, p.top_points, np.broadcast_to(THESIS_LEGS, (M, 6)), starts,
                  iterations=40)
    found = T[np.abs(r).max(axis=-1) < 1e-9]
    assert len(found) >= 20
    d = np.abs(found[:, None] - modes[None]).max(axis=(-1, -2)).min(axis=1)
    assert d.max() < 1e-6


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_random_poses_near_home_are_recovered(seed):
    p = prototype()
    T = near_home(np.random.default_rng(seed))
    L = leg_lengths(p, T)
    sol = fk_all(p, L)
    assert sol.count >= 2 and sol.count % 2 == 0
    d = np.abs(sol.poses[sol.valid] - T).max(axis=(-1, -2))
    assert d.min() < 1e-8
    assert np.all(sol.residual[sol.valid] <= 1e-9)


@settings(max_examples=25, deadline=None)
@given(st.floats(5, 100), st.floats(3, 50), st.floats(-120, 60), st.floats(30, 90))
def test_home_of_any_design_is_recovered(base_offset, top_offset, twist_deg, height):
    """Symmetric homes make several modes share a fold angle (multiple polynomial roots)."""
    try:
        q = special_6_6(base_offset=base_offset, top_offset=top_offset,
                        twist=np.radians(twist_deg), height=height)
    except ModelError:
        return  # a singular design or home pose: refused, nothing to solve
    # near a singular home the pose is ill-conditioned in the legs (legs within 1e-9 do not pin
    # the pose to 1e-8): only well-conditioned homes are compared tightly
    assume(singularity_measure(q, q.home_pose) > 1e-3)
    sol = fk_all(q, q.free_lengths)
    d = np.abs(sol.poses[sol.valid] - q.home_pose).max(axis=(-1, -2))
    assert d.min() < 1e-8


def test_batched_shapes_and_all_recovered():
    p = prototype()
    rng = np.random.default_rng(5)
    T = near_home(rng, 60, rot=0.15, trans=8.0).reshape(3, 20, 4, 4)
    sol = fk_all(p, leg_lengths(p, T))
    assert sol.poses.shape == (3, 20, 16, 4, 4) and sol.valid.shape == (3, 20, 16)
    d = np.abs(sol.poses - T[..., None, :, :]).max(axis=(-1, -2))
    assert np.all(np.where(sol.valid, d, np.inf).min(axis=-1) < 1e-8)
    assert np.all(np.isnan(sol.poses[~sol.valid]))


def test_reduction_gives_the_equivalent_33_distances():
    p = prototype()
    T = near_home(np.random.default_rng(1), rot=0.2, trans=6.0)
    X = top_points_in_base(p, T)
    O0, P0, Q0 = p.base_points[:3]
    R1, S1, T1 = X[3], X[4], X[5]
    direct = [np.linalg.norm(a - b) for a, b in
              [(O0, R1), (O0, S1), (P0, S1), (P0, T1), (Q0, T1), (Q0, R1)]]
    np.testing.assert_allclose(reduce_to_33(p, leg_lengths(p, T)), direct, rtol=1e-12)


def test_relabelled_legs_give_the_same_poses():
    p = prototype()
    perm = [3, 0, 5, 1, 4, 2]
    q = Platform(base_points=p.base_points[perm], top_points=p.top_points[perm],
                 stiffness=p.stiffness[perm], free_lengths=p.free_lengths[perm],
                 home_pose=p.home_pose, leg_names=tuple(p.leg_names[i] for i in perm))
    a = fk_all(p, THESIS_LEGS)
    b = fk_all(q, THESIS_LEGS[perm])
    assert a.count == b.count
    pa, pb = a.poses[a.valid], b.poses[b.valid]
    assert np.abs(pa[:, None] - pb[None]).max(axis=(-1, -2)).min(axis=1).max() < 1e-8


@pytest.mark.parametrize("legs", [
    [-79.0, 81, 81, 68, 67, 68], [0.0, 81, 81, 68, 67, 68], [np.nan, 81, 81, 68, 67, 68],
    [79.0, 81, 81, 68, 67], [[1, 2], [3, 4]],
])
def test_bad_leg_lengths_raise(legs):
    with pytest.raises(InputError):
        fk_all(prototype(), legs)


def test_impossible_lengths_have_no_assembly():
    p = prototype()
    for legs in ([500.0, 81, 81, 68, 67, 68], [1.0] * 6, [200.0, 200, 200, 10, 10, 10]):
        assert fk_all(p, legs).count == 0
        with pytest.raises(UnreachableError, match="no real assembly"):
            fk_list(p, legs)


def test_tracking_follows_a_small_motion():
    p = prototype()
    rng = np.random.default_rng(4)
    prev = near_home(rng, rot=0.05, trans=2.0)
    T = apply_twist(prev, rng.normal(size=6) * np.r_[[0.003] * 3, [0.1] * 3])
    got = fk_tracking(p, leg_lengths(p, T), prev)
    np.testing.assert_allclose(got, T, atol=1e-9)


def test_tracking_stays_in_a_non_home_mode():
    """From near mode k, tracking returns mode k, not the mode nearest home."""
    p = prototype()
    modes = fk_list(p, THESIS_LEGS)
    target = modes[3]
    prev = apply_twist(target, np.r_[0.004, -0.003, 0.002, 0.2, -0.1, 0.15])
    got = fk_tracking(p, THESIS_LEGS, prev)
    np.testing.assert_allclose(got, target, atol=1e-9)
    batch = fk_tracking(p, np.tile(THESIS_LEGS, (2, 1)), np.stack([prev, modes[0]]))
    np.testing.assert_allclose(batch, np.stack([target, modes[0]]), atol=1e-9)


def test_tracking_refuses_a_jump_to_another_mode():
    p = prototype()
    modes = fk_list(p, THESIS_LEGS)
    # halfway between two modes: Newton lands on one of them, the nearest check or the
    # determinant-sign check must object unless it is genuinely the nearest
    prev = modes[0].copy()
    prev[:3, 3] = 0.5 * (modes[0][:3, 3] + modes[3][:3, 3])
    try:
        got = fk_tracking(p, THESIS_LEGS, prev)
    except (SingularityError, UnreachableError):
        return
    d = [np.abs(got - m).max() for m in modes]
    dist_prev = [np.abs(prev - m).max() for m in modes]
    assert np.argmin(d) == np.argmin(dist_prev)


def _tracked(p, L, prev, backend):
    """fk_tracking's pose (``backend`` "numba") or the NumPy iteration's, checked and verified
    as fk_tracking checks it (``backend`` "numpy": ``_newton_checked`` and the nearest-mode
    test), or the class of the error it raised."""
    import kinestat.parallel.fk as fk_mod

    try:
        if backend == "numba":
            return fk_tracking(p, L, prev)
        Lc = np.asarray(L, dtype=float)
        prev_b = np.broadcast_to(prev, Lc.shape[:-1] + (4, 4)).copy()
        pose = fk_mod._newton_checked(p, Lc, prev_b, 1e-9, 20)
        if p.layout is not None:
            fk_mod._verify_nearest(p, Lc, prev_b, pose, 1e-9, "numpy")
        return pose
    except (SingularityError, UnreachableError) as exc:
        return type(exc)


@pytest.mark.parametrize("platform", ["prototype", "general"])
def test_compiled_tracking_agrees_with_the_numpy_iteration(platform):
    """The compiled Newton (fk_tracking) against the NumPy iteration (``_newton``): the same
    pose to rounding or the same error, from small moves to jumps between modes, near and across
    singular configurations (lengths from poses far from home), for a special and a general
    6-6; and the compiled path decides most small moves itself (it is not always falling back)."""
    import kinestat.parallel.fk as fk_mod

    p = prototype() if platform == "prototype" else _non_special()
    rng = np.random.default_rng(31)
    calls = []
    real_newton = fk_mod._newton

    def counting(*a):
        calls.append(1)
        return real_newton(*a)

    errors = 0
    small = 0
    fallbacks = 0
    for k in range(300):
        scale = [0.002, 0.05, 0.3, 1.0][k % 4]
        prev = near_home(rng, rot=0.3 * scale, trans=20.0 * scale)
        target = apply_twist(prev, rng.normal(size=6) * np.r_[[0.05 * scale] * 3,
                                                               [3.0 * scale] * 3])
        L = leg_lengths(p, target) + rng.normal(size=6) * (0.0 if k % 3 else 1e-3)
        if np.any(L <= 0):
            continue
        want = _tracked(p, L, prev, "numpy")
        calls.clear()
        fk_mod._newton = counting
        try:
            got = _tracked(p, L, prev, "numba")
        finally:
            fk_mod._newton = real_newton
        if isinstance(want, type):
            errors += 1
            assert got is want, (k, want, got)
        else:
            assert not isinstance(got, type), (k, got)
            np.testing.assert_allclose(got[:3, :3], want[:3, :3], atol=1e-12)
            np.testing.assert_allclose(got[:3, 3], want[:3, 3], atol=1e-9)
        if scale == 0.002:
            small += 1
            fallbacks += bool(calls)
    assert errors > 0  # the draw reaches the refusals too
    assert fallbacks <= 0.05 * small
    # a batch with one pose the compiled path cannot decide: the whole batch by NumPy, the
    # same error
    L = np.stack([leg_lengths(p, p.home_pose), np.full(6, 1.0)])
    assert _tracked(p, L, np.stack([p.home_pose] * 2), "numpy") is UnreachableError
    with pytest.raises(UnreachableError, match="did not converge"):
        fk_tracking(p, L, np.stack([p.home_pose] * 2))


def test_tracking_backend_is_deprecated_but_accepted():
    p = prototype()
    L = leg_lengths(p, p.home_pose)
    for backend in ("numba", "numpy"):
        with pytest.warns(DeprecationWarning, match="leave the argument out"):
            got = fk_tracking(p, L, p.home_pose, backend=backend)
        np.testing.assert_allclose(got, p.home_pose, atol=1e-9)
    with pytest.warns(DeprecationWarning), pytest.raises(InputError, match="backend"):
        fk_tracking(p, L, p.home_pose, backend="fortran")


def _non_special():
    p = prototype()
    base = p.base_points.copy()
    base[4] += [0.0, 4.0, 0.0]  # S0 off the edge O0P0
    top = p.top_points.copy()
    top[1] += [0.0, 0.0, 3.0]  # P1 off the top plane
    return Platform(base_points=base, top_points=top, stiffness=p.stiffness,
                    free_lengths=p.free_lengths, home_pose=p.home_pose, name="general")


def test_general_platform_numeric_fk_matches_scipy():
    q = _non_special()
    assert q.layout is None
    with pytest.raises(ModelError, match="not a special 6-6"):
        fk_all(q, THESIS_LEGS)
    T = near_home(np.random.default_rng(9), rot=0.08, trans=4.0)
    L = leg_lengths(q, T)
    got = fk_numeric(q, L)
    np.testing.assert_allclose(leg_lengths(q, got), L, atol=1e-9)
    np.testing.assert_allclose(got, T, atol=1e-8)

    def resid(v):  # an independent parameterisation: rotation vector + translation
        G = make_pose(Rotation.from_rotvec(v[:3]).as_matrix(), v[3:])
        return leg_lengths(q, G) - L

    v0 = np.r_[Rotation.from_matrix(q.home_pose[:3, :3]).as_rotvec(), q.home_pose[:3, 3]]
    sol = least_squares(resid, v0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    ref = make_pose(Rotation.from_rotvec(sol.x[:3]).as_matrix(), sol.x[3:])
    np.testing.assert_allclose(got, ref, atol=1e-7)


def test_numeric_fk_reports_failure():
    q = _non_special()
    with pytest.raises(UnreachableError):
        fk_numeric(q, [500.0, 81, 81, 68, 67, 68])


def test_thesis_printed_coordinates_still_solve_all_modes():
    """eq_wrench.m's points, printed to 4 decimals, are special to 1e-6 of the size: the closed
    form seeds Newton on the real legs, and the same 8 modes come out verified."""
    base = [[0.0, 0, 0], [120.0, 0, 0], [60.0, 103.9230, 0], [46.0, 79.6743, 0], [28.0, 0, 0],
            [106.0, 24.2487, 0]]
    top = [[14.0, 0, 0], [53.0, 12.1244, 0], [23.0, 39.8371, 0], [0.0, 0, 0], [60.0, 0, 0],
           [30.0, 51.9615, 0]]
    p = prototype()
    q = Platform(base_points=base, top_points=top, stiffness=p.stiffness,
                 free_lengths=p.free_lengths, home_pose=p.home_pose, name="printed")
    assert q.layout is not None
    sol = fk_all(q, THESIS_LEGS)
    assert sol.count == 8
    np.testing.assert_allclose(leg_lengths(q, sol.poses[sol.valid]),
                               np.tile(THESIS_LEGS, (8, 1)), atol=1e-9)


def test_absurd_lengths_are_unreachable_without_numpy_warnings():
    # 1e300 overflowed in the 3-3 reduction and printed a RuntimeWarning before the error
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UnreachableError, match="no real assembly"):
            fk_list(prototype(), [1e300] * 6)
        assert fk_all(prototype(), [1e300] * 6).count == 0
