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

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'fk': ['FKSolutions', 'fk_all', 'fk_list', 'fk_numeric', 'fk_tracking', 'reduce_to_33'],
        'fk33': ['fk_33'],
        'legs': ['leg_lengths', 'leg_vectors', 'top_points_in_base'],
        'planar_springs': [
            'springs_in_parallel', 'springs_in_series', 'two_spring_compliance', 'two_spring_force',
            'two_spring_stiffness',
        ],
        'platform': [
            'LEG_NAMES', 'Platform', 'SpecialDesign', 'SpecialLayout', 'special_6_6',
            'special_layout',
        ],
        'singularity': ['check_design', 'is_architecturally_singular', 'singularity_measure'],
        'statics': [
            'forces_from_wrench', 'jacobian_det', 'leg_lines', 'line_jacobian', 'spring_forces',
            'spring_wrench', 'wrench_from_forces', 'wrench_from_leg_lengths',
        ],
        'stiffness': ['equilibrium_pose', 'load_asymmetry', 'stiffness', 'stiffness_terms'],
    },
)
