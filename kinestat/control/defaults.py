"""The defaults of a ``kinestat control`` run, written once: the command line shows them
(this module imports nothing, so ``kinestat --help`` stays fast) and
:class:`~kinestat.control.runspec.RunSpec` uses them."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RunDefaults", "RUN_DEFAULTS", "TASKS", "PLANTS"]

TASKS = ("press", "follow")
"""``kinestat control --task``: press the tool on the workpiece (Vibhute ch. 5, the default) or
slide it along the workpiece holding the normal force (:mod:`kinestat.control.follow`)."""
PLANTS = ("kinestat", "mujoco")
"""The simulated cell's physics (``--sim``): the built-in contact simulator or MuJoCo."""


@dataclass(frozen=True)
class RunDefaults:
    """A run's settings when not given (the thesis's experiment, Vibhute 2011 §5.1).

    Attributes:
        force: |F_req| (N); direction: F_req's direction x,y,z (fixed frame; the thesis's
            0.9713 i + 0 j − 0.2375 k, sign restored: docs/seed-errata.md); start: the start
            tool point ``P_tool_F`` x,y,z (mm, fixed frame).
        force_tol: tolerance on |F| (N); align_tol_deg: on the angle S6–force (degrees).
        step: the fixed step and the largest stiffness step along S6 (mm).
        press_approach_step, follow_approach_step: the step along S6 before contact (mm): the
            thesis's 1 mm for the press; 0.25 mm for follow, whose first contact force then
            stays below 3 N on the prototype.
        press_max_iterations: the press's cycle budget (follow's is the ceiling,
            :data:`~kinestat.control.ceilings.MAX_ITERATIONS`).
        max_approach: farthest an approach without contact may carry the tool (mm).
        travel, travel_step: the follow task's distance and largest travel per cycle (mm);
            tilt_deg: its tool tilt from the normal (degrees).
        plane_distance: the default workpiece plane's distance ahead of the start tool point
            along F_req (mm); plane_tilt_deg: its normal's tilt from −F_req (degrees).
        rate_hz: the simulated encoder's packet rate (Hz).
        a67_dot_tol: largest |a67 · S6| of a given ``--a67`` (unit vectors; 0.06° off
            perpendicular): typed to four decimals it passes and is made exactly
            perpendicular to S6.
    """

    force: float = 4.0
    direction: str = "0.9713,0,-0.2375"
    start: str = "-400,800,-100"
    force_tol: float = 0.5
    align_tol_deg: float = 0.5
    step: float = 1.0
    press_approach_step: float = 1.0
    follow_approach_step: float = 0.25
    press_max_iterations: int = 60
    max_approach: float = 50.0
    travel: float = 50.0
    travel_step: float = 1.0
    tilt_deg: float = 0.0
    plane_distance: float = 2.5
    plane_tilt_deg: float = 5.0
    rate_hz: float = 200.0
    a67_dot_tol: float = 1e-3


RUN_DEFAULTS = RunDefaults()
"""The defaults of every run."""
