"""The public kernels' contracts, checked over a catalogue of functions and generated inputs.

For every kernel in :data:`CASES` (spatial algebra, serial FK/Jacobian/IK, platform statics and
stiffness): a batch equals the loop over its items, batches of 0, 1 and (3, 1) keep their leading
shape, lists, read-only, strided, Fortran-ordered and float32 arrays give the same values, the
inputs are never written to, and bad input (NaN, infinity, a wrong shape, a string, a pose that
is not rigid) raises ONE :class:`~kinestat.errors.InputError` naming the argument. No expected
value is written here: each property compares the function with itself.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import kinestat
from kinestat import parallel as P
from kinestat.errors import InputError
from kinestat.io.library import prototype
from kinestat.mechanism.chain import from_standard_dh
from kinestat.mechanism.nadkarni import hand_points
from kinestat.serial.analytic import ik_all, select_nearest
from kinestat.serial.fk import fk_frames, joint_axes
from kinestat.serial.guidance import command_path, joint_rates, run_guidance
from kinestat.serial.ik import wrap_joints
from kinestat.serial.jacobian import fk_and_jacobian
from kinestat.serial.lengths import characteristic_length
from kinestat.spatial import displacement, euler, plucker, screws, se3

PUMA = kinestat.load("puma560")
UR5 = kinestat.load("ur5")
STANFORD = kinestat.load("stanford")
PLATFORM = prototype()
NADKARNI = kinestat.load("nadkarni-config2")
#: a redundant arm with a prismatic joint: its least-squares joint rates depend on the
#: characteristic length of each configuration
ARM7P = from_standard_dh(
    np.c_[np.zeros(7), [0.3, 0.0, 0.4, 0.0, 0.4, 0.0, 0.1], [0.0, 0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
          [-1.5708, 1.5708, -1.5708, 1.5708, -1.5708, 1.5708, 0.0]],
    ["revolute", "prismatic", "revolute", "revolute", "revolute", "revolute", "revolute"],
    name="arm7p")

Gen = Callable[[np.random.Generator], np.ndarray]


def _pose(rng: np.random.Generator) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rng.uniform(-2.0, 2.0, 3)).as_matrix()
    T[:3, 3] = rng.uniform(-1.0, 1.0, 3)
    return T


def _arm_pose(model) -> Gen:
    return lambda rng: kinestat.fk(model, rng.uniform(-1.0, 1.0, model.n))


def _platform_pose(rng: np.random.Generator) -> np.ndarray:
    T = PLATFORM.home_pose.copy()
    T[:3, :3] = Rotation.from_rotvec(rng.uniform(-0.05, 0.05, 3)).as_matrix() @ T[:3, :3]
    T[:3, 3] += rng.uniform(-2.0, 2.0, 3)
    return T


def _line(rng: np.random.Generator) -> np.ndarray:
    return plucker.line_from_points(rng.uniform(-1.0, 1.0, 3), rng.uniform(2.0, 3.0, 3))


def _vec(n: int, lo: float = -1.0, hi: float = 1.0) -> Gen:
    return lambda rng: rng.uniform(lo, hi, n)


class Case(NamedTuple):
    name: str
    call: Callable
    gens: tuple  # one generator of ONE item per batched argument
    args: tuple  # the arguments' names, as the error message must name them
    poses: tuple = ()  # the indices of the arguments that are rigid poses (..., 4, 4)
    none_ok: bool = False  # None is a valid value of the first argument (its default)


CASES = [
    Case("fk", lambda q: kinestat.fk(PUMA, q), (_vec(6),), ("q",)),
    Case("jacobian", lambda q: kinestat.jacobian(PUMA, q), (_vec(6),), ("q",)),
    Case("fk_and_jacobian", lambda q: fk_and_jacobian(PUMA, q), (_vec(6),), ("q",)),
    Case("fk_frames", lambda q: fk_frames(PUMA, q), (_vec(6),), ("q",)),
    Case("joint_axes", lambda q: joint_axes(PUMA, q), (_vec(6),), ("q",)),
    Case("wrap_joints", lambda q: wrap_joints(PUMA, q), (_vec(6, -9.0, 9.0),), ("q",)),
    Case("characteristic_length", lambda q: characteristic_length(STANFORD, q), (_vec(6),),
         ("q",), none_ok=True),
    Case("joint_rates", lambda q, V: joint_rates(ARM7P, q, V, 1.0), (_vec(7), _vec(6)),
         ("q", "twist")),
    Case("ik_all.pieper", lambda T: ik_all(PUMA, T), (_arm_pose(PUMA),), ("T_base_flange",),
         (0,)),
    Case("ik_all.three_parallel", lambda T: ik_all(UR5, T), (_arm_pose(UR5),),
         ("T_base_flange",), (0,)),
    Case("ik_all.decoupled", lambda T: ik_all(STANFORD, T), (_arm_pose(STANFORD),),
         ("T_base_flange",), (0,)),
    Case("ik_all.locked", lambda T: ik_all(ARM7P, T, locked={1: 0.2}),
         (lambda rng: kinestat.fk(ARM7P, np.insert(rng.uniform(-1.0, 1.0, 6), 1, 0.2)),),
         ("T_base_flange",), (0,)),
    # no random restarts: a restart draws from a stream keyed by the target's index in the batch
    Case("ik", lambda T: kinestat.ik(PUMA, T, restarts=0), (_arm_pose(PUMA),), ("target poses",),
         (0,)),
    Case("adjoint", screws.adjoint, (_pose,), ("T",), (0,)),
    Case("transform_twist", screws.transform_twist, (_pose, _vec(6)), ("T", "twist"), (0,)),
    Case("transform_wrench", screws.transform_wrench, (_pose, _vec(6)), ("T", "wrench"), (0,)),
    Case("screw_axis", screws.screw_axis, (_vec(6),), ("screw",)),
    Case("so3_exp", se3.so3_exp, (_vec(3),), ("w",)),
    Case("so3_log", se3.so3_log, (lambda rng: _pose(rng)[:3, :3],), ("R",)),
    Case("twist_exp", se3.twist_exp, (_vec(6),), ("twist",)),
    Case("pose_error", se3.pose_error, (_pose, _pose), ("T", "T_target"), (0, 1)),
    Case("screw_from_poses", displacement.screw_from_poses, (_pose, _pose),
         ("pose 1", "pose 2"), (0, 1)),
    Case("euler_from_matrix", lambda R: euler.euler_from_matrix(R, "zyz"),
         (lambda rng: _pose(rng)[:3, :3],), ("R",)),
    Case("transform_line", lambda T, L: plucker.transform_line(T, L),
         (_pose, _line), ("T", "line"), (0,)),
    Case("line_distance", plucker.line_distance, (_line, _line), ("l1", "l2")),
    Case("common_normal", plucker.common_normal, (_line, _line), ("l1", "l2")),
    Case("classify_lines", plucker.classify_lines, (_line, _line), ("l1", "l2")),
    Case("hand_points", hand_points, (_pose,), ("hand_pose",), (0,)),
    Case("leg_lengths", lambda T: P.leg_lengths(PLATFORM, T), (_platform_pose,), ("pose",), (0,)),
    Case("line_jacobian", lambda T: P.line_jacobian(PLATFORM, T), (_platform_pose,), ("pose",),
         (0,)),
    Case("stiffness", lambda T: P.stiffness(PLATFORM, T), (_platform_pose,), ("pose",), (0,)),
    Case("wrench_from_forces", lambda T, f: P.wrench_from_forces(PLATFORM, T, f),
         (_platform_pose, _vec(6)), ("pose", "forces"), (0,)),
    Case("spring_forces", lambda lengths: P.spring_forces(PLATFORM, lengths),
         (lambda rng: P.leg_lengths(PLATFORM, _platform_pose(rng)),), ("lengths",)),
]
IDS = [c.name for c in CASES]


def _arrays(result) -> list[np.ndarray]:
    """The arrays of a result (an array, a tuple of them, a dict, a dataclass), in order."""
    if isinstance(result, np.ndarray):
        return [result]
    if dataclasses.is_dataclass(result):
        values = [getattr(result, f.name) for f in dataclasses.fields(result)]
        return [v for v in values if isinstance(v, np.ndarray)]
    if isinstance(result, dict):
        return [np.asarray(v) for v in result.values()]
    if isinstance(result, (tuple, list)):
        return [a for r in result for a in _arrays(r)]
    return [np.asarray(result)]


def _assert_same(got, want, rtol: float = 1e-12) -> None:
    a_list, b_list = _arrays(got), _arrays(want)
    assert len(a_list) == len(b_list)
    for a, b in zip(a_list, b_list, strict=True):
        a, b = np.asarray(a), np.asarray(b)
        assert a.shape == b.shape
        if a.dtype.kind == "f":
            finite = np.isfinite(b)
            assert np.array_equal(np.isnan(a), np.isnan(b))
            scale = max(1.0, float(np.max(np.abs(b[finite]), initial=0.0)))
            np.testing.assert_allclose(a[finite], b[finite], rtol=0, atol=rtol * scale)
        else:
            np.testing.assert_array_equal(a, b)


def _call(case: Case, args):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a NaN slot of an unreachable pose
        return case.call(*args)


def _items(case: Case, seed: int, n: int) -> list[list[np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [[g(rng) for g in case.gens] for _ in range(n)]


def _batch(items, case: Case, n: int) -> list[np.ndarray]:
    if n == 0:
        one = [g(np.random.default_rng(0)) for g in case.gens]
        return [np.empty((0,) + a.shape) for a in one]
    return [np.stack([it[k] for it in items]) for k in range(len(case.gens))]


@pytest.mark.parametrize("case", CASES, ids=IDS)
@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.sampled_from([0, 1, 3]))
def test_batch_equals_loop(case, seed, n):
    """A batch of N is the loop over its N items, with the batch's leading shape."""
    items = _items(case, seed, n)
    batch = _batch(items, case, n)
    copies = [b.copy() for b in batch]
    result = _call(case, batch)
    for b, c in zip(batch, copies, strict=True):
        np.testing.assert_array_equal(b, c)  # the inputs are not written to
    for a in _arrays(result):
        if a.ndim:
            assert a.shape[0] == n
    batched = _arrays(result)
    for i, item in enumerate(items):
        pairs = list(zip(_arrays(_call(case, item)), batched, strict=True))
        _assert_same([b[i] for _, b in pairs if b.ndim], [a for a, b in pairs if b.ndim])


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_nested_batch_keeps_its_shape(case):
    """A (3, 1) batch gives (3, 1, ...) outputs equal to the flat batch's."""
    items = _items(case, 7, 3)
    flat = _batch(items, case, 3)
    result = _call(case, [b[:, None] for b in flat])
    want = _call(case, flat)
    for a, b in zip(_arrays(result), _arrays(want), strict=True):
        if b.ndim:
            assert a.shape == b.shape[:1] + (1,) + b.shape[1:]
            _assert_same(a[:, 0], b)


def _readonly(a: np.ndarray) -> np.ndarray:
    a = a.copy()
    a.setflags(write=False)
    return a


LAYOUTS = {
    "list": lambda a: a.tolist(),
    "readonly": _readonly,
    "strided": lambda a: np.repeat(a, 2, axis=0)[::2],
    "fortran": np.asfortranarray,
}


@pytest.mark.parametrize("layout", sorted(LAYOUTS))
@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_layouts_give_the_same_values(case, layout):
    """Lists, read-only, strided and Fortran-ordered arrays (batched and single) are accepted
    and give the values of a C-contiguous float64 array."""
    items = _items(case, 11, 3)
    batch = _batch(items, case, 3)
    change = LAYOUTS[layout]
    _assert_same(_call(case, [change(b) for b in batch]), _call(case, batch))
    single = [change(a) if layout != "strided" else np.repeat(a[None], 2, axis=0)[0][..., ::1]
              for a in items[0]]
    _assert_same(_call(case, single), _call(case, items[0]))


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_float32_is_read_as_float64(case):
    """float32 input gives float64 output, the values of the same numbers given as float64."""
    items = _items(case, 13, 3)
    low = [b.astype(np.float32) for b in _batch(items, case, 3)]
    result = _call(case, low)
    for a in _arrays(result):
        assert a.dtype != np.float32
    _assert_same(result, _call(case, [b.astype(np.float64) for b in low]))


def _corruptions(case: Case, k: int, b: np.ndarray, rng: np.random.Generator):
    """(label, bad value of argument k) pairs."""
    bad = []
    for value in (np.nan, np.inf, -np.inf):
        x = b.copy()
        x[(int(rng.integers(b.shape[0])),) + tuple(int(rng.integers(s)) for s in b.shape[1:])] \
            = value
        bad.append((f"{value} in the batch", x))
        x = b[0].copy()
        x[tuple(int(rng.integers(s)) for s in x.shape)] = value
        bad.append((f"{value} in one item", x))
    bad += [("trailing size - 1", b[..., :-1]),
            ("trailing size + 1", np.concatenate([b, b[..., :1]], axis=-1)),
            ("a scalar", 1.0), ("a string", "abc")]
    if not (k == 0 and case.none_ok):
        bad.append(("None", None))
    if k in case.poses:
        bad.append(("3x4 poses", b[..., :3, :]))
        x = b.copy()
        x[int(rng.integers(b.shape[0])), :3, :3] *= 1.0 + rng.uniform(1e-4, 0.1)
        bad.append(("a scaled rotation", x))
        x = b.copy()
        x[int(rng.integers(b.shape[0])), :3, :3] = rng.uniform(-1.0, 1.0, (3, 3))
        bad.append(("a random 3x3 block", x))
        x = b.copy()
        x[..., 3, int(rng.integers(3))] = 0.5
        bad.append(("a last row not [0, 0, 0, 1]", x))
    return bad


@pytest.mark.parametrize("case", CASES, ids=IDS)
@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_bad_input_raises_one_input_error_naming_the_argument(case, seed):
    rng = np.random.default_rng(seed)
    batch = _batch(_items(case, seed, 3), case, 3)
    for k, name in enumerate(case.args):
        for label, value in _corruptions(case, k, batch[k], rng):
            args = list(batch)
            args[k] = value
            with pytest.raises(InputError) as info:
                _call(case, args)
            assert name.lower() in str(info.value).lower(), (label, str(info.value))


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_joint_values_outside_the_limits_are_accepted(case):
    """Good input is never refused: FK-type kernels take any finite joint values."""
    if case.args[0] != "q":
        pytest.skip("no joint values")
    items = _items(case, 17, 2)
    big = [it[0] * 1e3 for it in items]
    args = [np.stack(big)] + [np.stack([it[k] for it in items]) for k in range(1, len(case.gens))]
    for a in _arrays(_call(case, args)):
        assert a.shape[:1] == (2,)


SCALARS = [
    ("ik_all tol", lambda v: ik_all(PUMA, kinestat.fk(PUMA, np.full(6, 0.2)), tol=v), "tol"),
    ("ik rot_tol", lambda v: kinestat.ik(PUMA, np.eye(4), rot_tol=v), "rot_tol"),
    ("ik pos_tol", lambda v: kinestat.ik(PUMA, np.eye(4), pos_tol=v), "pos_tol"),
    ("special_6_6 height", lambda v: P.special_6_6(height=v), "height"),
    ("fk_all tol", lambda v: P.fk_all(PLATFORM, PLATFORM.free_lengths, tol=v), "tol"),
    ("fk_numeric tol", lambda v: P.fk_numeric(PLATFORM, PLATFORM.free_lengths, tol=v), "tol"),
    ("fk_tracking tol", lambda v: P.fk_tracking(PLATFORM, PLATFORM.free_lengths,
                                                PLATFORM.home_pose, tol=v), "tol"),
    ("run_guidance length", lambda v: run_guidance(
        NADKARNI, NADKARNI.q_home, [lambda H: command_path(H, [0, 0, 1], 1.0, 0.0)], steps=1,
        length=v), "length"),
    ("command_path distance", lambda v: command_path(np.eye(4), [0, 0, 1], v, 0.0), "distance"),
    ("command_path angle", lambda v: command_path(np.eye(4), [0, 0, 1], 1.0, v), "angle"),
]
COUNTS = [
    ("fk_all polish", lambda v: P.fk_all(PLATFORM, PLATFORM.free_lengths, polish=v), "polish"),
    ("fk_numeric max_iter", lambda v: P.fk_numeric(PLATFORM, PLATFORM.free_lengths, max_iter=v),
     "max_iter"),
    ("fk_tracking max_iter", lambda v: P.fk_tracking(PLATFORM, PLATFORM.free_lengths,
                                                     PLATFORM.home_pose, max_iter=v), "max_iter"),
]


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -1.0, 0.0, "x", None, True])
@pytest.mark.parametrize("name, call, arg", SCALARS, ids=[s[0] for s in SCALARS])
def test_bad_scalar_argument_raises_input_error(name, call, arg, value):
    if value is None and arg in ("pos_tol", "length"):
        pytest.skip(f"None is {arg}'s default")
    if value == 0.0 and arg in ("distance", "angle"):
        pytest.skip(f"0 is a valid {arg}")
    if value == -1.0 and arg in ("distance", "angle"):
        pytest.skip(f"a negative {arg} is valid")
    with pytest.raises(InputError, match=arg):
        call(value)


@pytest.mark.parametrize("value", [-1, 2.5, "x", None, True])
@pytest.mark.parametrize("name, call, arg", COUNTS, ids=[s[0] for s in COUNTS])
def test_bad_count_raises_input_error(name, call, arg, value):
    with pytest.raises(InputError, match=arg):
        call(value)


def test_forces_from_wrench_tolerance_must_be_a_number():
    for tol in (float("nan"), -1.0, "x"):
        with pytest.raises(InputError, match="tol"):
            P.forces_from_wrench(PLATFORM, PLATFORM.home_pose, np.zeros(6), tol=tol)


def test_guidance_entries_refuse_bad_stages_and_starts():
    with pytest.raises(InputError, match="stage"):
        run_guidance(NADKARNI, NADKARNI.q_home, [42], steps=1)
    with pytest.raises(InputError, match="q0"):
        run_guidance(NADKARNI, np.full(NADKARNI.n, np.nan), [], steps=1)
    with pytest.raises(InputError, match="start pose"):
        command_path(2.0 * np.eye(4), [0, 0, 1], 1.0, 0.0)


def test_selection_weights_must_not_be_negative():
    res = ik_all(PUMA, kinestat.fk(PUMA, np.full(6, 0.2)))
    with pytest.raises(InputError, match="weights"):
        select_nearest(PUMA, res, np.zeros(6), weights=-np.ones(6))
    with pytest.raises(InputError, match="weights"):
        select_nearest(PUMA, res, np.zeros(6), weights=np.ones(5))


@pytest.mark.parametrize("call", [kinestat.fk, kinestat.jacobian, ik_all],
                         ids=["fk", "jacobian", "ik_all"])
def test_a_model_that_is_not_a_chain_is_refused(call):
    with pytest.raises(InputError, match="ChainModel"):
        call("puma560", np.eye(4) if call is ik_all else np.zeros(6))


@pytest.mark.parametrize("case", [c for c in CASES if not c.poses and c.args[0] == "q"],
                         ids=lambda c: c.name)
def test_integer_joint_values_are_read_as_float(case):
    """Integer arrays (and lists of ints) are numbers like any other."""
    items = _items(case, 19, 3)
    batch = _batch(items, case, 3)
    q_int = np.rint(batch[0] * 3).astype(np.int64)
    want = _call(case, [q_int.astype(float)] + batch[1:])
    _assert_same(_call(case, [q_int] + batch[1:]), want)
    _assert_same(_call(case, [q_int.tolist()] + batch[1:]), want)


def test_tip_stiffness_rotation_must_be_a_rotation():
    from kinestat.parallel.stiffness import tip_stiffness

    with pytest.raises(InputError, match="rotation"):
        tip_stiffness(PLATFORM, PLATFORM.home_pose, [0.0, 0.0, 0.0], rotation=2.0 * np.eye(3))
