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

import importlib
import sys
import types
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
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

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "FKSolutions": ("kinestat.parallel.fk", "FKSolutions"),
    "fk_all": ("kinestat.parallel.fk", "fk_all"),
    "fk_list": ("kinestat.parallel.fk", "fk_list"),
    "fk_numeric": ("kinestat.parallel.fk", "fk_numeric"),
    "fk_tracking": ("kinestat.parallel.fk", "fk_tracking"),
    "reduce_to_33": ("kinestat.parallel.fk", "reduce_to_33"),
    "fk_33": ("kinestat.parallel.fk33", "fk_33"),
    "leg_lengths": ("kinestat.parallel.legs", "leg_lengths"),
    "leg_vectors": ("kinestat.parallel.legs", "leg_vectors"),
    "top_points_in_base": ("kinestat.parallel.legs", "top_points_in_base"),
    "springs_in_parallel": ("kinestat.parallel.planar_springs", "springs_in_parallel"),
    "springs_in_series": ("kinestat.parallel.planar_springs", "springs_in_series"),
    "two_spring_compliance": ("kinestat.parallel.planar_springs", "two_spring_compliance"),
    "two_spring_force": ("kinestat.parallel.planar_springs", "two_spring_force"),
    "two_spring_stiffness": ("kinestat.parallel.planar_springs", "two_spring_stiffness"),
    "LEG_NAMES": ("kinestat.parallel.platform", "LEG_NAMES"),
    "Platform": ("kinestat.parallel.platform", "Platform"),
    "SpecialDesign": ("kinestat.parallel.platform", "SpecialDesign"),
    "SpecialLayout": ("kinestat.parallel.platform", "SpecialLayout"),
    "special_6_6": ("kinestat.parallel.platform", "special_6_6"),
    "special_layout": ("kinestat.parallel.platform", "special_layout"),
    "check_design": ("kinestat.parallel.singularity", "check_design"),
    "is_architecturally_singular": ("kinestat.parallel.singularity", "is_architecturally_singular"),
    "singularity_measure": ("kinestat.parallel.singularity", "singularity_measure"),
    "forces_from_wrench": ("kinestat.parallel.statics", "forces_from_wrench"),
    "jacobian_det": ("kinestat.parallel.statics", "jacobian_det"),
    "leg_lines": ("kinestat.parallel.statics", "leg_lines"),
    "line_jacobian": ("kinestat.parallel.statics", "line_jacobian"),
    "spring_forces": ("kinestat.parallel.statics", "spring_forces"),
    "spring_wrench": ("kinestat.parallel.statics", "spring_wrench"),
    "wrench_from_forces": ("kinestat.parallel.statics", "wrench_from_forces"),
    "wrench_from_leg_lengths": ("kinestat.parallel.statics", "wrench_from_leg_lengths"),
    "equilibrium_pose": ("kinestat.parallel.stiffness", "equilibrium_pose"),
    "load_asymmetry": ("kinestat.parallel.stiffness", "load_asymmetry"),
    "stiffness": ("kinestat.parallel.stiffness", "stiffness"),
    "stiffness_terms": ("kinestat.parallel.stiffness", "stiffness_terms"),
}

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


def __getattr__(name: str) -> Any:
    """Load a public name's module on first use (PEP 562): importing the package stays cheap."""
    where = _LAZY.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = importlib.import_module(where[0])
    value = module if where[1] is None else getattr(module, where[1])
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """This package, where a public function keeps its name when its same-named submodule is
    imported (as the eager ``from .x import x`` used to guarantee)."""

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, types.ModuleType) and _LAZY.get(name, ("", None))[1] is not None:
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
