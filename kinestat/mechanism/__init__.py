"""Mechanisms: joints, the immutable serial chain model, notations, DH from axes. Never reads files.

- :mod:`~kinestat.mechanism.joints` — revolute, prismatic and screw joints, DISP's pitch rule.
- :mod:`~kinestat.mechanism.chain` — the immutable :class:`ChainModel` and its builders from
  standard DH, modified DH and Nadkarni's notation.
- :mod:`~kinestat.mechanism.nadkarni` — Nadkarni's mechanism frames (TRANSM) and hand points.
- :mod:`~kinestat.mechanism.dh_from_axes` — a standard DH table from the joint axes.

Loading models from files or by name is :mod:`kinestat.io.library` (``kinestat.load``).
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
    from kinestat.mechanism.chain import (
        ChainModel,
        from_modified_dh,
        from_nadkarni,
        from_standard_dh,
    )
    from kinestat.mechanism.dh_from_axes import DHFromAxes, dh_from_axes
    from kinestat.mechanism.joints import Joint
    from kinestat.mechanism.nadkarni import MechanismFrames, hand_points, mechanism_frames

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "ChainModel": ("kinestat.mechanism.chain", "ChainModel"),
    "from_modified_dh": ("kinestat.mechanism.chain", "from_modified_dh"),
    "from_nadkarni": ("kinestat.mechanism.chain", "from_nadkarni"),
    "from_standard_dh": ("kinestat.mechanism.chain", "from_standard_dh"),
    "DHFromAxes": ("kinestat.mechanism.dh_from_axes", "DHFromAxes"),
    "dh_from_axes": ("kinestat.mechanism.dh_from_axes", "dh_from_axes"),
    "Joint": ("kinestat.mechanism.joints", "Joint"),
    "MechanismFrames": ("kinestat.mechanism.nadkarni", "MechanismFrames"),
    "hand_points": ("kinestat.mechanism.nadkarni", "hand_points"),
    "mechanism_frames": ("kinestat.mechanism.nadkarni", "mechanism_frames"),
}

__all__ = [
    "ChainModel",
    "DHFromAxes",
    "Joint",
    "MechanismFrames",
    "dh_from_axes",
    "from_modified_dh",
    "from_nadkarni",
    "from_standard_dh",
    "hand_points",
    "mechanism_frames",
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
