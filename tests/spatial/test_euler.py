"""Euler angles: all 24 conventions, round trips, gimbal lock, peer check, bad input."""

from __future__ import annotations

import numpy as np
import pytest
import spatialmath.base as smb
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError
from kinestat.spatial.euler import (
    EULER_SEQUENCES,
    euler_from_matrix,
    is_proper_sequence,
    matrix_from_euler,
)
from kinestat.spatial.transforms import rot_x, rot_y, rot_z

ELEMENTARY = {"x": rot_x, "y": rot_y, "z": rot_z}
angle = st.floats(-np.pi, np.pi, allow_nan=False)


def _by_hand(angles, seq: str) -> np.ndarray:
    """Compose the elementary rotations directly (independent of SciPy)."""
    mats = [ELEMENTARY[ax.lower()](a)[:3, :3] for ax, a in zip(seq, angles, strict=True)]
    if seq.isupper():  # intrinsic: R = R1 R2 R3
        return mats[0] @ mats[1] @ mats[2]
    return mats[2] @ mats[1] @ mats[0]  # extrinsic: R = R3 R2 R1


def test_there_are_24_distinct_conventions():
    assert len(EULER_SEQUENCES) == 24 == len(set(EULER_SEQUENCES))
    assert sum(s.isupper() for s in EULER_SEQUENCES) == 12
    assert sum(is_proper_sequence(s) for s in EULER_SEQUENCES) == 12


@pytest.mark.parametrize("seq", EULER_SEQUENCES)
@settings(max_examples=15, deadline=None)
@given(a=angle, b=angle, c=angle)
def test_matrix_matches_elementary_product_and_round_trips(seq, a, b, c):
    ang = np.array([a, b, c])
    R = matrix_from_euler(ang, seq)
    np.testing.assert_allclose(R, _by_hand(ang, seq), atol=1e-12)
    back = euler_from_matrix(R, seq)
    np.testing.assert_allclose(matrix_from_euler(back, seq), R, atol=1e-9)


@pytest.mark.parametrize("seq", EULER_SEQUENCES)
def test_gimbal_lock_reported_and_reproduced(seq):
    singular = [0.0, np.pi] if is_proper_sequence(seq) else [np.pi / 2, -np.pi / 2]
    rng = np.random.default_rng(7)
    for mid in singular:
        for _ in range(5):
            a, c = rng.uniform(-np.pi, np.pi, 2)
            R = _by_hand([a, mid, c], seq)
            ang, deg = euler_from_matrix(R, seq, return_degenerate=True)
            assert deg
            assert ang[2] == 0.0
            np.testing.assert_allclose(matrix_from_euler(ang, seq), R, atol=1e-9)


@pytest.mark.parametrize("seq", EULER_SEQUENCES)
@pytest.mark.parametrize("offset", [1e-15, 1e-12, 1e-10, 5e-8, -5e-8])
def test_near_gimbal_lock_is_flagged_and_reproduced(seq, offset):
    """Within GIMBAL_TOL of the lock: flagged, and R is still reproduced to rounding
    (SciPy's own as_euler misses R by up to ~1e-7 there)."""
    mid = (np.pi if is_proper_sequence(seq) and offset < 0 else
           0.0 if is_proper_sequence(seq) else np.pi / 2) + offset
    R = _by_hand([0.4, mid, -1.1], seq)
    ang, deg = euler_from_matrix(R, seq, return_degenerate=True)
    assert deg
    np.testing.assert_allclose(matrix_from_euler(ang, seq), R, atol=1e-12)


@pytest.mark.parametrize("seq", ["ZYX", "xzx"])
def test_just_outside_the_lock_band_is_not_flagged(seq):
    mid = 1e-6 if is_proper_sequence(seq) else np.pi / 2 - 1e-6  # inside the angle ranges
    R = _by_hand([0.4, mid, -1.1], seq)
    ang, deg = euler_from_matrix(R, seq, return_degenerate=True)
    assert not deg
    np.testing.assert_allclose(ang, [0.4, mid, -1.1], atol=1e-9)


def test_batched_and_mask_shape():
    rng = np.random.default_rng(1)
    ang = rng.uniform(-1, 1, (4, 5, 3))
    ang[1, 2, 1] = np.pi / 2
    R = matrix_from_euler(ang, "ZYX")
    assert R.shape == (4, 5, 3, 3)
    back, deg = euler_from_matrix(R, "ZYX", return_degenerate=True)
    assert back.shape == (4, 5, 3) and deg.shape == (4, 5)
    assert deg.sum() == 1 and deg[1, 2]
    np.testing.assert_allclose(matrix_from_euler(back, "ZYX"), R, atol=1e-9)


def test_degrees_flag():
    R = matrix_from_euler([90.0, 0.0, 0.0], "ZYX", degrees=True)
    np.testing.assert_allclose(R, rot_z(np.pi / 2)[:3, :3], atol=1e-15)
    np.testing.assert_allclose(euler_from_matrix(R, "ZYX", degrees=True), [90.0, 0.0, 0.0],
                               atol=1e-12)


def test_peer_zyz_and_rpy():
    """spatialmath (Robotics Toolbox) eul2r is ZYZ intrinsic; rpy2r order='zyx' is ZYX."""
    rng = np.random.default_rng(3)
    for a, b, c in rng.uniform(-3, 3, (10, 3)):
        np.testing.assert_allclose(matrix_from_euler([a, b, c], "ZYZ"), smb.eul2r(a, b, c),
                                   atol=1e-12)
        # rpy2r(roll, pitch, yaw, order='zyx') = Rz(yaw) Ry(pitch) Rx(roll)
        np.testing.assert_allclose(matrix_from_euler([c, b, a], "ZYX"),
                                   smb.rpy2r(a, b, c, order="zyx"), atol=1e-12)


@pytest.mark.parametrize("seq", ["ZZY", "ZyX", "abc", "XY", "", 3])
def test_bad_sequence(seq):
    with pytest.raises(InputError, match="Euler sequence"):
        matrix_from_euler([0, 0, 0], seq)
    with pytest.raises(InputError, match="Euler sequence"):
        euler_from_matrix(np.eye(3), seq)


def test_bad_values():
    with pytest.raises(InputError, match="NaN"):
        matrix_from_euler([0, np.nan, 0], "ZYX")
    with pytest.raises(InputError, match="trailing shape"):
        matrix_from_euler([0, 0], "ZYX")
    with pytest.raises(InputError, match="not a rotation"):
        euler_from_matrix(np.diag([1.0, 1.0, -1.0]), "ZYX")
    R = np.stack([np.eye(3), 2 * np.eye(3)])
    with pytest.raises(InputError, match=r"batch index \(1,\)"):
        euler_from_matrix(R, "xyz")


@pytest.mark.parametrize("seq", EULER_SEQUENCES)
def test_same_angles_as_scipy_away_from_lock(seq):
    from scipy.spatial.transform import Rotation

    R = Rotation.from_rotvec(np.random.default_rng(11).uniform(-2, 2, (50, 3))).as_matrix()
    ang, deg = euler_from_matrix(R, seq, return_degenerate=True)
    assert not deg.any()
    np.testing.assert_allclose(ang, Rotation.from_matrix(R).as_euler(seq), atol=1e-9)
