"""Step rules: how one guidance step turns the path's twist B into joint increments.

A rule is a strategy (:class:`StepRule`) chosen by :attr:`GuidanceOptions.step_rule`:

===============  =========================================================================
rule             joint increments of a step from s0 to s1
===============  =========================================================================
``first_order``  ``J δq = B`` (Nadkarni eq. 4-11; DISP 1977's equations)
``second_order`` eq. 4-11, then Newton on eqs. 4-9 and 5-5 with the δθ²/2 terms
                 (Nadkarni suggestion 2) towards the chord of the step
``disp_1977``    an *inferred* rule for the type III analysis (MS = 4) that reproduces
                 Table A2-9 of Illustration 5: B's translation is the second-order
                 displacement of the body point at the global origin, and every step is
                 done as ⌈(δθ°)²/40⌉ equal first-order sub-steps. It is fitted to that one
                 published table (docs/seed-errata.md G1), not taken from the thesis text.
===============  =========================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.guidance.planners import Path
from kinestat.serial.guidance.step import (
    DEFAULT_COND_LIMIT,
    StepSolution,
    origin_displacement_twist,
    solve_second_order,
    solve_step,
    split_substep_count,
)
from kinestat.serial.jacobian import jacobian

__all__ = [
    "StepRuleName",
    "SingularMode",
    "SINGULAR_MODES",
    "STEP_RULES",
    "StepInput",
    "StepIncrement",
    "StepRule",
    "FirstOrder",
    "SecondOrder",
    "Disp1977",
    "GuidanceOptions",
]

StepRuleName = Literal["first_order", "second_order", "disp_1977"]
SingularMode = Literal["perturb", "perturb_all", "damped", "stop"]
STEP_RULES: tuple[str, ...] = ("first_order", "second_order", "disp_1977")
SINGULAR_MODES: tuple[str, ...] = ("perturb", "perturb_all", "damped", "stop")


@dataclass(frozen=True, eq=False)
class StepInput:
    """What a rule needs for one step: joints ``q`` ``(n,)``, hand pose ``H`` ``(4, 4)``, the
    Jacobian ``J`` ``(6, n)`` at ``q``, the length L and the solver settings."""

    model: ChainModel
    q: np.ndarray
    H: np.ndarray
    J: np.ndarray
    length: float
    damping: str | None = None
    cond_limit: float = DEFAULT_COND_LIMIT
    max_damping: float = 0.1

    def solve(self, J, B) -> StepSolution:
        return solve_step(J, B, prismatic=self.model.prismatic, length=self.length,
                          damping=self.damping, cond_limit=self.cond_limit,
                          max_damping=self.max_damping)


@dataclass(frozen=True, eq=False)
class StepIncrement:
    """Joint increments ``dq`` ``(n,)``, the (last) solution and the sub-steps taken."""

    dq: np.ndarray
    solution: StepSolution
    substeps: int = 1


class StepRule(Protocol):
    """Joint increments for the step ``s0 → s1`` of ``path``; ``refinable`` rules may be split
    into equal sub-steps by the runner (automatic step counts)."""

    name: str
    refinable: bool

    def increment(self, path: Path, s0: float, s1: float, inp: StepInput) -> StepIncrement:
        ...


@dataclass(frozen=True)
class FirstOrder:
    """Eq. 4-11: ``J δq = B``."""

    name: str = "first_order"
    refinable: bool = True

    def increment(self, path: Path, s0: float, s1: float, inp: StepInput) -> StepIncrement:
        sol = inp.solve(inp.J, path.step_twist(s0, s1, inp.H))
        return StepIncrement(sol.dq, sol)


@dataclass(frozen=True)
class SecondOrder:
    """Eqs. 4-9 and 5-5 (suggestion 2), from the first-order solution."""

    name: str = "second_order"
    refinable: bool = True

    def increment(self, path: Path, s0: float, s1: float, inp: StepInput) -> StepIncrement:
        B = path.step_twist(s0, s1, inp.H)
        sol = inp.solve(inp.J, B)
        target = path.step_target(s0, s1, inp.H)
        dq, _, _ = solve_second_order(inp.model, inp.q, B, target[:3, 3] - inp.H[:3, 3],
                                      length=inp.length, dq0=sol.dq)
        return StepIncrement(dq, sol)


@dataclass(frozen=True)
class Disp1977:
    """The inferred step of DISP's Illustration 5 run (docs/seed-errata.md G1): B split into
    m equal parts (``split_substep_deg2``, :func:`~.step.split_substep_count`), each solved to
    first order at the current joints with, for ``origin_step``, the origin point's
    second-order displacement as its translation
    (:func:`~.step.origin_displacement_twist`)."""

    origin_step: bool = True
    split_substep_deg2: float | None = 40.0
    name: str = "disp_1977"
    refinable: bool = False

    def increment(self, path: Path, s0: float, s1: float, inp: StepInput) -> StepIncrement:
        B = path.step_twist(s0, s1, inp.H)
        m = 1 if self.split_substep_deg2 is None else split_substep_count(
            B, self.split_substep_deg2)
        Bi = B / m
        if self.origin_step:
            Bi = origin_displacement_twist(Bi)
        q_i = np.array(inp.q, dtype=float)
        sol = None
        for i in range(m):
            J_i = inp.J if i == 0 else jacobian(inp.model, q_i)
            sol = inp.solve(J_i, Bi)
            q_i = q_i + sol.dq
        return StepIncrement(q_i - inp.q, sol, m)


def _positive(name: str, v) -> None:
    if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
        raise InputError(f"{name} must be a positive number, got {v!r}")


@dataclass(frozen=True)
class GuidanceOptions:
    """How to run an analysis.

    - ``step_rule``: ``"first_order"`` (eq. 4-11), ``"second_order"`` (eqs. 4-9, 5-5) or
      ``"disp_1977"`` (the inferred type III rule of Table A2-9, :class:`Disp1977`); one
      option for what used to be exclusive switches. ``second_order=True`` is short for
      ``step_rule="second_order"``; ``origin_step``/``split_substep_deg2`` are the
      parameters of the ``disp_1977`` rule (setting either selects it).
    - ``closed_loop``: after each step, Newton iterations ``J δq = ε`` with ε the error twist
      from the actual to the ideal hand pose of the step, until the hand is within ``tol``·L of
      the path pose and ``tol`` rad of its orientation (L the characteristic length of the
      mechanism: a relative tolerance, 1e-9 by default, ~1 nm on a 1 m arm; beyond the thesis).
      Not with ``disp_1977``.
    - ``singular``: ``"perturb"`` (greedy: one joint by ``perturb_deg`` per try),
      ``"perturb_all"`` (DISP's way, ch. IV: every joint by ``perturb_all_deg`` per try, each
      with the sign that raises σ_min, up to ``max_perturb_all_tries`` tries),
      ``"damped"`` or ``"stop"``; a configuration is singular when the dimensionless
      condition number exceeds ``cond_limit``.
    - ``max_step_deg``, ``max_step_fraction``: the automatic step count (IT = 0): no step
      rotates the hand by more than ``max_step_deg`` or moves its origin by more than
      ``max_step_fraction`` × L; and, for automatically counted stages only, a step whose joint
      increments exceed ``max_joint_step_deg`` (prismatic: that angle in radians × L) is done
      as equal sub-steps (``None`` disables it). Explicit step counts are never refined.
    - ``counted_substep_deg``: for stages counted by a step-count rule (``run_guidance``'s
      ``step_count``, DISP's IT = 0), a step is done as round(largest joint increment /
      ``counted_substep_deg``) equal sub-steps, the Jacobian recomputed at each (prismatic:
      that angle in radians × L); ``None`` (default) takes such counts as they are. Near a
      singularity the first-order increments of a whole step grow as 1/σ_min; sub-steps follow
      the path instead of extrapolating them.
    - ``settle``: after the last step of a stage, take first-order steps straight at the stage's
      target (eq. 4-19 with k = 1: Newton's method) until it is reached to ``settle_tol``; each
      is a table row and a ``settle`` event. A target still missed after ``max_settle`` of them
      stops the run (``target_not_reached``). The position criterion is ``settle_tol`` ×
      ``settle_length`` (default max(1, L)), the angle ``settle_tol`` rad. ``kinestat disp``
      uses it as DISP's final correction, to the printed precision of its tables (0.0005 in
      and 0.0005 rad: every hand point within 0.0005 of the target's).
    """

    step_rule: StepRuleName = "first_order"
    closed_loop: bool = False
    singular: SingularMode = "perturb"
    cond_limit: float = DEFAULT_COND_LIMIT
    tol: float = 1e-9
    max_newton: int = 30
    perturb_deg: float = 1.0
    max_perturb_tries: int = 30
    max_perturbations: int = 25
    perturb_all_deg: float = 0.1
    max_perturb_all_tries: int = 300
    max_damping: float = 0.1
    max_step_deg: float = 1.0
    max_step_fraction: float = 0.01
    max_joint_step_deg: float | None = 2.0
    counted_substep_deg: float | None = None
    settle: bool = True
    settle_tol: float = 1e-9
    settle_length: float | None = None
    max_settle: int = 10
    check_limits: bool = True
    second_order: bool = False
    origin_step: bool = False
    split_substep_deg2: float | None = None

    @classmethod
    def disp_1977(cls, **changes) -> GuidanceOptions:
        """The inferred type III rule that reproduces Nadkarni's Table A2-9 (Illustration 5):
        B from the origin point's second-order displacement, ⌈(δθ°)²/40⌉ sub-steps per step."""
        return cls(**{"step_rule": "disp_1977", "origin_step": True,
                      "split_substep_deg2": 40.0, **changes})

    def __post_init__(self) -> None:
        rule = self.step_rule
        if rule not in STEP_RULES:
            raise InputError(f"step_rule must be one of {', '.join(STEP_RULES)}, got {rule!r}")
        legacy_disp = self.origin_step or self.split_substep_deg2 is not None
        if self.second_order:
            if rule == "disp_1977" or legacy_disp:
                raise InputError("second_order cannot be combined with the DISP 1977 step "
                                 "(origin_step / split_substep_deg2)")
            rule = "second_order"
        if legacy_disp:
            if rule == "second_order":
                raise InputError("origin_step / split_substep_deg2 (the DISP 1977 step) cannot "
                                 "be combined with second_order")
            rule = "disp_1977"
        if rule == "disp_1977" and not legacy_disp:
            object.__setattr__(self, "origin_step", True)
            object.__setattr__(self, "split_substep_deg2", 40.0)
        if rule == "disp_1977" and self.closed_loop:
            raise InputError("the DISP 1977 step (origin_step / split_substep_deg2) cannot be "
                             "combined with second_order or closed_loop")
        object.__setattr__(self, "step_rule", rule)
        object.__setattr__(self, "second_order", rule == "second_order")
        if self.split_substep_deg2 is not None:
            _positive("split_substep_deg2", self.split_substep_deg2)
        if self.singular not in SINGULAR_MODES:
            raise InputError(
                f"singular must be one of {', '.join(SINGULAR_MODES)}, got {self.singular!r}")
        if self.settle_length is not None:
            _positive("settle_length", self.settle_length)
        if self.counted_substep_deg is not None:
            _positive("counted_substep_deg", self.counted_substep_deg)
        for name in ("cond_limit", "tol", "perturb_deg", "perturb_all_deg", "max_step_deg",
                     "max_step_fraction"):
            _positive(name, getattr(self, name))

    def rule(self) -> StepRule:
        """The step-rule strategy of these options."""
        if self.step_rule == "second_order":
            return SecondOrder()
        if self.step_rule == "disp_1977":
            return Disp1977(self.origin_step, self.split_substep_deg2)
        return FirstOrder()
