"""Kinestatic control (Vibhute 2011 ch. 4-5): decide from measured wrenches, never leave the
safety envelope, log every cycle.

- :mod:`kinestat.control.arm` — the robot arm (any 6R arm with an analytic solver; the
  thesis's PUMA 762, :mod:`kinestat.robots.puma762`, is the default instance).
- :mod:`kinestat.control.model` — what the controller knows about the cell.
- :mod:`kinestat.control.wrench` — the measurement chain (counts → wrench, fixed frame).
- :mod:`kinestat.control.controller` — pure decision logic, ``decide(config, state, meas)``.
- :mod:`kinestat.control.envelope` — limits, worst-case predictions, verdicts.
- :mod:`kinestat.control.log` — the JSON-lines cycle log.
- :mod:`kinestat.control.runspec` — one run as one frozen :class:`RunSpec` (the Python API:
  ``kinestat.app.run(RunSpec(...))``; defaults in :mod:`kinestat.control.defaults`).
- :mod:`kinestat.control.task` — the task protocol (start, decide, report): the press
  (:mod:`~kinestat.control.press_task`), the thesis's procedure
  (:mod:`~kinestat.control.thesis_task`) and follow (:mod:`~kinestat.control.follow_task`).
- :mod:`kinestat.control.loop` — the loop over a task and the
  :class:`~kinestat.control.loop.CellIO` protocol (cell in, decisions, cell out); it imports
  no driver and no simulator.

The robot's axis conventions come from its package (:mod:`kinestat.robots`), the leg
calibration from :mod:`kinestat.hardware`.
"""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'arm': ['Arm', 'ChainArm', 'Puma762Arm', 'THESIS_ARM'],
        'controller': [
            'Command', 'ControllerConfig', 'ControllerState', 'STATES', 'THESIS_FORCE_DIRECTION',
            'Target', 'decide', 'start',
        ],
        'envelope': ['Envelope', 'predict'],
        'log': ['CycleLog', 'read_log'],
        'entry': ['run'],
        'loop': ['CellIO', 'RunReport', 'SensorReading'],
        'model': ['ControlModel'],
        'runspec': ['RunSpec', 'SimulatedCell', 'RealDevices', 'CylinderSpec'],
        'task': ['Task'],
        'press_task': ['PressTask'],
        'thesis_task': ['ThesisTask'],
        'follow_task': ['FollowTask'],
        'wrench': ['Measurement', 'measure'],
    },
)
