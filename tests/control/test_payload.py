"""The payload's gravity wrench (:func:`kinestat.control.payload.gravity_wrench`)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinestat.control.payload import Payload, gravity_wrench
from kinestat.errors import ModelError

finite = st.floats(-200, 200, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31), st.floats(0.0, 5.0), finite, finite, finite)
def test_wrench_is_the_weight_through_the_centre_of_mass(seed, mass, cx, cy, cz):
    """Independent of the formula: the weight's line passes through the centre of mass, so its
    moment about that point vanishes, and its force is the weight seen from the base."""
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=rng).as_matrix()
    T = np.eye(4)
    T[:3, :3] = Rotation.random(random_state=rng).as_matrix()
    T[:3, 3] = rng.uniform(-100, 100, 3)
    p = Payload(mass, (cx, cy, cz))
    w = gravity_wrench(p, T, R)
    c_base = T[:3, :3] @ np.array([cx, cy, cz]) + T[:3, 3]
    np.testing.assert_allclose(R @ w[:3], mass * np.array(p.gravity), atol=1e-12)
    np.testing.assert_allclose(w[3:] - np.cross(c_base, w[:3]), 0.0, atol=1e-9)


def test_batch_matches_one_at_a_time():
    rng = np.random.default_rng(3)
    T = np.tile(np.eye(4), (5, 1, 1))
    T[:, :3, 3] = rng.uniform(-50, 50, (5, 3))
    R = Rotation.random(5, random_state=rng).as_matrix()
    p = Payload(0.4, (1.0, 2.0, 30.0))
    W = gravity_wrench(p, T, R)
    assert W.shape == (5, 6)
    for i in range(5):
        np.testing.assert_allclose(W[i], gravity_wrench(p, T[i], R[i]))


@pytest.mark.parametrize("kw, what", [
    ({"mass_kg": -1.0}, "mass"), ({"mass_kg": float("nan")}, "mass"),
    ({"mass_kg": 1.0, "com_top_mm": (1.0, 2.0)}, "com_top_mm"),
    ({"mass_kg": 1.0, "gravity": (0.0, 0.0, float("inf"))}, "gravity"),
])
def test_bad_payload_is_one_clear_error(kw, what):
    with pytest.raises(ModelError, match=what):
        Payload(**kw)
