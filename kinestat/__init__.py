"""kinestat: kinematics and statics (kinestatics) of robot manipulators.

The stable top-level API::

    import kinestat
    model = kinestat.load("puma762")          # an embedded model or a TOML file
    T = kinestat.fk(model, q)                 # (..., 4, 4) for q of shape (..., n)
    J = kinestat.jacobian(model, q)           # (..., 6, n), twists [w; v_O]
    res = kinestat.ik(model, poses)           # numerical IK, batched, honest success flags
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
    from kinestat.errors import KinestatError
    from kinestat.io.library import list_models, load
    from kinestat.mechanism.chain import ChainModel
    from kinestat.serial.fk import fk
    from kinestat.serial.ik import ik
    from kinestat.serial.jacobian import jacobian

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "KinestatError": ("kinestat.errors", "KinestatError"),
    "list_models": ("kinestat.io.library", "list_models"),
    "load": ("kinestat.io.library", "load"),
    "ChainModel": ("kinestat.mechanism.chain", "ChainModel"),
    "fk": ("kinestat.serial.fk", "fk"),
    "ik": ("kinestat.serial.ik", "ik"),
    "jacobian": ("kinestat.serial.jacobian", "jacobian"),
}

__version__ = "0.1.0"

__all__ = [
    "ChainModel",
    "KinestatError",
    "load",
    "list_models",
    "fk",
    "jacobian",
    "ik",
    "__version__",
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
