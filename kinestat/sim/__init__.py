"""Stand-ins for the cell's hardware, for tests, demos and development without the robot.

Only hardware: no decisions (:mod:`kinestat.control`) and no drivers (:mod:`kinestat.devices`)
are imported here; the wiring of a simulated cell to the controller is
:mod:`kinestat.app.sim_cell`.

- :mod:`kinestat.sim.contact` — the cell's mechanics: platform + tool + planar workpiece, the
  contact equilibrium (frictionless or Coulomb) at a flange pose.
- :mod:`kinestat.sim.sensor` — the leg encoders: true leg lengths -> quantised counts, noise.
- :mod:`kinestat.sim.dmc` — a simulated Galil DMC controller: command interpreter,
  trapezoidal profiles, the PUMA's axis 4 -> 5 coupling, simulated or real time, fault
  injection.
- :mod:`kinestat.sim.galil_server` — that controller served over TCP (loopback only unless
  told otherwise).
- :mod:`kinestat.sim.encoder_emitter` — a simulated encoder box streaming packets onto a
  pseudo-terminal, with fault injection.
- :mod:`kinestat.sim.arm` — any 6-joint arm whose joints are set directly within its limits
  (the in-process cell of ``kinestat control --arm``).
- :mod:`kinestat.sim.mujoco_scene` and :mod:`kinestat.sim.mujoco_plant` — the cell as a MuJoCo
  scene built from kinestat's models, stepped in time (``--sim mujoco``; MuJoCo is imported
  only there).
"""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'arm': ['SimulatedArm'],
        'contact': ['Cell', 'Equilibrium', 'Workpiece', 'equilibrium', 'make_cell'],
        'dmc': ['DmcSimulator', 'SimClock'],
        'encoder_emitter': ['EncoderEmitter', 'constant_counts'],
        'galil_server': ['GalilSimServer'],
        'sensor': ['Sensor', 'ideal_sensor'],
    },
)
