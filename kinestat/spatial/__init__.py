"""Spatial algebra: rigid transforms, Euler angles, Plücker lines, twists and wrenches, and the
screw axis of a finite displacement (Nadkarni 1977, ch. III)."""

from __future__ import annotations

from kinestat.spatial import displacement, euler, plucker, screws, transforms
from kinestat.spatial.displacement import *  # noqa: F403
from kinestat.spatial.euler import *  # noqa: F403
from kinestat.spatial.plucker import *  # noqa: F403
from kinestat.spatial.screws import *  # noqa: F403
from kinestat.spatial.transforms import *  # noqa: F403

__all__ = [
    *transforms.__all__,
    *euler.__all__,
    *plucker.__all__,
    *screws.__all__,
    *displacement.__all__,
]
