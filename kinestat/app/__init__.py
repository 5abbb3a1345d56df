"""Composition roots: the wiring of applications (layer 2: may import control, devices, sim,
io, viz; imported only by the CLI).

- :mod:`kinestat.app.sim_cell` — the simulated cell behind the simulated Galil and encoder box
  (:class:`SimHarness`), and in-process without devices (:class:`InProcessIO`).
- :mod:`kinestat.app.control_run` — assembling the cell and the controller for
  ``kinestat control`` (simulated or real devices) and running it.
"""

from kinestat.app.control_run import (
    ControlRequest,
    PreparedRun,
    RealDevices,
    SimulatedCell,
    prepare_control,
    run_control,
)
from kinestat.app.sim_cell import CellState, InProcessIO, SimHarness, control_model, start_counts

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
