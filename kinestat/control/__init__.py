"""Kinestatic control (Vibhute 2011 ch. 4-5): decide from measured wrenches, never leave the
safety envelope, log every cycle.

- :mod:`kinestat.control.model` — what the controller knows about the cell.
- :mod:`kinestat.control.wrench` — the measurement chain (counts → wrench, fixed frame).
- :mod:`kinestat.control.controller` — pure decision logic, ``decide(config, state, meas)``.
- :mod:`kinestat.control.envelope` — limits, worst-case predictions, verdicts.
- :mod:`kinestat.control.log` — the JSON-lines cycle log.
- :mod:`kinestat.control.loop` — the loop over the :class:`~kinestat.control.loop.CellIO`
  protocol (cell in, decisions, cell out); it imports no driver and no simulator.

The robot's axis conventions and the leg calibration come from :mod:`kinestat.hardware`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
    from kinestat.control.controller import (
        STATES,
        THESIS_FORCE_DIRECTION,
        Command,
        ControllerConfig,
        ControllerState,
        Target,
        decide,
        start,
    )
    from kinestat.control.envelope import Envelope, predict
    from kinestat.control.log import CycleLog, read_log
    from kinestat.control.loop import CellIO, RunReport, SensorReading, run
    from kinestat.control.model import ControlModel
    from kinestat.control.wrench import Measurement, measure

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "STATES": ("kinestat.control.controller", "STATES"),
    "THESIS_FORCE_DIRECTION": ("kinestat.control.controller", "THESIS_FORCE_DIRECTION"),
    "Command": ("kinestat.control.controller", "Command"),
    "ControllerConfig": ("kinestat.control.controller", "ControllerConfig"),
    "ControllerState": ("kinestat.control.controller", "ControllerState"),
    "Target": ("kinestat.control.controller", "Target"),
    "decide": ("kinestat.control.controller", "decide"),
    "start": ("kinestat.control.controller", "start"),
    "Envelope": ("kinestat.control.envelope", "Envelope"),
    "predict": ("kinestat.control.envelope", "predict"),
    "CycleLog": ("kinestat.control.log", "CycleLog"),
    "read_log": ("kinestat.control.log", "read_log"),
    "CellIO": ("kinestat.control.loop", "CellIO"),
    "RunReport": ("kinestat.control.loop", "RunReport"),
    "SensorReading": ("kinestat.control.loop", "SensorReading"),
    "run": ("kinestat.control.loop", "run"),
    "ControlModel": ("kinestat.control.model", "ControlModel"),
    "Measurement": ("kinestat.control.wrench", "Measurement"),
    "measure": ("kinestat.control.wrench", "measure"),
}

__all__ = [
    "STATES",
    "THESIS_FORCE_DIRECTION",
    "Command",
    "ControlModel",
    "ControllerConfig",
    "ControllerState",
    "CycleLog",
    "CellIO",
    "Envelope",
    "Measurement",
    "RunReport",
    "SensorReading",
    "Target",
    "decide",
    "measure",
    "predict",
    "read_log",
    "run",
    "start",
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
