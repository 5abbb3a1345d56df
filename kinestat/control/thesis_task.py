"""The thesis's procedure (ForceCorrection.m as written, Vibhute 2011 App. D.1) behind the
task protocol (:class:`kinestat.control.task.Task`)."""

from __future__ import annotations

from dataclasses import dataclass

from kinestat.control.controller import ControllerConfig, start
from kinestat.control.procedure import decide_thesis

__all__ = ["ThesisTask"]


@dataclass(frozen=True, eq=False)
class ThesisTask:
    """The press as the thesis's MATLAB does it: the same start pose, then
    :func:`~kinestat.control.procedure.decide_thesis` each cycle."""

    config: ControllerConfig
    name: str = "thesis"

    def start(self, q_now, counts_now):
        return start(self.config, q_now, counts_now=counts_now)

    def decide(self, state, meas):
        return decide_thesis(self.config, state, meas)

    def report(self, cycles: list[dict]) -> dict:
        return {}
