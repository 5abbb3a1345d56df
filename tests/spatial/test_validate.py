"""The single-pose shortcut of :func:`kinestat.spatial.validate.as_pose` against its full checks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kinestat.errors import InputError
from kinestat.spatial.tolerances import LAST_ROW_TOL, ORTHO_TOL
from kinestat.spatial.validate import _one_pose_clear, as_pose


def _full(T):
    """The full checks alone: a batch of one pose does not take the single-pose shortcut."""
    try:
        as_pose(T[None])
    except InputError:
        return False
    return True


def test_the_single_pose_shortcut_never_passes_what_the_full_checks_refuse():
    """Rigid poses spoiled at every scale around the tolerances (the rotation scaled, sheared,
    reflected, the last row moved, NaN and infinity): wherever the shortcut clears a pose, the
    full checks pass it; and as_pose of the pose gives the full checks' verdict. The shortcut
    clears the plainly rigid poses (it is used)."""
    rng = np.random.default_rng(7)
    cleared = refused = 0
    for k in range(2000):
        T = np.eye(4)
        T[:3, :3] = Rotation.random(random_state=rng.integers(1 << 30)).as_matrix()
        T[:3, 3] = rng.normal(size=3) * 100.0
        size = 10.0 ** rng.uniform(-12, -3)
        kind = k % 6
        if kind == 1:
            T[:3, :3] *= 1.0 + size
        elif kind == 2:
            T[:3, :3] += size * rng.normal(size=(3, 3))
        elif kind == 3:
            T[3, rng.integers(4)] += size * 1e-6 * rng.choice([-1.0, 1.0])
        elif kind == 4:
            T[:3, 0] *= -1.0 if k % 12 == 4 else 1.0
            T[rng.integers(4), rng.integers(4)] = [np.nan, np.inf][k % 2] if k % 24 == 4 else \
                T[0, 0]
        elif kind == 5:
            T[:3, :3] *= 1.0 + rng.choice([0.5, 1.0, 2.0]) * ORTHO_TOL * rng.choice([-1.0, 1.0])
        full = _full(T)
        if _one_pose_clear(T.tolist(), ORTHO_TOL, LAST_ROW_TOL):
            cleared += 1
            assert full, (k, T)
        try:
            as_pose(T)
            got = True
        except InputError:
            got = False
            refused += 1
        assert got == full, (k, T)
    assert cleared > 600 and refused > 100
    with pytest.raises(InputError, match="not a rigid pose"):
        as_pose(np.diag([1.0, 1.0, -1.0, 1.0]), "T_base_tool")
