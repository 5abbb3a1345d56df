"""The compliant 6-6 parallel platform: model, reverse and forward kinematics, statics, stiffness.

- :mod:`~kinestat.parallel.platform` — the immutable :class:`Platform`, the special 6-6 builder
  :func:`special_6_6` (the embedded 2011 prototype is loaded by
  :func:`kinestat.io.library.prototype`: models never read files).
- :mod:`~kinestat.parallel.legs` — leg lengths from a pose (reverse kinematics), leg lines and
  the line Jacobian.
- :mod:`~kinestat.parallel.fk33` — closed-form 3-3 forward kinematics (all modes).
- :mod:`~kinestat.parallel.fk` — special 6-6 → 3-3, all modes; tracking mode; general 6-6.
- :mod:`~kinestat.parallel.statics` — leg forces ↔ wrench (re-exports the leg lines).
- :mod:`~kinestat.parallel.stiffness` — spatial stiffness under load, equilibrium poses.
- :mod:`~kinestat.parallel.planar_springs` — the thesis's planar spring examples.
- :mod:`~kinestat.parallel.singularity` — singular poses and architecturally singular designs.

Every name in the modules' ``__all__`` is importable from ``kinestat.parallel``.
"""

from __future__ import annotations

import sys

from kinestat.parallel.fk import *  # noqa: F403
from kinestat.parallel.fk33 import *  # noqa: F403
from kinestat.parallel.legs import *  # noqa: F403
from kinestat.parallel.planar_springs import *  # noqa: F403
from kinestat.parallel.platform import *  # noqa: F403
from kinestat.parallel.singularity import *  # noqa: F403
from kinestat.parallel.statics import *  # noqa: F403
from kinestat.parallel.stiffness import *  # noqa: F403

_MODULES = ("fk", "fk33", "legs", "planar_springs", "platform", "singularity", "statics",
            "stiffness")

# the package's public names are its modules' public names (each module's __all__)
__all__ = sorted({name for m in _MODULES for name in sys.modules[f"{__name__}.{m}"].__all__})
