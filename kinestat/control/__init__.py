"""Kinestatic control (Vibhute 2011 ch. 4-5): decide from measured wrenches, never leave the
safety envelope, log every cycle.

- :mod:`kinestat.control.model` — what the controller knows about the cell.
- :mod:`kinestat.control.wrench` — the measurement chain (counts → wrench, fixed frame).
- :mod:`kinestat.control.controller` — pure decision logic, ``decide(config, state, meas)``.
- :mod:`kinestat.control.envelope` — limits, worst-case predictions, verdicts.
- :mod:`kinestat.control.log` — the JSON-lines cycle log.
- :mod:`kinestat.control.loop` — the I/O driver (devices in, decisions, devices out).
"""

from kinestat.control.controller import (
    STATES,
    THESIS_FORCE_DIRECTION,
    Command,
    Controller,
    ControllerConfig,
    ControllerState,
    Target,
    decide,
    start,
)
from kinestat.control.envelope import Envelope, predict
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import DeviceIO, MotionProfile, RunReport, run
from kinestat.control.model import ControlModel
from kinestat.control.wrench import Measurement, measure

__all__ = [
    "STATES",
    "THESIS_FORCE_DIRECTION",
    "Command",
    "ControlModel",
    "Controller",
    "ControllerConfig",
    "ControllerState",
    "CycleLog",
    "DeviceIO",
    "Envelope",
    "Measurement",
    "MotionProfile",
    "RunReport",
    "Target",
    "decide",
    "measure",
    "predict",
    "read_log",
    "run",
    "start",
]
