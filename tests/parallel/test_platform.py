"""The platform model and the special 6-6 builder (Vibhute 2011 ch. 3, Appendix B/D)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinestat.errors import InputError, ModelError
from kinestat.io.library import prototype
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import (
    LEG_NAMES,
    Platform,
    special_6_6,
    special_layout,
)

# eq_wrench.m (Vibhute App. D.8): the prototype's joint points, printed to 4 decimals (Q1's
# y = 23 sqrt(3) = 39.83717 is printed truncated as 39.8371).
TOP_PRINTED = {"O": [14.0, 0, 0], "P": [53.0, 12.1244, 0], "Q": [23.0, 39.8371, 0],
               "R": [0.0, 0, 0], "S": [60.0, 0, 0], "T": [30.0, 51.9615, 0]}
BASE_PRINTED = {"O": [0.0, 0, 0], "P": [120.0, 0, 0], "Q": [60.0, 103.9230, 0],
                "R": [46.0, 79.6743, 0], "S": [28.0, 0, 0], "T": [106.0, 24.2487, 0]}


def test_prototype_points_match_the_thesis_code():
    p = prototype()
    assert p.leg_names == LEG_NAMES
    for i, n in enumerate(p.leg_names):
        np.testing.assert_allclose(p.top_points[i], TOP_PRINTED[n], atol=1e-4)
        np.testing.assert_allclose(p.base_points[i], BASE_PRINTED[n], atol=1e-4)


def test_prototype_free_lengths_from_the_design():
    p = prototype()
    # long legs: printed Llong = 80.969 mm (eq. 3-3); short legs: exactly sqrt(60^2 + 32^2) = 68
    # (S1 sits 60 mm above the midpoint (60, 0) of O0P0, S0 is at (28, 0)); printed 68.021.
    np.testing.assert_allclose(p.free_lengths[:3], 80.969, atol=5e-4)
    np.testing.assert_allclose(p.free_lengths[3:], math.hypot(60.0, 32.0), atol=1e-12)
    np.testing.assert_allclose(leg_lengths(p, p.home_pose), p.free_lengths, atol=1e-12)
    np.testing.assert_allclose(p.stiffness, 2.627)


def test_home_pose_puts_top_corners_above_base_edge_midpoints():
    p = prototype()
    T = p.home_pose
    corners_top = p.top_points[3:]  # R1, S1, T1
    X = corners_top @ T[:3, :3].T + T[:3, 3]
    O0, P0, Q0 = p.base_points[:3]
    mids = np.array([(Q0 + O0) / 2, (O0 + P0) / 2, (P0 + Q0) / 2])  # under R1, S1, T1
    np.testing.assert_allclose(X[:, :2], mids[:, :2], atol=1e-12)
    np.testing.assert_allclose(X[:, 2], 60.0, atol=1e-12)
    np.testing.assert_allclose(T[:3, 2], [0, 0, 1], atol=1e-15)  # top parallel to base


def test_builder_general_triangles_and_offsets():
    p = special_6_6(base_side=(120, 110, 100), top_side=(60, 55, 50),
                    base_offset=(20, 30, 25), top_offset=(10, 12, 14), height=55, twist=-1.0)
    b, t = p.base_points, p.top_points
    assert np.linalg.norm(b[1] - b[0]) == pytest.approx(120)
    assert np.linalg.norm(b[2] - b[1]) == pytest.approx(110)
    assert np.linalg.norm(b[0] - b[2]) == pytest.approx(100)
    assert np.linalg.norm(b[4] - b[0]) == pytest.approx(20)  # |O0S0|
    assert np.linalg.norm(b[5] - b[1]) == pytest.approx(30)  # |P0T0|
    assert np.linalg.norm(b[3] - b[2]) == pytest.approx(25)  # |Q0R0|
    assert np.linalg.norm(t[0] - t[3]) == pytest.approx(10)  # |R1O1|
    assert np.linalg.norm(t[1] - t[4]) == pytest.approx(12)  # |S1P1|
    assert np.linalg.norm(t[2] - t[5]) == pytest.approx(14)  # |T1Q1|
    assert p.layout is not None and p.layout.order == tuple(range(6))
    np.testing.assert_allclose(p.layout.t, [10 / 60, 12 / 55, 14 / 50, 25 / 100, 20 / 120,
                                            30 / 110])


def test_layout_detected_under_any_leg_labelling():
    p = prototype()
    perm = [4, 2, 5, 0, 3, 1]
    lay = special_layout(p.base_points[perm], p.top_points[perm])
    assert lay is not None
    # role r is played by permuted leg lay.order[r], i.e. original leg perm[lay.order[r]]; the
    # layout has a three-fold symmetry, so any cyclic relabelling of O, P, Q (with R, S, T) fits
    cyclic = [(0, 1, 2, 3, 4, 5), (1, 2, 0, 4, 5, 3), (2, 0, 1, 5, 3, 4)]
    assert tuple(perm[i] for i in lay.order) in cyclic
    np.testing.assert_allclose(lay.t, p.layout.t)


def test_general_layout_is_not_special():
    rng = np.random.default_rng(0)
    assert special_layout(rng.normal(size=(6, 3)), rng.normal(size=(6, 3))) is None


def test_model_is_immutable():
    p = prototype()
    with pytest.raises(ValueError):
        p.base_points[0, 0] = 1.0
    with pytest.raises(AttributeError):
        p.name = "x"  # type: ignore[misc]


@pytest.mark.parametrize("kwargs, err", [
    ({"base_offset": 130}, InputError),
    ({"top_offset": -1}, InputError),
    ({"base_side": (1, 1, 3)}, InputError),
    ({"height": -5}, InputError),
    ({"stiffness": [1, 2, 3]}, InputError),
    ({"height": float("nan")}, InputError),
    ({"base_offset": 60, "top_offset": 30}, ModelError),
])
def test_builder_rejects_bad_designs(kwargs, err):
    with pytest.raises(err):
        special_6_6(**kwargs)


def test_platform_validation():
    p = prototype()
    good = dict(base_points=p.base_points, top_points=p.top_points, stiffness=p.stiffness,
                free_lengths=p.free_lengths, home_pose=p.home_pose)
    for key, bad in [("base_points", np.zeros((5, 3))), ("stiffness", -p.stiffness),
                     ("free_lengths", np.full(6, np.nan)), ("home_pose", 2 * np.eye(4))]:
        with pytest.raises(ModelError):
            Platform(**{**good, key: bad})
    with pytest.raises(ModelError):
        Platform(**good, leg_names=("a", "a", "b", "c", "d", "e"))


@pytest.mark.parametrize("kwargs, which", [
    ({"base_side": (1, 1, 3)}, "base_side"),
    ({"top_side": -60}, "top_side"),
])
def test_bad_triangle_names_the_triangle_with_plain_numbers(kwargs, which):
    # the message used to show "[np.float64(-60.0), ...]" and not say which triangle
    with pytest.raises(InputError) as exc:
        special_6_6(**kwargs)
    msg = str(exc.value)
    assert msg.startswith(f"{which}: ") and "np.float64" not in msg
