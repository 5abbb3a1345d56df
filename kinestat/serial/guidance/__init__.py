"""Resolved-rate guidance of a manipulator's hand (Nadkarni 1977, ch. IV–V) and DISP decks.

- :mod:`.planners` — the hand paths of analysis types I–IV and each step's twist B (eq. 4-11)
- :mod:`.step` — solving ``J δq = B``, singularities, eq. 5-5, joint limits
- :mod:`.run` — the step loop: events, step counts, closed-loop and correction steps
- :mod:`.velocity` — joint rates for a hand speed (suggestion 1)
- :mod:`.disp` — running a DISP deck for every MS

See docs/guidance.md.
"""

from __future__ import annotations

from kinestat.serial.guidance.disp import DeckRun, deck_json, run_deck
from kinestat.serial.guidance.planners import (
    command_path,
    general_motion,
    general_path,
    line_path,
    screw_path,
)
from kinestat.serial.guidance.run import (
    GuidanceOptions,
    GuidanceResult,
    joint_display,
    result_record,
    run_guidance,
)
from kinestat.serial.guidance.step import solve_step
from kinestat.serial.guidance.velocity import joint_rates

__all__ = [
    "DeckRun",
    "GuidanceOptions",
    "GuidanceResult",
    "command_path",
    "deck_json",
    "general_motion",
    "general_path",
    "joint_display",
    "joint_rates",
    "line_path",
    "result_record",
    "run_deck",
    "run_guidance",
    "screw_path",
    "solve_step",
]
