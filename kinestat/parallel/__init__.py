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
"""

from __future__ import annotations

from kinestat.parallel.fk import (
    FKSolutions,
    fk_all,
    fk_list,
    fk_numeric,
    fk_tracking,
    reduce_to_33,
)
from kinestat.parallel.fk33 import fk_33
from kinestat.parallel.legs import leg_lengths, leg_vectors, top_points_in_base
from kinestat.parallel.planar_springs import (
    springs_in_parallel,
    springs_in_series,
    two_spring_compliance,
    two_spring_force,
    two_spring_stiffness,
)
from kinestat.parallel.platform import (
    LEG_NAMES,
    Platform,
    SpecialDesign,
    SpecialLayout,
    special_6_6,
    special_layout,
)
from kinestat.parallel.singularity import (
    check_design,
    is_architecturally_singular,
    singularity_measure,
)
from kinestat.parallel.statics import (
    forces_from_wrench,
    jacobian_det,
    leg_lines,
    line_jacobian,
    spring_forces,
    spring_wrench,
    wrench_from_forces,
    wrench_from_leg_lengths,
)
from kinestat.parallel.stiffness import (
    equilibrium_pose,
    load_asymmetry,
    stiffness,
    stiffness_terms,
)

__all__ = [
    "LEG_NAMES",
    "FKSolutions",
    "Platform",
    "SpecialDesign",
    "SpecialLayout",
    "check_design",
    "equilibrium_pose",
    "fk_33",
    "fk_all",
    "fk_list",
    "fk_numeric",
    "fk_tracking",
    "forces_from_wrench",
    "is_architecturally_singular",
    "jacobian_det",
    "leg_lengths",
    "leg_lines",
    "leg_vectors",
    "line_jacobian",
    "load_asymmetry",
    "reduce_to_33",
    "singularity_measure",
    "special_6_6",
    "special_layout",
    "spring_forces",
    "spring_wrench",
    "springs_in_parallel",
    "springs_in_series",
    "stiffness",
    "stiffness_terms",
    "top_points_in_base",
    "two_spring_compliance",
    "two_spring_force",
    "two_spring_stiffness",
    "wrench_from_forces",
    "wrench_from_leg_lengths",
]
