"""The press task: the kinestatic procedure (Vibhute 2011 ch. 5, Fig. 5-2) behind the task
protocol (:class:`kinestat.control.task.Task`)."""

from __future__ import annotations

from dataclasses import dataclass

from kinestat.control.controller import ControllerConfig, decide, start

__all__ = ["PressTask"]


@dataclass(frozen=True, eq=False)
class PressTask:
    """Press the tool on the workpiece with ``|F_req|`` along the force: the start pose, then
    :func:`~kinestat.control.controller.decide` each cycle."""

    config: ControllerConfig
    name: str = "press"

    def start(self, q_now, counts_now):
        return start(self.config, q_now, counts_now=counts_now)

    def decide(self, state, meas):
        return decide(self.config, state, meas)

    def report(self, cycles: list[dict]) -> dict:
        return {}
