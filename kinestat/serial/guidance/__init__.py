"""Resolved-rate guidance of a manipulator's hand (Nadkarni 1977, ch. IV–V).

- :mod:`.planners` — the hand paths of analysis types I–IV (the :class:`Path` protocol) and
  each step's twist B (eq. 4-11)
- :mod:`.step` — solving ``J δq = B``, singularities, eq. 5-5, joint limits
- :mod:`.rules` — the step rules (first order, second order, the inferred 1977 rule) and
  :class:`GuidanceOptions`
- :mod:`.events` — typed events of a run
- :mod:`.run` — the step loop: events, step counts, closed-loop and correction steps
- :mod:`.stages` — stages from targets, operator commands and moves
- :mod:`.velocity` — joint rates for a hand speed (suggestion 1)

DISP decks are run by :mod:`kinestat.disp`. See docs/guidance.md.
"""

from __future__ import annotations

from kinestat.serial.guidance.planners import (
    Path,
    command_path,
    general_motion,
    general_path,
    line_path,
    screw_path,
)
from kinestat.serial.guidance.rules import GuidanceOptions
from kinestat.serial.guidance.run import GuidanceResult, joint_display, run_guidance
from kinestat.serial.guidance.step import solve_step
from kinestat.serial.guidance.velocity import joint_rates

__all__ = [
    "GuidanceOptions",
    "GuidanceResult",
    "Path",
    "command_path",
    "general_motion",
    "general_path",
    "joint_display",
    "joint_rates",
    "line_path",
    "run_guidance",
    "screw_path",
    "solve_step",
]
