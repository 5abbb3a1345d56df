"""The control cycle's one-value primitives against the NumPy formulations they stand for
(issue 13, compute time): the follow estimator's cone normal, friction sample and path
curvature, the one-stiffness solve and singularity check, the vernier's compiled tables, the
plain-dataclass ``replace`` and ``norm3``."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.control.contact_estimate import (
    cone_normal,
    cone_normal_one,
    friction_sample,
    friction_sample_one,
    path_curvature,
    path_curvature_one,
)
from kinestat.control.controller import THESIS_FORCE_DIRECTION, Target
from kinestat.control.cycle import mount_inverse, norm3, replace
from kinestat.control.follow import FollowState
from kinestat.control.vernier import AXIS_OFFSETS, ZERO_OFFSETS, vernier_tables, vernier_tables_one
from kinestat.errors import InputError, KinestatError, SingularityError
from kinestat.parallel import _kinestatic_kernels as kk
from kinestat.parallel.kinestatic import compose_twist, compose_twist_line, solve_one
from kinestat.spatial.transforms import inv

RNG = np.random.default_rng(23)


@pytest.fixture(scope="module")
def model():
    prep = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=np.array([-400.0, 800.0, -100.0]),
                                          cell=SimulatedCell()))
    return prep.config.model


def test_cone_normal_and_friction_sample_one_are_the_batched_ones():
    for _ in range(3000):
        f, s = RNG.normal(size=(2, 3)) * 10.0 ** RNG.uniform(-3, 3, (2, 1))
        mu = RNG.uniform(0.0, 1.0)
        np.testing.assert_allclose(cone_normal_one(f, s, mu), cone_normal(f, s, mu),
                                   rtol=0, atol=4e-16)
        assert friction_sample_one(f, s) == pytest.approx(friction_sample(f, s), rel=1e-14,
                                                          abs=1e-15)


def _arc(radius: float, n: int, noise: float):
    """``n + 1`` tips on a circle of signed ``radius`` (mm; > 0 convex), with noise; the last
    tip's normal and tangent."""
    a = np.sort(RNG.uniform(0.0, 12.0 / abs(radius), n + 1))
    pts = np.column_stack([radius * np.sin(a), radius * np.cos(a) - radius, 0.0 * a])
    pts += RNG.normal(0.0, noise, pts.shape)
    n_hat = np.sign(radius) * np.array([math.sin(a[-1]), math.cos(a[-1]), 0.0])
    t_hat = np.array([math.cos(a[-1]), -math.sin(a[-1]), 0.0])
    return pts[:-1], pts[-1], n_hat, t_hat


def test_compiled_path_curvature_is_the_lstsq_one():
    nonzero = 0
    for _ in range(1500):
        radius = RNG.uniform(30.0, 2000.0) * RNG.choice([-1.0, 1.0])
        pts, tip, n_hat, t_hat = _arc(radius, int(RNG.integers(2, 13)),
                                      float(RNG.choice([0.0, 1e-4, 1e-3, 1e-2])))
        ref = path_curvature(pts, tip, n_hat, t_hat, 1.0)
        got = path_curvature_one(pts, tip, n_hat, t_hat, 1.0)
        assert got == pytest.approx(ref, rel=1e-9, abs=1e-15)
        nonzero += ref != 0.0
    assert nonzero > 300  # the fits were really compared, not only the early returns


def test_path_curvature_of_collinear_points_falls_back_to_lstsq():
    # points on the x axis: the design matrix [x², x, 1] has full rank; y ≡ 0 fits a line
    x = np.linspace(-10.0, 0.0, 8)
    pts = np.column_stack([x, 0.0 * x, 0.0 * x])
    n_hat, t_hat = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    assert path_curvature_one(pts[:-1], pts[-1], n_hat, t_hat, 1.0) == \
        path_curvature(pts[:-1], pts[-1], n_hat, t_hat, 1.0) == 0.0


def test_solve_one_is_numpy_solve_and_raises_on_a_singular_k():
    for _ in range(2000):
        K = RNG.normal(size=(6, 6)) * 10.0 ** RNG.uniform(-2, 3, (1, 6))
        b = RNG.normal(size=6)
        np.testing.assert_allclose(solve_one(K, b), np.linalg.solve(K, b),
                                   rtol=1e-9 * np.linalg.cond(K) * 1e-6 + 1e-12, atol=0)
    K = np.ones((6, 6))
    with pytest.raises(np.linalg.LinAlgError):
        solve_one(K, np.ones(6))


def test_jacobi_singular_ratio_is_lapacks():
    for i in range(2000):
        U, _, Vt = np.linalg.svd(RNG.normal(size=(6, 6)))
        s = np.sort(10.0 ** RNG.uniform(-3, 3, 6))[::-1]
        if i % 3 == 0:
            s[-1] = s[0] * 10.0 ** RNG.uniform(-17, -9)  # near or below the 1e-12 threshold
        K = (U * s) @ Vt
        ref = np.linalg.svd(K, compute_uv=False)
        assert kk.singular_ratio6(K) == pytest.approx(ref[-1] / ref[0], rel=1e-6, abs=1e-15)
    assert kk.singular_ratio6(np.full((6, 6), np.nan)) == 0.0


def test_compose_twist_line_refuses_a_singular_or_nonfinite_k_as_compose_twist():
    w = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    Tf = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    bad = [np.diag([10.0, 10.0, 10.0, 1.0, 1.0, 10.0 * s]) for s in (0.0, 1e-13, 5e-13)]
    K = np.eye(6)
    K[2, 3] = np.inf
    bad.append(K)
    for K in bad:
        with pytest.raises(KinestatError) as ref:
            compose_twist(K, w, Tf, 2.0 * w)
        with pytest.raises(type(ref.value), match=re.escape(str(ref.value))):
            compose_twist_line(K, w, Tf, 2.0 * w)
    assert isinstance(ref.value, InputError)
    K = np.diag([10.0, 10.0, 10.0, 1.0, 1.0, 3e-11])  # regular: s_min/s_max = 3e-12
    np.testing.assert_array_equal(compose_twist_line(K, w, Tf, 2.0 * w),
                                  compose_twist(K, w, Tf, 2.0 * w))
    with pytest.raises(SingularityError):
        compose_twist_line(bad[1], w, Tf, 2.0 * w)


def test_compiled_vernier_tables_are_the_numpy_tables(model):
    for _ in range(1000):
        c0 = RNG.integers(-2_000_000, 2_000_000, 6)
        now = c0 + RNG.integers(-3000, 3000, 6)
        for offsets in (AXIS_OFFSETS, ZERO_OFFSETS):
            for a, b in zip(vernier_tables(model, c0, now, offsets),
                            vernier_tables_one(model, c0, now, offsets), strict=True):
                assert a.shape == b.shape
                np.testing.assert_array_max_ulp(a, b, maxulp=1)  # bit for bit here


def test_replace_is_dataclasses_replace():
    st = FollowState(cycle=3, label="f", last_action="follow",
                     target=Target(np.zeros(3), np.array([0.0, 0.0, 1.0]), np.ones(3)),
                     axis_counts=np.arange(6), top_pose=np.eye(4), normal=np.ones(3) / 3,
                     path=(np.zeros(3),), travel=1.5)
    for changes in ({}, {"cycle": 4}, {"travel": 2.0, "label": "e", "done": True},
                    {"normal": None, "path": ()}):
        a, b = replace(st, **changes), dataclasses.replace(st, **changes)
        assert type(a) is type(b) is FollowState
        assert vars(a).keys() == vars(b).keys()
        for k in vars(b):
            assert getattr(a, k) is getattr(b, k)
        with pytest.raises(dataclasses.FrozenInstanceError):
            a.cycle = 9
    with pytest.raises(TypeError):
        replace(st, no_such_field=1)
    # a class with __post_init__ still runs it (through dataclasses.replace)
    seen = []

    @dataclasses.dataclass(frozen=True)
    class Checked:
        x: float

        def __post_init__(self) -> None:
            seen.append(self.x)

    assert replace(Checked(1.0), x=2.0).x == 2.0 and seen == [1.0, 2.0]


def test_norm3_and_mount_inverse(model):
    for _ in range(2000):
        v = RNG.normal(size=3) * 10.0 ** RNG.uniform(-6, 6)
        # equal to rounding: NumPy's norm may sum the squares in another order (SIMD) on
        # another machine, a few ulps apart (2.3e-16 relative seen on 2026-12-02)
        assert norm3(v) == pytest.approx(float(np.linalg.norm(v)), rel=1e-15)
    M = mount_inverse(model)
    np.testing.assert_array_equal(M, inv(model.mount))
    assert mount_inverse(model) is M and not M.flags.writeable


def test_compiled_prediction_wrapping_equals_the_numpy_wrapping():
    """envelope.predict's one-call kernel against the platform kernel wrapped in NumPy, on the
    measurements of a simulated press run and random flange moves."""
    import copy
    import functools
    import tempfile
    from pathlib import Path

    from kinestat.app.sim_cell import InProcessIO, start_counts
    from kinestat.control import predict as env_mod
    from kinestat.control.controller import decide
    from kinestat.control.log import CycleLog
    from kinestat.control.loop import run
    from kinestat.spatial.se3 import twist_exp

    prep = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=np.array([-400.0, 800.0, -100.0]),
                                          cell=SimulatedCell()))
    meas = []

    def recording(state, m):
        meas.append(m)
        return functools.partial(decide, prep.config)(state, m)

    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with tempfile.TemporaryDirectory() as tmp, CycleLog(Path(tmp) / "log.jsonl") as log:
        run(prep.config, io, log, decide_fn=recording)
    model = prep.config.model
    compared = 0
    for m in meas:
        for _ in range(10):
            dT = twist_exp(np.concatenate([RNG.normal(0, 0.01, 3), RNG.normal(0, 1.0, 3)]))
            Tn = m.flange_pose @ dT
            a = env_mod._predict_compiled(model, copy.copy(m), Tn)
            b = env_mod._predict_numpy_wrapped(model, copy.copy(m), Tn)
            for x, y in ((a.force, b.force), (a.deflections, b.deflections),
                         (a.tip_motion, b.tip_motion), (a.top_pose, b.top_pose)):
                np.testing.assert_allclose(x, y, rtol=1e-12, atol=1e-12)
            compared += 1
    assert compared >= 30


def test_target_key_is_numpys_rounding():
    """Target.key (scalars) against the NumPy rounding it replaced (ties to even, int64), on
    random targets, ties and values near the rounding's halves; non-finite values keep NumPy's
    cast instead of raising."""
    rng = np.random.default_rng(5)

    def numpy_key(t):
        return tuple(np.round(np.concatenate([t.tool_point * 1e6, t.s6 * 1e9, t.a67 * 1e9]))
                     .astype(np.int64).tolist())

    cases = [Target(rng.normal(size=3) * 10.0 ** rng.integers(-9, 4), rng.normal(size=3),
                    rng.normal(size=3)) for _ in range(500)]
    cases.append(Target(np.array([0.5e-6, 1.5e-6, -2.5e-6]), np.array([0.5e-9, 0.0, -1.0]),
                        np.array([1.0, 2.5e-9, 0.0])))
    for t in cases:
        assert t.key() == numpy_key(t)
    with np.errstate(invalid="ignore"):
        bad = Target(np.array([np.nan, 0.0, 1.0]), np.zeros(3), np.zeros(3))
        assert t.key() is not None and bad.key() == numpy_key(bad)
