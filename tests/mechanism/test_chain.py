"""``kinestat.mechanism.chain`` builders: bad tables are ModelErrors, not NumPy errors."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.errors import ModelError
from kinestat.mechanism.chain import from_modified_dh, from_nadkarni, from_standard_dh


@pytest.mark.parametrize("build", [from_standard_dh, from_modified_dh])
@pytest.mark.parametrize("rows, match", [
    ("abc", "array of numbers"),               # used to be NumPy's bare ValueError
    ([[0, 0, 1, 0], [0, 1]], "array of numbers"),
    ([[0, 0, 1]], "rows of 4"),
    ([[0, 0, np.nan, 0]], "NaN"),
])
def test_bad_dh_rows(build, rows, match):
    with pytest.raises(ModelError, match=match):
        build(rows)


def test_bad_nadkarni_rows():
    with pytest.raises(ModelError, match="array of numbers"):
        from_nadkarni([[0, 0, 1, 0, 0], [0, 1]], np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0]]))


def test_planar_2r_reaches_its_closed_form(rng):
    # x = l1 cos q1 + l2 cos(q1 + q2), y = l1 sin q1 + l2 sin(q1 + q2)
    arm = from_standard_dh([[0, 0, 1.5, 0], [0, 0, 0.7, 0]])
    q = rng.uniform(-3, 3, (20, 2))
    p = kinestat.fk(arm, q)[..., :3, 3]
    x = 1.5 * np.cos(q[:, 0]) + 0.7 * np.cos(q.sum(1))
    y = 1.5 * np.sin(q[:, 0]) + 0.7 * np.sin(q.sum(1))
    np.testing.assert_allclose(p, np.stack([x, y, 0 * x], axis=1), atol=1e-12)
