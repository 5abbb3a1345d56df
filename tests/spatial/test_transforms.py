"""``kinestat.spatial.transforms``: input checking of ``as_array``; rigid-motion properties."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError
from kinestat.spatial.transforms import apply, as_array, compose, inv, rot_x, rot_z, trans


@pytest.mark.parametrize("bad", ["abc", [[1.0, 2.0], [3.0]], [1.0, None, "x"]])
def test_as_array_non_numbers_are_input_errors(bad):
    # used to raise NumPy's bare ValueError ("could not convert string to float")
    with pytest.raises(InputError, match="q must be an array of numbers"):
        as_array(bad, name="q")


def test_as_array_shape_and_finiteness():
    with pytest.raises(InputError, match="trailing shape"):
        as_array(np.zeros(4), shape_tail=(3,))
    with pytest.raises(InputError, match="NaN"):
        as_array([0.0, np.nan, 1.0], shape_tail=(3,))


@settings(max_examples=30, deadline=None)
@given(st.floats(-4, 4), st.floats(-4, 4), st.lists(st.floats(-10, 10), min_size=3, max_size=3))
def test_rigid_motion_preserves_distances_and_inverts(a, b, p):
    T = compose(trans(p), rot_z(a), rot_x(b))
    pts = np.array([[0.0, 0, 0], [1.0, 2, 3], [-2.0, 0.5, 1]])
    q = apply(T, pts)
    d0 = np.linalg.norm(pts[:, None] - pts[None], axis=-1)
    np.testing.assert_allclose(np.linalg.norm(q[:, None] - q[None], axis=-1), d0, atol=1e-9)
    np.testing.assert_allclose(apply(inv(T), q), pts, atol=1e-9)
