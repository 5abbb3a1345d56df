"""The task protocol: what the loop (:mod:`kinestat.control.loop`) needs from a task.

A task is the pure decision half of a run: where to start, what to command after each
measurement and what its run adds to the report. The loop does the rest — the start move and
its waypoints, sensing, the measurement chain, the log, the envelope's check of every sent
command and the safe stop — the same for every task. The tasks of ``kinestat control``:

- :class:`kinestat.control.press_task.PressTask` — the kinestatic procedure (Vibhute ch. 5,
  :func:`kinestat.control.controller.decide`);
- :class:`kinestat.control.thesis_task.ThesisTask` — ForceCorrection.m's steps as written
  (:func:`kinestat.control.procedure.decide_thesis`);
- :class:`kinestat.control.follow_task.FollowTask` — slide along the workpiece holding the
  normal force (:func:`kinestat.control.follow.decide_follow`).

A new task (e.g. peg-in-hole, the thesis's future work) is one module with one class of this
shape, built from a :class:`~kinestat.control.controller.ControllerConfig` (the model, the
envelope and the goal force) and its own settings.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from kinestat.control.controller import Command, ControllerConfig, ControllerState
from kinestat.control.press_task import PressTask
from kinestat.control.runspec import RunSpec
from kinestat.control.thesis_task import ThesisTask
from kinestat.control.wrench import Measurement
from kinestat.errors import InputError

__all__ = ["Task", "as_task"]


@runtime_checkable
class Task(Protocol):
    """One task behind the loop: pure (the same inputs give the same outputs), no I/O.

    Attributes:
        name: the task's name in the log and the report (``"press"``, ``"thesis"``,
            ``"follow"``).
        config: the controller's settings the loop reads too: the model (counts to joints,
            the measurement chain), the envelope (stream faults) and the goal force.
    """

    name: str
    config: ControllerConfig

    def start(self, q_now: np.ndarray, counts_now: np.ndarray
              ) -> tuple[Command, ControllerState]:
        """The start move from joints ``q_now`` (radians) at axis counts ``counts_now``, and
        the first state (a ``stop`` command when the start cannot be commanded safely)."""

    def decide(self, state: ControllerState, meas: Measurement
               ) -> tuple[Command, ControllerState]:
        """The next command and state after one measurement."""

    def report(self, cycles: list[dict]) -> dict:
        """The task's own figures of a run from the report's ``cycles`` (keys added to the
        run's JSON report; empty when the task has none)."""


def as_task(config: ControllerConfig, decide_fn=None) -> Task:
    """The task of a bare :class:`~kinestat.control.controller.ControllerConfig` (the press,
    or the thesis's procedure when ``config.procedure == "thesis"``), or of a bound decision
    function ``decide_fn(state, meas)`` after the press's start (the older way of passing a
    task to :func:`kinestat.control.loop.run`, kept for callers that record decisions)."""
    if not isinstance(config, ControllerConfig):
        hint = (": a RunSpec runs with kinestat.control.run(spec), which builds its cell"
                if isinstance(config, RunSpec) else "")
        raise InputError(f"the loop runs a Task or a ControllerConfig, not a "
                         f"{type(config).__name__}{hint}")
    base = ThesisTask(config) if config.procedure == "thesis" else PressTask(config)
    return base if decide_fn is None else _BoundTask(base, decide_fn)


class _BoundTask:
    """A task whose decision is a bound function (see :func:`as_task`)."""

    def __init__(self, base: Task, decide_fn) -> None:
        self.name, self.config, self._base, self._decide = base.name, base.config, base, decide_fn

    def start(self, q_now, counts_now):
        return self._base.start(q_now, counts_now)

    def decide(self, state, meas):
        return self._decide(state, meas)

    def report(self, cycles: list[dict]) -> dict:
        return {}
