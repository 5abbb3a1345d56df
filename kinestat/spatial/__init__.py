"""Spatial algebra: rigid transforms, Euler angles, Plücker lines, twists and wrenches, and the
screw axis of a finite displacement (Nadkarni 1977, ch. III), SE(3) exp/log and the pose error
(:mod:`~kinestat.spatial.se3`), and the input validators (:mod:`~kinestat.spatial.validate`)."""

from __future__ import annotations

from kinestat.spatial import displacement, euler, plucker, screws, se3, transforms, validate
from kinestat.spatial.displacement import *  # noqa: F403
from kinestat.spatial.euler import *  # noqa: F403
from kinestat.spatial.plucker import *  # noqa: F403
from kinestat.spatial.screws import *  # noqa: F403
from kinestat.spatial.se3 import *  # noqa: F403
from kinestat.spatial.transforms import *  # noqa: F403
from kinestat.spatial.validate import *  # noqa: F403

__all__ = [
    *transforms.__all__,
    *euler.__all__,
    *plucker.__all__,
    *screws.__all__,
    *displacement.__all__,
    *se3.__all__,
    *[n for n in validate.__all__ if n != "as_array"],
]
