"""The compiled all-mode forward kinematics of the special 6-6 platform against the NumPy
reference ``fk_all``, on random leg lengths and designs."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.errors import InputError, ModelError
from kinestat.io.library import prototype
from kinestat.parallel import _fk_kernels as F
from kinestat.parallel.fk import fk_all
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import Platform, special_6_6

# Appendix B, main.cpp: the prototype's example leg lengths.
THESIS_LEGS = np.array([79.6804, 81.8285, 81.2669, 68.6500, 67.2037, 68.2854])


def assert_same(a, b, tol=1e-9):
    """The same set of modes for every leg-length set, in mirror pairs, each within the
    polish tolerance's reach of the reference's. (The pairs' slot order follows the order in
    which the eigenvalue solver returns the polynomial's roots, which rounding can change.)"""
    assert a.poses.shape == b.poses.shape
    np.testing.assert_array_equal(a.count, b.count)
    assert np.all(np.isnan(a.poses[~a.valid])) and np.all(np.isinf(a.residual[~a.valid]))
    assert np.all(a.residual[a.valid] <= tol)
    A = a.poses.reshape(-1, 16, 4, 4)
    B = b.poses.reshape(-1, 16, 4, 4)
    va, vb = a.valid.reshape(-1, 16), b.valid.reshape(-1, 16)
    for k in np.flatnonzero(va.any(axis=1)):
        d = np.abs(A[k][va[k]][:, None] - B[k][vb[k]][None]).max(axis=(-1, -2))
        assert d.min(axis=1).max() < 1e-8 and d.min(axis=0).max() < 1e-8
    # mirror pairs: a mode in slot 2i, its mirror image through the base plane in 2i + 1
    pair = va[:, 0::2] & va[:, 1::2]
    mirrored = np.diag([1.0, 1.0, -1.0, 1.0]) @ A[:, 0::2] @ np.diag([1.0, 1.0, -1.0, 1.0])
    assert np.max(np.abs(mirrored - A[:, 1::2])[pair], initial=0.0) < 1e-8


@pytest.mark.parametrize("spread", [0.05, 0.3, 1.0])
def test_random_lengths_match_reference(spread):
    p = prototype()
    rng = np.random.default_rng(int(spread * 100))
    L = p.free_lengths * (1 + rng.uniform(-spread, spread, (400, 6)))
    a = fk_all(p, L)
    assert_same(a, fk_all(p, L, backend="numpy"))
    # every valid mode reproduces its legs (reverse kinematics, independent of both solvers)
    modes = a.poses[a.valid]
    legs = np.broadcast_to(L[:, None, :], a.valid.shape + (6,))[a.valid]
    assert np.max(np.abs(leg_lengths(p, modes) - legs), initial=0.0) <= 1e-9


def test_thesis_example_and_shapes():
    p = prototype()
    a = fk_all(p, THESIS_LEGS)
    assert a.poses.shape == (16, 4, 4) and int(a.count) == 8
    assert_same(a, fk_all(p, THESIS_LEGS, backend="numpy"))
    rng = np.random.default_rng(7)
    L = p.free_lengths * (1 + rng.uniform(-0.1, 0.1, (2, 3, 6)))
    b = fk_all(p, L)
    assert b.poses.shape == (2, 3, 16, 4, 4) and b.residual.shape == (2, 3, 16)
    assert_same(b, fk_all(p, L, backend="numpy"))


def test_other_designs_and_relabelled_legs():
    rng = np.random.default_rng(8)
    designs = [special_6_6(base_offset=b, top_offset=t, twist=np.radians(w), height=h)
               for b, t, w, h in ((20.0, 10.0, -40.0, 50.0), (40.0, 25.0, 10.0, 70.0),
                                  (50.0, 8.0, -100.0, 40.0))]
    p = prototype()
    perm = [3, 0, 5, 1, 4, 2]
    designs.append(Platform(base_points=p.base_points[perm], top_points=p.top_points[perm],
                            stiffness=p.stiffness[perm], free_lengths=p.free_lengths[perm],
                            home_pose=p.home_pose,
                            leg_names=tuple(p.leg_names[i] for i in perm)))
    for q in designs:
        L = q.free_lengths * (1 + rng.uniform(-0.2, 0.2, (150, 6)))
        assert_same(fk_all(q, L), fk_all(q, L, backend="numpy"))


def test_chunks_and_thread_paths_give_the_same_answers(monkeypatch):
    p = prototype()
    rng = np.random.default_rng(9)
    L = p.free_lengths * (1 + rng.uniform(-0.2, 0.2, (50, 6)))
    whole = fk_all(p, L)  # one chunk, parallel kernels
    few = fk_all(p, L[:5])  # single-thread kernels
    np.testing.assert_array_equal(few.poses, whole.poses[:5])
    monkeypatch.setattr(F, "CHUNK", 7)
    chunked = fk_all(p, L)
    np.testing.assert_array_equal(chunked.poses, whole.poses)
    np.testing.assert_array_equal(chunked.valid, whole.valid)


@pytest.mark.parametrize("legs", [
    [-79.0, 81, 81, 68, 67, 68], [0.0, 81, 81, 68, 67, 68], [np.nan, 81, 81, 68, 67, 68],
    [79.0, 81, 81, 68, 67], [[1, 2], [3, 4]],
])
def test_bad_lengths_raise_as_the_reference(legs):
    msgs = []
    for solve in (fk_all, fk_all):
        with pytest.raises(InputError) as ei:
            solve(prototype(), legs)
        msgs.append(str(ei.value))
    assert msgs[0] == msgs[1]


def test_impossible_lengths_and_non_special_platform():
    p = prototype()
    legs = np.array([[500.0, 81, 81, 68, 67, 68], [1.0] * 6, [200.0, 200, 200, 10, 10, 10],
                     [1e300] * 6])
    a = fk_all(p, legs)
    assert not np.any(a.valid)
    assert_same(a, fk_all(p, legs, backend="numpy"))
    rng = np.random.default_rng(10)
    general = Platform(base_points=rng.normal(0, 50, (6, 3)) * [1, 1, 0],
                       top_points=rng.normal(0, 30, (6, 3)) * [1, 1, 0], stiffness=np.ones(6),
                       free_lengths=np.full(6, 80.0), home_pose=p.home_pose)
    with pytest.raises(ModelError, match="special"):
        fk_all(general, np.full(6, 80.0))
