"""The press's settings and memory: :class:`ControllerConfig` (one run's settings, immutable)
and :class:`ControllerState` (what the controller remembers between cycles), with the names of
Vibhute's Figure 5-2 states, the step methods and the procedures."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np

from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.control.command import Action, Target
from kinestat.control.envelope import Envelope
from kinestat.control.model import ControlModel
from kinestat.control.tuning import Tuning
from kinestat.control.wrench import Estimator
from kinestat.errors import InputError

__all__ = ["THESIS_FORCE_DIRECTION", "STATES", "StepMethod", "METHODS", "Procedure",
           "PROCEDURES", "ESTIMATORS", "default_a67", "ControllerConfig", "ControllerState"]

THESIS_FORCE_DIRECTION = np.array([0.9713, 0.0, -0.2375]) / math.hypot(0.9713, 0.2375)
"""Direction of the thesis's ``F_req = 0.9713 i + 0 j − 0.2375 k`` (Vibhute §5.1; the OCR
dropped the minus sign — see docs/seed-errata.md), normalised (|F_req| printed = 0.99991)."""
THESIS_FORCE_DIRECTION.setflags(write=False)

STATES = {
    "a": "platform at rest, unloaded",
    "b": "tool has hit the workpiece, wrench generated",
    "c": "robot reoriented the tool along the equivalent wrench",
    "d": "force in the tool being controlled",
    "e": "goal force attained, kinestatic control complete",
}
"""The states of Vibhute's Figure 5-2."""

StepMethod = Literal["fixed", "stiffness"]
"""How the step along S6 is chosen: the thesis's fixed step or a Newton step from the
platform stiffness (see the module docstring)."""
METHODS: tuple[str, ...] = get_args(StepMethod)
Procedure = Literal["kinestat", "thesis"]
"""``kinestat``: :func:`decide` (the improved loop); ``thesis``: ForceCorrection.m as written
(:func:`kinestat.control.procedure.decide_thesis`)."""
PROCEDURES: tuple[str, ...] = get_args(Procedure)
ESTIMATORS: tuple[str, ...] = get_args(Estimator)


def _unit(v, name: str) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise InputError(f"{name} must be 3 finite numbers, got {np.asarray(v).tolist()}")
    n = float(np.linalg.norm(a))
    if n < 1e-12:
        raise InputError(f"{name} must be a nonzero vector")
    return a / n


def default_a67(s6) -> np.ndarray:
    """A link direction a67 ⟂ S6 for a start pose: the fixed z axis projected off S6 (or the
    x axis if S6 is vertical)."""
    s = _unit(s6, "s6")
    for ref in (np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])):
        a = ref - (ref @ s) * s
        if np.linalg.norm(a) > 0.1:
            return a / np.linalg.norm(a)
    raise InputError("cannot choose a67")  # pragma: no cover - one of the two always works


@dataclass(frozen=True, eq=False)
class ControllerConfig:
    """Settings of one kinestatic control run (immutable).

    Attributes:
        model: the cell as the controller knows it.
        force: (3,) ``F_req``: its magnitude is the target force (N), its direction the
            approach direction and the start pose's S6.
        start_tool_point: (3,) the start pose's tool point ``P_tool_F`` (mm, fixed frame).
        start_s6, start_a67: the start pose's S6 (default along ``force``) and a67 (default
            :func:`default_a67`).
        force_tol: tolerance on the force magnitude (N).
        align_tol_deg: tolerance on the angle between S6 and the measured force (degrees).
        method: ``"fixed"`` (thesis) or ``"stiffness"``.
        step: the fixed step, and the largest step of the stiffness method (mm).
        approach_step: step along S6 while no contact is measured (mm; the thesis's 1 mm).
        contact_force: force magnitude above which the tool is in contact (N).
        max_iterations: measurement cycles before giving up.
        vernier: choose the count vector that best realises the target along S6.
        estimator: the force acted on: ``"point"`` (point-contact fit, default) or
            ``"wrench"`` (the equivalent wrench's force, as the thesis), see
            :meth:`kinestat.control.wrench.Measurement.estimate`.
        repeat_limit: a target commanded this many times means a limit cycle → stop.
        max_approach: the farthest an approach without contact may carry the tool point from
            the start tool point (mm); beyond it the run stops (:func:`approach_refusal`).
        envelope: the safety envelope.
        procedure: "kinestat" (default) or "thesis" (ForceCorrection.m's steps as written).
        tuning: the press's tuning (:class:`~kinestat.control.tuning.Tuning`).
    """

    model: ControlModel
    force: np.ndarray
    start_tool_point: np.ndarray
    start_s6: np.ndarray | None = None
    start_a67: np.ndarray | None = None
    force_tol: float = 0.5
    align_tol_deg: float = 0.5
    method: StepMethod = "stiffness"
    step: float = 1.0
    approach_step: float = 1.0
    contact_force: float = 0.25
    max_iterations: int = 60
    vernier: bool = True
    estimator: Estimator = "point"
    repeat_limit: int = 3
    max_approach: float = 50.0
    envelope: Envelope = field(default_factory=Envelope)
    procedure: Procedure = "kinestat"
    tuning: Tuning = field(default_factory=Tuning)

    def __post_init__(self) -> None:
        F = np.asarray(self.force, dtype=float)
        if F.shape != (3,) or not np.all(np.isfinite(F)) or np.linalg.norm(F) <= 0:
            raise InputError(f"force (F_req) must be 3 finite numbers, not all zero, got "
                             f"{np.asarray(self.force).tolist()}")
        object.__setattr__(self, "force", F.copy())
        p = np.asarray(self.start_tool_point, dtype=float)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise InputError("start_tool_point must be 3 finite numbers (mm)")
        object.__setattr__(self, "start_tool_point", p.copy())
        s6 = F / np.linalg.norm(F) if self.start_s6 is None else _unit(self.start_s6, "start_s6")
        a67 = default_a67(s6) if self.start_a67 is None else _unit(self.start_a67, "start_a67")
        if abs(float(s6 @ a67)) > 1e-6:
            raise InputError(f"start_a67 must be perpendicular to start_s6 (dot "
                             f"{float(s6 @ a67):.3g})")
        object.__setattr__(self, "start_s6", s6)
        object.__setattr__(self, "start_a67", a67)
        if self.estimator not in ESTIMATORS:
            raise InputError(f"estimator must be one of {ESTIMATORS}, got {self.estimator!r}")
        if self.method not in METHODS:
            raise InputError(f"method must be one of {METHODS}, got {self.method!r}")
        if self.procedure not in PROCEDURES:
            raise InputError(f"procedure must be one of {PROCEDURES}, got {self.procedure!r}")
        for name in ("force_tol", "align_tol_deg", "step", "contact_force"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"{name} must be a positive number, got {getattr(self, name)!r}")
        if not (math.isfinite(self.approach_step) and self.approach_step > 0):
            raise InputError(f"approach_step must be positive, got {self.approach_step!r}")
        if not (math.isfinite(self.max_approach) and self.max_approach > 0):
            raise InputError(f"max_approach must be a positive number of mm, got "
                             f"{self.max_approach!r}")
        if not 1 <= int(self.max_iterations) <= MAX_ITERATIONS:
            raise InputError(f"max_iterations must be in 1..{MAX_ITERATIONS}, got "
                             f"{self.max_iterations!r}")
        if self.contact_force >= np.linalg.norm(F):
            raise InputError(f"the contact threshold {self.contact_force} N must be below the "
                             f"requested force {np.linalg.norm(F):.3g} N")

    @functools.cached_property
    def force_target(self) -> float:
        """|F_req| (N); computed once per config (the cycle reads it several times)."""
        return float(np.linalg.norm(self.force))

    @property
    def approach(self) -> float:
        return float(self.approach_step)


@dataclass(frozen=True, eq=False)
class ControllerState:
    """What the controller remembers between cycles (immutable; :func:`decide` returns a new one).

    Attributes:
        cycle: measurements processed so far.
        label: the state (a–e) of the last cycle, "" before the first.
        last_action: the last command's action ("start", "approach", "align", "force").
        target: the last commanded end effector.
        axis_counts: (6,) the last commanded axis counts.
        top_pose: (4, 4) the last measured top pose (the tracking FK's seed).
        history: keys of the targets commanded so far (limit-cycle detection).
        done: the run is over (goal reached or stopped).
        reoriented: the thesis's procedure made (or no longer needs) its one reorientation.
        align_gain: the fraction of the misalignment the next align turn makes (1: the whole
            turn; halved each time a turn overshot, see
            :func:`kinestat.control.align.align_gain`).
        align_turn: (3,) the last align turn's rotation vector (radians), None before one.
        align_from: (3,) the misalignment (rotation vector from S6 onto the force) it was
            made from.
        shed_expect_deg: the misalignment the last shed (a move across S6 that turns a held
            tip's force onto S6) should leave at most (degrees).
        align_best_deg: the misalignment measured at the align turns' last progress (degrees;
            None before contact): the first contact, a misalignment within tolerance or one
            below the tuning's ``align_progress`` of the previous value.
        align_stall: contact cycles since that progress
            (:func:`~kinestat.control.align.align_stalled`).
    """

    cycle: int
    label: str
    last_action: Action
    target: Target
    axis_counts: np.ndarray
    top_pose: np.ndarray
    history: tuple = ()
    done: bool = False
    reoriented: bool = False
    align_gain: float = 1.0
    align_turn: np.ndarray | None = None
    align_from: np.ndarray | None = None
    shed_expect_deg: float = 0.0
    align_best_deg: float | None = None
    align_stall: int = 0
