"""The single-pose fast path of ik_all (kernels called through their compiled entry point,
results built in their final shape) against the batched call, and its input checks."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.errors import InputError
from kinestat.serial.analytic import closed_form, ik_all, solve
from kinestat.serial.analytic._common import plain_poses

from .arms import PI, arm

_FIELDS = ("q", "valid", "position_error", "rotation_error", "singular", "family_sign",
           "family_value", "n_solutions", "reason")


def _poses(name, n, seed):
    model = arm(name)
    q = np.random.default_rng(seed).uniform(-PI, PI, (n, 6))
    if name in ("puma560", "puma762"):
        q[:3, 4] = 0.0  # wrist-singular poses (families) among them
    return model, kinestat.fk(model, q)


def _assert_same(one, batch, i):
    for f in _FIELDS:
        a, b = getattr(one, f), getattr(batch, f)[i]
        assert isinstance(a, np.ndarray) and a.shape == np.shape(b), f
        np.testing.assert_array_equal(a, b, err_msg=f)
    assert (one.method, one.tol, one.family_joints) == (batch.method, batch.tol,
                                                         batch.family_joints)


@pytest.mark.parametrize("name", ["ur5", "puma560", "puma762", "jaco6", "random1"])
def test_single_call_is_the_batched_result_bit_for_bit(name):
    model, T = _poses(name, 40, seed=11)
    batch = ik_all(model, T)
    for i in range(T.shape[0]):
        one = ik_all(model, T[i])
        assert one.shape == ()
        _assert_same(one, batch, i)
        assert isinstance(one.reason[()], str) and int(one.n_solutions) == one.valid.sum()


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_poses_the_fast_path_must_not_take_give_the_same_solutions(name):
    """Read-only, Fortran-ordered and misaligned poses go through the Numba dispatcher (their
    Numba types differ from the entry point's) and give the same solutions."""
    model, T = _poses(name, 6, seed=3)
    ik_all(model, T[0])  # the entry point is recorded
    ref = ik_all(model, T)
    ro = T.copy()
    ro.flags.writeable = False
    raw = np.zeros(T.nbytes + 8, dtype=np.uint8)
    mis = raw[1:1 + T.nbytes].view(np.float64).reshape(T.shape)  # not 8-byte aligned
    mis[...] = T
    assert not plain_poses(ro) and not plain_poses(mis) and plain_poses(T)
    for variant in (ro, mis, np.asfortranarray(T[0])):
        if variant.ndim == 2:
            one = ik_all(model, variant)
            _assert_same(one, ref, 0)
            continue
        res = ik_all(model, variant)
        for f in _FIELDS:
            np.testing.assert_array_equal(getattr(res, f), getattr(ref, f), err_msg=f)
    _assert_same(ik_all(model, T[1]), ref, 1)  # the fast path still right afterwards


@pytest.mark.parametrize("name", ["ur5", "jaco6"])
def test_fast_path_keeps_the_pose_checks(name):
    model, T = _poses(name, 2, seed=4)
    ik_all(model, T[0])
    bad = [T[0].copy() for _ in range(4)]
    bad[0][3, 2] = 1e-3  # last row
    bad[1][0, 0] += 1e-3  # not orthonormal
    bad[2][1, 3] = np.nan
    bad[3][:3, 0] *= -1.0  # det −1
    for B in bad:
        with pytest.raises(InputError, match="T_base_flange"):
            ik_all(model, B)
    np.testing.assert_array_equal(ik_all(model, T[1]).q, ik_all(model, T).q[1])


def test_integer_tolerance_is_the_float_one():
    """Scalars reach the kernels as floats (one Numba type for the recorded entry point)."""
    model, T = _poses("ur5", 3, seed=6)
    ik_all(model, T[0])
    a, b = ik_all(model, T[1], tol=1), ik_all(model, T[1], tol=1.0)
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.valid, b.valid)


@pytest.mark.parametrize("name", ["ur5", "puma560", "kr16"])
def test_poses_handed_back_for_newton_steps_are_solved_with_them(name):
    """Below 256 unchecked poses the kernels run without Newton steps and hand back a pose
    whose candidate misses tol; the call then solves it with them. At a tolerance near
    rounding (3e-16 × the pose's size) candidates miss: the kernel hands poses back, and the
    result is still the checked call's (Newton steps from the start), bit for bit; in the
    parallel batch (256 poses, whose Newton steps start from the angles of the stored cosines
    and sines, an ulp away) every valid slot is within tol by kinestat.fk (to its rounding,
    which is that size here)."""
    model, T = _poses(name, 256, seed=8)
    tol = 3e-16 * max(1.0, float(np.abs(T[:, :3, 3]).max()))
    kind, data = solve._plan(model)
    compiled = closed_form.solve_pieper_compiled if kind == "pieper" else \
        closed_form.solve_three_parallel_compiled
    back = [compiled(model, np.ascontiguousarray(T[i:i + 1]), data, tol=tol, shape=(),
                     plain=True, checked=False) is None for i in range(40)]
    assert any(back)
    batch = ik_all(model, T, tol=tol)
    part = ik_all(model, T[:40], tol=tol)  # fewer than 256: handed back, solved again
    for i in range(40):
        _assert_same(ik_all(model, T[i], tol=tol), part, i)
    F = kinestat.fk(model, np.where(batch.valid[..., None], batch.q, 0.0))
    pos = np.linalg.norm(F[..., :3, 3] - T[:, None, :3, 3], axis=-1)
    assert batch.valid.sum() > 0 and np.all(pos[batch.valid] <= 2.0 * tol)


def test_a_first_single_call_sets_up_no_batch_kernel():
    """A fresh process's first single call loads the single-pose kernel, not the batch
    kernels' modules (their dispatchers cost a first call's time); a batch loads them."""
    import subprocess
    import sys

    code = ("import sys, numpy as np, kinestat; m = kinestat.load('puma560'); "
            "T = kinestat.fk(m, np.full(6, 0.3)); kinestat.ik_all(m, T); "
            "a = [k for k in sys.modules if k.endswith('_batch')]; "
            "kinestat.ik_all(m, np.stack([T, T])); "
            "b = [k for k in sys.modules if k.endswith('_batch')]; print(a, b)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.split() == ["[]", "['kinestat.serial.analytic._cf_batch']"]
