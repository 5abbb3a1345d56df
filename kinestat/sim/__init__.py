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
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
    from kinestat.sim.contact import Cell, Equilibrium, Workpiece, equilibrium, make_cell
    from kinestat.sim.dmc import DmcSimulator, SimClock
    from kinestat.sim.encoder_emitter import EncoderEmitter, constant_counts
    from kinestat.sim.galil_server import GalilSimServer
    from kinestat.sim.sensor import Sensor, ideal_sensor

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "Cell": ("kinestat.sim.contact", "Cell"),
    "Equilibrium": ("kinestat.sim.contact", "Equilibrium"),
    "Workpiece": ("kinestat.sim.contact", "Workpiece"),
    "equilibrium": ("kinestat.sim.contact", "equilibrium"),
    "make_cell": ("kinestat.sim.contact", "make_cell"),
    "DmcSimulator": ("kinestat.sim.dmc", "DmcSimulator"),
    "SimClock": ("kinestat.sim.dmc", "SimClock"),
    "EncoderEmitter": ("kinestat.sim.encoder_emitter", "EncoderEmitter"),
    "constant_counts": ("kinestat.sim.encoder_emitter", "constant_counts"),
    "GalilSimServer": ("kinestat.sim.galil_server", "GalilSimServer"),
    "Sensor": ("kinestat.sim.sensor", "Sensor"),
    "ideal_sensor": ("kinestat.sim.sensor", "ideal_sensor"),
}

__all__ = [
    "Cell",
    "DmcSimulator",
    "EncoderEmitter",
    "Equilibrium",
    "GalilSimServer",
    "Sensor",
    "SimClock",
    "Workpiece",
    "constant_counts",
    "equilibrium",
    "ideal_sensor",
    "make_cell",
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
