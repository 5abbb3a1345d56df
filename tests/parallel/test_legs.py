"""Reverse kinematics: leg lengths from a pose."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kinestat.errors import InputError
from kinestat.io.library import prototype
from kinestat.parallel.legs import leg_lengths, leg_vectors, top_points_in_base
from kinestat.spatial.transforms import make_pose


def test_leg_lengths_direct_distance():
    p = prototype()
    rng = np.random.default_rng(0)
    R = Rotation.from_rotvec(rng.normal(size=(5, 3)) * 0.1).as_matrix()
    t = np.array([30, 52, 60.0]) + rng.normal(size=(5, 3))
    T = make_pose(R, t)
    L = leg_lengths(p, T)
    assert L.shape == (5, 6)
    for k in range(5):
        for i in range(6):
            X = R[k] @ p.top_points[i] + t[k]
            assert L[k, i] == pytest.approx(np.linalg.norm(X - p.base_points[i]), abs=1e-12)
    np.testing.assert_allclose(np.linalg.norm(leg_vectors(p, T), axis=-1), L)
    assert top_points_in_base(p, T).shape == (5, 6, 3)


def test_leg_lengths_invariant_under_common_rigid_motion():
    """Moving base and top together leaves the legs unchanged (distances are preserved)."""
    p = prototype()
    G = make_pose(Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix(), [5, -7, 11])
    T = p.home_pose
    X = top_points_in_base(p, T) @ G[:3, :3].T + G[:3, 3]
    B = p.base_points @ G[:3, :3].T + G[:3, 3]
    np.testing.assert_allclose(np.linalg.norm(X - B, axis=-1), leg_lengths(p, T), atol=1e-12)


@pytest.mark.parametrize("pose", [np.eye(3), np.full((4, 4), np.nan), 2 * np.eye(4),
                                  np.r_[np.eye(4)[:3], [[1, 0, 0, 1]]]])
def test_bad_poses_raise(pose):
    with pytest.raises(InputError):
        leg_lengths(prototype(), pose)


def test_non_rigid_pose_messages_say_what_is_wrong():
    # the message used to list every possible fault at once, with no size and no batch index
    from kinestat.parallel.legs import as_pose

    p = prototype()
    T = np.broadcast_to(p.home_pose, (3, 4, 4)).copy()
    T[1, 0, 1] += 4.4e-5                           # a rotation typed to four digits
    rotation = r"\(pose \(1,\)\) is not a rigid pose: its rotation part"
    with pytest.raises(InputError, match=rotation) as exc:
        as_pose(T)
    R = T[1, :3, :3]
    reported = float(str(exc.value).split("= ")[1].split(",")[0])
    assert reported == pytest.approx(np.abs(R @ R.T - np.eye(3)).max(), rel=0.05)
    T = p.home_pose.copy()
    T[3, 2] = 1.0
    with pytest.raises(InputError, match=r"the last row of a pose must be \[0, 0, 0, 1\]"):
        leg_lengths(p, T)


def test_the_compiled_line_jacobian_is_the_numpy_one():
    """line_jacobian_trusted (compiled, unvalidated) against line_jacobian (validated, NumPy)
    over a batch of random poses (leading dimensions kept), to rounding; a zero-length leg is
    refused."""
    from kinestat.errors import SingularityError
    from kinestat.parallel.legs import line_jacobian, line_jacobian_trusted

    p = prototype()
    rng = np.random.default_rng(3)
    R = Rotation.from_rotvec(rng.normal(size=(4, 5, 3)) * 0.3).as_matrix()
    T = make_pose(R, np.array([0.0, 0.0, 60.0]) + rng.normal(size=(4, 5, 3)) * 10.0)
    got = line_jacobian_trusted(p, T)
    assert got.shape == (4, 5, 6, 6)
    np.testing.assert_allclose(got, line_jacobian(p, T), rtol=0, atol=1e-12)
    T0 = np.eye(4)
    T0[:3, 3] = p.base_points[0] - p.top_points[0]  # top point 0 on base point 0
    with pytest.raises(SingularityError, match="zero length"):
        line_jacobian_trusted(p, T0)
