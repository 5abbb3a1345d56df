"""Composition roots: the wiring of applications (layer 2: may import control, devices, sim,
io, viz; imported only by the CLI).

- :mod:`kinestat.app.sim_cell` — the simulated cell behind the simulated Galil and encoder box
  (:class:`SimHarness`), and in-process without devices (:class:`InProcessIO`).
- :mod:`kinestat.app.control_run` — assembling the cell and the controller for
  ``kinestat control`` (simulated or real devices) and running it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
    from kinestat.app.control_run import (
        ControlRequest,
        PreparedRun,
        RealDevices,
        SimulatedCell,
        prepare_control,
        run_control,
    )
    from kinestat.app.sim_cell import (
        CellState,
        InProcessIO,
        SimHarness,
        control_model,
        start_counts,
    )

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "ControlRequest": ("kinestat.app.control_run", "ControlRequest"),
    "PreparedRun": ("kinestat.app.control_run", "PreparedRun"),
    "RealDevices": ("kinestat.app.control_run", "RealDevices"),
    "SimulatedCell": ("kinestat.app.control_run", "SimulatedCell"),
    "prepare_control": ("kinestat.app.control_run", "prepare_control"),
    "run_control": ("kinestat.app.control_run", "run_control"),
    "CellState": ("kinestat.app.sim_cell", "CellState"),
    "InProcessIO": ("kinestat.app.sim_cell", "InProcessIO"),
    "SimHarness": ("kinestat.app.sim_cell", "SimHarness"),
    "control_model": ("kinestat.app.sim_cell", "control_model"),
    "start_counts": ("kinestat.app.sim_cell", "start_counts"),
}

__all__ = [
    "CellState",
    "ControlRequest",
    "InProcessIO",
    "PreparedRun",
    "RealDevices",
    "SimHarness",
    "SimulatedCell",
    "control_model",
    "prepare_control",
    "run_control",
    "start_counts",
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
