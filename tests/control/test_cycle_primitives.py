"""Primitives the control cycle uses: the path curvature of a straight path, the platform's
one-stiffness solve and singularity check against NumPy/LAPACK, and the target's key."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.control.contact_estimate import path_curvature
from kinestat.control.controller import THESIS_FORCE_DIRECTION, Target
from kinestat.errors import InputError, KinestatError, SingularityError
from kinestat.parallel import _kinestatic_kernels as kk
from kinestat.parallel.kinestatic import compose_twist, compose_twist_line, solve_one

RNG = np.random.default_rng(23)


@pytest.fixture(scope="module")
def model():
    prep = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=np.array([-400.0, 800.0, -100.0]),
                                          cell=SimulatedCell()))
    return prep.config.model


def _arc(radius: float, n: int, noise: float):
    """``n + 1`` tips on a circle of signed ``radius`` (mm; > 0 convex), with noise; the last
    tip's normal and tangent."""
    a = np.sort(RNG.uniform(0.0, 12.0 / abs(radius), n + 1))
    pts = np.column_stack([radius * np.sin(a), radius * np.cos(a) - radius, 0.0 * a])
    pts += RNG.normal(0.0, noise, pts.shape)
    n_hat = np.sign(radius) * np.array([math.sin(a[-1]), math.cos(a[-1]), 0.0])
    t_hat = np.array([math.cos(a[-1]), -math.sin(a[-1]), 0.0])
    return pts[:-1], pts[-1], n_hat, t_hat


def test_path_curvature_of_collinear_points_is_zero():
    # points on the x axis: the design matrix [x², x, 1] has full rank; y ≡ 0 fits a line
    x = np.linspace(-10.0, 0.0, 8)
    pts = np.column_stack([x, 0.0 * x, 0.0 * x])
    n_hat, t_hat = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    assert path_curvature(pts[:-1], pts[-1], n_hat, t_hat, 1.0) == 0.0


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
