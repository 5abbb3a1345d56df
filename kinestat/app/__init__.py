"""Composition roots: the wiring of applications (layer 2: may import control, devices, sim,
io, viz; imported only by the CLI).

- :mod:`kinestat.app.sim_cell` — the simulated cell behind the simulated Galil and encoder box
  (:class:`SimHarness`), and in-process without devices (:class:`InProcessIO`).
- :mod:`kinestat.app.control_run` — assembling the cell, the controller and the task of a
  :class:`~kinestat.control.runspec.RunSpec` (``kinestat control``) and running it.
- :mod:`kinestat.app.cell_factory` — the cell of a run: the built-in simulator, MuJoCo or the
  real devices.
- :mod:`kinestat.app.control_api` — :func:`run`: ``kinestat control`` as a Python call.
- :mod:`kinestat.app.arm_cell` — another arm (``kinestat control --arm``) in the in-process
  simulated cell: millimetres, automatic placement, start joints.
"""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'arm_cell': ['ArmSpec', 'PlacedArm', 'place_arm'],
        'control_api': ['run'],
        'control_run': [
            'ControlRequest', 'PreparedRun', 'RealDevices', 'SimulatedCell', 'prepare_control',
            'run_control',
        ],
        'sim_cell': ['CellState', 'InProcessIO', 'SimHarness', 'control_model', 'start_counts'],
    },
)
