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
