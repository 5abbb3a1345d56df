"""The thesis's procedure (ForceCorrection.m as written, Vibhute 2011 App. D.1) behind the
task protocol (:class:`kinestat.control.task.Task`)."""

from __future__ import annotations

from dataclasses import dataclass

from kinestat.control.press_task import PressTask
from kinestat.control.procedure import decide_thesis

__all__ = ["ThesisTask"]


@dataclass(frozen=True, eq=False)
class ThesisTask(PressTask):
    """The press as the thesis's MATLAB does it: the press's start pose, then
    :func:`~kinestat.control.procedure.decide_thesis` each cycle."""

    name: str = "thesis"

    def decide(self, state, meas):
        return decide_thesis(self.config, state, meas)
