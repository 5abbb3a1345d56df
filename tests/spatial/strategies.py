"""Hypothesis strategies shared by the spatial tests."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

coord = st.floats(-100.0, 100.0, allow_nan=False, allow_infinity=False)
vec3 = st.tuples(coord, coord, coord).map(np.array)


@st.composite
def unit_vectors(draw, horizontal: bool | None = None):
    """Unit vectors; ``horizontal=True`` gives u3 = 0 exactly."""
    if horizontal is None:
        horizontal = draw(st.booleans()) and draw(st.booleans())
    if horizontal:
        a = draw(st.floats(-np.pi, np.pi))
        return np.array([np.cos(a), np.sin(a), 0.0])
    z = draw(st.floats(-1.0, 1.0))
    a = draw(st.floats(-np.pi, np.pi))
    r = np.sqrt(max(0.0, 1.0 - z * z))
    return np.array([r * np.cos(a), r * np.sin(a), z])


@st.composite
def rotations(draw):
    u = draw(unit_vectors())
    theta = draw(st.floats(-np.pi, np.pi))
    return Rotation.from_rotvec(theta * u).as_matrix()


@st.composite
def poses(draw):
    T = np.eye(4)
    T[:3, :3] = draw(rotations())
    T[:3, 3] = draw(vec3)
    return T
