"""The follow task behind the task protocol (:class:`kinestat.control.task.Task`): slide the
tool along the workpiece holding the normal force (:mod:`kinestat.control.follow`)."""

from __future__ import annotations

from dataclasses import dataclass

from kinestat.control.controller import ControllerConfig, start
from kinestat.control.follow import FollowConfig, decide_follow, follow_summary

__all__ = ["FollowTask"]


@dataclass(frozen=True, eq=False)
class FollowTask:
    """The press's start pose, then :func:`~kinestat.control.follow.decide_follow` each
    cycle; the report adds the travel and normal-force figures
    (:func:`~kinestat.control.follow.follow_summary`)."""

    follow: FollowConfig
    name: str = "follow"

    @property
    def config(self) -> ControllerConfig:
        return self.follow.base

    def start(self, q_now, counts_now):
        return start(self.config, q_now, counts_now=counts_now)

    def decide(self, state, meas):
        return decide_follow(self.follow, state, meas)

    def report(self, cycles: list[dict]) -> dict:
        return {"task": "follow",
                **follow_summary(cycles, self.config.force_target, self.follow.travel),
                "travel_dir": self.follow.travel_dir.tolist()}
