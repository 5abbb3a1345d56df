"""Running a guidance analysis: the step loop, events, step counts, corrections.

For each stage (a :class:`~.planners.Path`, or a function of the hand pose returning one) and
each step j of k (:class:`_Run`, one small method per part):

1. compute the Jacobian at the current joints; if it is (near) singular, handle it
   (:attr:`GuidanceOptions.singular`) — ``"perturb"``/``"perturb_all"``: Nadkarni's remedy
   (small joint increments until regular, report the new configuration, replan the rest of the
   stage from the actual hand, continue), ``"damped"``: damped least squares for the step,
   ``"stop"``: stop;
2. B = the path's step twist (eq. 4-11's right-hand side); the step rule
   (:mod:`~kinestat.serial.guidance.rules`: first order, second order eq. 5-5, the inferred
   1977 rule) turns it into joint increments;
3. optionally (``closed_loop``) Newton-correct onto the ideal path pose of this step;
4. check the joint limits: a violation ends the run cleanly with a :class:`JointLimitStop`.

Nothing here raises for a motion that cannot be completed: the result carries the rows so far,
``stopped`` and the event that stopped it; :meth:`GuidanceResult.raise_if_stopped` raises
that event's :class:`~kinestat.errors.KinestatError`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from kinestat.errors import InputError, KinestatError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.fk import fk
from kinestat.serial.guidance.events import (
    GuidanceEvent,
    JointLimitStop,
    LeastSquaresStep,
    NotConverged,
    NumericalFailure,
    SettleStep,
    Singularity,
    TargetNotReached,
    newton_failure,
    newton_stalled,
)
from kinestat.serial.guidance.planners import (
    Path,
    StageSpec,
    auto_steps,
    path_extent,
    pose_error,
    resolve_stage,
    twist_between,
)
from kinestat.serial.guidance.rules import SINGULAR_MODES, GuidanceOptions, StepInput, StepRule
from kinestat.serial.guidance.step import (
    characteristic_length,
    conditioning,
    escape_singularity,
    limit_violation,
    perturb_all_joints,
    scaled_jacobian,
    solve_step,
)
from kinestat.serial.jacobian import jacobian
from kinestat.spatial.validate import as_number

__all__ = [
    "GuidanceOptions",
    "GuidanceResult",
    "run_guidance",
    "joint_display",
    "SINGULAR_MODES",
    "MAX_RUN_STEPS",
    "GuidanceInterrupted",
]

#: Ceiling on the path steps of one run, the per-stage counts summed (explicit and automatic
#: alike; correction and sub-steps come on top, each bounded by its own option). 10^5 steps take
#: a minute or two and ~120 MB of rows; see docs/reliability.md, "Limits and ceilings".
MAX_RUN_STEPS = 100_000


class GuidanceInterrupted(KeyboardInterrupt):
    """Ctrl-C during a guidance run: a ``KeyboardInterrupt`` (nothing swallows it) that says
    where the run was: ``step`` of ``planned`` path steps."""

    def __init__(self, step: int, planned: int) -> None:
        self.step, self.planned = int(step), int(planned)
        super().__init__(f"the guidance run was stopped at step {step} of {planned} planned")


@dataclass(frozen=True, eq=False)
class GuidanceResult:
    """Rows of a guidance run (row 0 is the initial configuration).

    ``q`` ``(R, n)`` joint values (radians / length), ``poses`` ``(R, 4, 4)`` actual hand
    poses, ``ideal`` ``(R, 4, 4)`` the ideal path pose of each row, ``stage`` ``(R,)`` the stage
    of each row (-1 for row 0), ``stage_targets`` the ideal end pose of each stage started,
    ``steps`` the planned step count per stage, ``events`` typed events
    (:mod:`~kinestat.serial.guidance.events`), ``stopped``/``stop_kind``/``stop_message``/
    ``stop_event`` when the run ended early.
    """

    model: ChainModel
    q: np.ndarray
    poses: np.ndarray
    ideal: np.ndarray
    stage: np.ndarray
    stage_targets: tuple[np.ndarray, ...]
    steps: tuple[int, ...]
    events: tuple[GuidanceEvent, ...]
    length: float
    stopped: bool = False
    stop_kind: str | None = None
    stop_message: str | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    substeps: int = 0
    stop_event: GuidanceEvent | None = None

    @property
    def final_q(self) -> np.ndarray:
        return self.q[-1]

    @property
    def final_pose(self) -> np.ndarray:
        return self.poses[-1]

    def settle_rows(self) -> set[int]:
        """Rows that are correction (settle) steps, not path steps."""
        return {e.step for e in self.events if isinstance(e, SettleStep)}

    def stage_end_rows(self) -> list[int]:
        """Index of the last row of each stage that ran (its end, or where it stopped)."""
        out = []
        for s in range(len(self.stage_targets)):
            rows = np.nonzero(self.stage == s)[0]
            out.append(int(rows[-1]) if rows.size else (out[-1] if out else 0))
        return out

    def final_pose_error(self) -> tuple[float, float]:
        """(origin distance, angle in rad) between the final hand pose and the last target."""
        if not self.stage_targets:
            return 0.0, 0.0
        dp, da = pose_error(self.poses[-1], self.stage_targets[-1])
        return float(dp), float(da)

    def path_deviation(self) -> tuple[np.ndarray, np.ndarray]:
        """Per row, (origin distance, angle in rad) between the actual and ideal hand pose."""
        return pose_error(self.poses, self.ideal)

    def max_path_deviation(self) -> tuple[float, float]:
        dp, da = self.path_deviation()
        return float(np.max(dp)), float(np.max(da))

    def raise_if_stopped(self) -> None:
        """Raise the error of the stopping event (JointLimitError, SingularityError, ...)."""
        if not self.stopped:
            return
        msg = self.stop_message or "the guidance run stopped"
        if self.stop_event is None:
            raise KinestatError(msg)
        raise self.stop_event.error(msg)


def joint_display(model: ChainModel, q) -> np.ndarray:
    """Joint values as the thesis prints them: degrees for revolute and screw joints, length
    units for prismatic joints (batched).

    >>> from kinestat.io.library import load
    >>> joint_display(load("puma762"), [math.pi / 2, 0, 0, 0, 0, 0]).tolist()
    [90.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    """
    q = np.asarray(q, dtype=float)
    return np.where(model.prismatic, q, np.degrees(q))


def _unit(model: ChainModel, i: int) -> str:
    return model.length_unit if model.prismatic[i] else "deg"


def _step_count(s) -> int | None:
    """One stage's step count: a whole number ≥ 0 (0/None: automatic), else InputError."""
    if s is None:
        return None
    if isinstance(s, bool) or not isinstance(s, (int, np.integer, float, np.floating)):
        raise InputError(f"a step count must be a whole number, got {s!r}")
    if isinstance(s, (float, np.floating)) and not (math.isfinite(s) and float(s).is_integer()):
        raise InputError(f"a step count must be a whole number, got {s!r}")
    if s < 0:
        raise InputError("step counts must be positive integers (0 means automatic)")
    if s > MAX_RUN_STEPS:
        raise InputError(f"a step count of {int(s)} is over the ceiling of {MAX_RUN_STEPS} "
                         "steps per run")
    return int(s) or None


def _per_stage_steps(steps, n_stages: int) -> list[int | None]:
    if steps is None or isinstance(steps, (int, np.integer, float, np.floating)):
        per_stage: list[int | None] = [_step_count(steps)] * n_stages
    else:
        per_stage = [_step_count(s) for s in steps]
        if len(per_stage) != n_stages:
            raise InputError(
                f"{len(per_stage)} step counts given for {n_stages} stages; give one count "
                "for all or one per stage")
    total = sum(s for s in per_stage if s is not None)
    if total > MAX_RUN_STEPS:
        raise InputError(
            f"{total} steps over {n_stages} stages is over the ceiling of {MAX_RUN_STEPS} steps "
            "per run: give fewer steps or split the motion into several runs")
    return per_stage


@dataclass
class _Stage:
    """The stage being run: its path (replaced after a perturbation), step count k, the step
    j0 at which the current path object starts, and the sub-step limit (automatic counts
    only; ``nearest``: sub-step counts rounded to the nearest)."""

    index: int
    path: Path
    k: int
    refine: float | None
    j0: int = 0
    nearest: bool = False

    def fractions(self, j: int) -> tuple[float, float]:
        return (j - 1 - self.j0) / (self.k - self.j0), (j - self.j0) / (self.k - self.j0)


class _Run:
    """The mutable state of one run: current joints and hand, rows, events, the stop."""

    def __init__(self, model: ChainModel, q: np.ndarray, opt: GuidanceOptions, L: float,
                 progress: Callable[[int, int], None] | None,
                 rule: StepRule | None = None,
                 step_count: Callable[[Path], int] | None = None) -> None:
        self.model, self.opt, self.L, self.progress = model, opt, L, progress
        self.step_count = step_count
        self.rule: StepRule = opt.rule() if rule is None else rule
        self.q = q
        self.H = fk(model, q)
        self.rows_q = [q.copy()]
        self.rows_T = [self.H]
        self.rows_ideal = [self.H]
        self.rows_stage = [-1]
        self.events: list[GuidanceEvent] = []
        self.targets: list[np.ndarray] = []
        self.planned: list[int] = []
        self.stop_event: GuidanceEvent | None = None
        self.stop_msg: str | None = None
        self.gstep = 0
        self.perturbations = 0
        self.total_planned = 0
        self.substeps = 0

    # -- bookkeeping -------------------------------------------------------------------------
    def stop(self, event: GuidanceEvent, message: str) -> None:
        self.events.append(event)
        self.stop_event, self.stop_msg = event, message

    def accept(self, q_new: np.ndarray, ideal, stage: int) -> None:
        self.q = q_new
        self.H = fk(self.model, q_new)
        self.rows_q.append(q_new.copy())
        self.rows_T.append(self.H)
        self.rows_ideal.append(np.asarray(ideal, dtype=float))
        self.rows_stage.append(stage)

    def limit_stop(self, q_new, stage: int | None) -> bool:
        """Stop with a :class:`JointLimitStop` if ``q_new`` leaves the limits (ch. IV, 2))."""
        if not self.opt.check_limits or (v := limit_violation(self.model, q_new)) is None:
            return False
        m = self.model
        i, side, lim, _ = v
        dv = float(joint_display(m, np.where(np.arange(m.n) == i, lim, 0.0))[i])
        val = float(joint_display(m, q_new)[i])
        ev = JointLimitStop(self.gstep, stage, joint=i + 1, limit=side, limit_value=dv,
                            value=val, unit=_unit(m, i))
        if stage is None:
            msg = f"joint {i + 1} starts outside its {side} limit ({val:.6g} {_unit(m, i)})"
        else:
            msg = (f"joint {i + 1} would pass its {side} limit ({dv:.6g} {_unit(m, i)}) at step "
                   f"{self.gstep}: stopped with the configuration of step {self.gstep - 1}")
        self.stop(ev, msg)
        return True

    def _error_small(self, T, T_ref, tol: float, scale: float | None = None
                     ) -> tuple[bool, float, float]:
        """Pose error of ``T`` from ``T_ref`` within ``tol`` rad and ``tol``·scale (default
        max(1, L))."""
        dp, da = pose_error(T, T_ref)
        scale = max(1.0, self.L) if scale is None else scale
        return bool(da <= tol and dp <= tol * scale), float(dp), float(da)

    def _solve(self, J, B, damping):
        o = self.opt
        return solve_step(J, B, prismatic=self.model.prismatic, length=self.L, damping=damping,
                          cond_limit=o.cond_limit, max_damping=o.max_damping)

    # -- a stage -----------------------------------------------------------------------------
    def run_stage(self, si: int, spec: StageSpec, k_given: int | None) -> None:
        path = resolve_stage(spec, self.H)
        refine = None
        k = k_given
        left = MAX_RUN_STEPS - self.total_planned
        counted = k is None and self.step_count is not None
        if counted:
            k = _step_count(self.step_count(path))
            refine = self.opt.counted_substep_deg
        if k is None:
            refine = self.opt.max_joint_step_deg
            k = auto_steps(path, self.L, max_step_deg=self.opt.max_step_deg,
                           max_step_fraction=self.opt.max_step_fraction, max_steps=left)
        elif not all(map(math.isfinite, path_extent(path, samples=8))):
            raise InputError(f"stage {si + 1}: the motion is not finite (a distance, angle or "
                             "target too large to guide)")
        self.planned.append(k)
        self.total_planned += k
        self.targets.append(np.asarray(path.end, dtype=float))
        stage = _Stage(si, path, k, refine, nearest=counted)
        try:
            for j in range(1, k + 1):
                self.gstep += 1
                if not self.step(stage, j):
                    break
                if self.progress is not None:
                    self.progress(self.gstep, self.total_planned)
            if self.stop_event is None and self.opt.settle:
                self.settle(si)
        except np.linalg.LinAlgError as exc:  # e.g. "SVD did not converge" on extreme numbers
            self.numerical_stop(stage, f"the linear algebra of the step failed ({exc})")
        if isinstance(self.stop_event, (Singularity, NotConverged)):
            dp, _ = pose_error(self.H, self.targets[-1])
            if dp > 1e-6 * max(1.0, self.L):
                self.stop_msg += (f"; the hand is still {float(dp):.4g} "
                                  f"{self.model.length_unit} from the target of stage "
                                  f"{si + 1}, which may be out of reach")

    def step(self, st: _Stage, j: int) -> bool:
        """Step j of the stage; False when the run stopped."""
        J = jacobian(self.model, self.q)
        damping = None
        smin, cond = conditioning(scaled_jacobian(J, self.model.prismatic, self.L))
        if cond > self.opt.cond_limit:
            handled = self.singular(st, j, J, float(smin), float(cond))
            if handled is None:
                return False
            J, damping = handled
        s0, s1 = st.fractions(j)
        inc = self.increment(st, s0, s1, J, damping)
        q_new = self.q + inc
        if not np.all(np.isfinite(q_new)):
            return self.numerical_stop(st, "the joint increments are not finite")
        ideal = st.path.pose_at(s1)
        if self.opt.closed_loop:
            q_new = self.newton(st, ideal, q_new)
            if q_new is None:
                return False
        if self.limit_stop(q_new, st.index + 1):
            return False
        self.accept(q_new, ideal, st.index)
        return True

    def numerical_stop(self, st: _Stage, reason: str) -> bool:
        """Stop with a :class:`NumericalFailure` at the current step; returns False."""
        self.stop(NumericalFailure(self.gstep, st.index + 1, reason=reason),
                  f"step {self.gstep}: {reason}; stopped with the configuration of step "
                  f"{self.gstep - 1} (the motion is too large or passes a degenerate "
                  "configuration)")
        return False

    def increment(self, st: _Stage, s0: float, s1: float, J, damping) -> np.ndarray:
        """Joint increments of the step from the step rule; for automatic step counts a step
        whose increments exceed ``max_joint_step_deg`` is redone as equal sub-steps."""
        o = self.opt
        inp = StepInput(self.model, self.q, self.H, J, self.L, damping, o.cond_limit,
                        o.max_damping)
        res = self.rule.increment(st.path, s0, s1, inp)
        self.substeps += res.substeps - 1
        if damping is not None:
            ev = self.events[-1]
            self.events[-1] = dataclasses.replace(ev, damping=float(res.solution.damping))
        if self.model.n != 6 and res.solution.residual > 1e-9:
            self.events.append(LeastSquaresStep(self.gstep, st.index + 1,
                                                residual=float(res.solution.residual)))
        m_sub = _substeps(self.model, res.dq, self.L, st.refine if self.rule.refinable else None,
                          nearest=st.nearest)
        if m_sub <= 1:
            return res.dq
        q_i, H_i = self.q, self.H  # the same hand motion in m_sub smaller steps
        for i in range(m_sub):
            a = s0 + (s1 - s0) * i / m_sub
            b = s0 + (s1 - s0) * (i + 1) / m_sub
            J_i = J if i == 0 else jacobian(self.model, q_i)
            sub = StepInput(self.model, q_i, H_i, J_i, self.L, damping, o.cond_limit,
                            o.max_damping)
            q_i = q_i + self.rule.increment(st.path, a, b, sub).dq
            H_i = fk(self.model, q_i)
        self.substeps += m_sub - 1
        return q_i - self.q

    # -- singularities (ch. IV, "Singularities" 1)) ------------------------------------------
    def singular(self, st: _Stage, j: int, J, smin: float, cond: float):
        """Handle a singular [A]: ``(J, damping)`` to go on with, or None when stopped."""
        o = self.opt
        base = dict(sigma_min=smin, cond=cond)
        where = (self.gstep, st.index + 1)
        if o.singular == "stop" or (o.singular.startswith("perturb")
                                    and self.perturbations >= o.max_perturbations):
            self.stop(Singularity(*where, **base),
                      f"singular configuration at step {self.gstep} (condition number "
                      f"{cond:.3g} > {o.cond_limit:g})")
            return None
        if o.singular == "damped":
            self.events.append(Singularity(*where, **base, action="damped"))
            return J, "auto"
        if o.singular == "perturb_all":
            escape, inc, tries_max = (perturb_all_joints, o.perturb_all_deg,
                                      o.max_perturb_all_tries)
        else:
            escape, inc, tries_max = escape_singularity, o.perturb_deg, o.max_perturb_tries
        q_new, cond_new, tries = escape(self.model, self.q, length=self.L,
                                        cond_limit=o.cond_limit, increment_deg=inc,
                                        max_tries=tries_max)
        self.perturbations += 1
        base.update(joint_increments=joint_display(self.model, q_new - self.q), tries=tries,
                    cond_after=cond_new, method=o.singular)
        if cond_new >= o.cond_limit:
            self.stop(Singularity(*where, **base),
                      f"singular at step {self.gstep}: {tries} small joint increments did not "
                      f"bring the condition number below {o.cond_limit:g} (best "
                      f"{cond_new:.3g}); the motion cannot continue")
            return None
        if o.check_limits and limit_violation(self.model, q_new) is not None:
            self.stop(Singularity(*where, **base),
                      f"singular at step {self.gstep} and no perturbation within limits")
            return None
        H_new = fk(self.model, q_new)
        dp, da = pose_error(H_new, self.H)
        self.events.append(Singularity(
            *where, **base, action="perturbed", q=joint_display(self.model, q_new),
            hand_shift=float(dp), hand_rotation_deg=math.degrees(float(da))))
        s0, _ = st.fractions(j)
        self.q, self.H = q_new, H_new
        st.path = st.path.replan(H_new, s0)
        st.j0 = j - 1
        return jacobian(self.model, self.q), None

    # -- corrections -------------------------------------------------------------------------
    def newton(self, st: _Stage, target, q) -> np.ndarray | None:
        """Closed loop: Newton iterations ``J δq = twist(actual → target)`` until the hand is
        within ``tol``·L and ``tol`` rad of the step's path pose; the corrected joints, or None
        (stopped, with the reason) when they do not get there."""
        o = self.opt
        damping = "auto" if o.singular == "damped" else None
        history: list[float] = []
        for it in range(o.max_newton + 1):
            T = fk(self.model, q)
            ok, dp, da = self._error_small(T, target, o.tol, self.L)
            if ok:
                return q
            history.append(dp / self.L + da)
            if it == o.max_newton or newton_stalled(history):
                break
            q = q + self._solve(jacobian(self.model, q), twist_between(T, target), damping).dq
        _, cond = conditioning(scaled_jacobian(jacobian(self.model, q), self.model.prismatic,
                                               self.L))
        reason, why = newton_failure(float(cond), o.cond_limit, history)
        unit = self.model.length_unit
        self.stop(NotConverged(self.gstep, st.index + 1, position_error=dp,
                               angle_error_deg=math.degrees(da), iterations=len(history) - 1,
                               reason=reason, cond=float(cond)),
                  f"step {self.gstep}: the closed-loop correction did not bring the hand onto "
                  f"the path: after {len(history) - 1} Newton iterations it is {dp:.3g} {unit} "
                  f"and {math.degrees(da):.3g} deg from the step's path pose (tolerance "
                  f"{o.tol * self.L:.3g} {unit} = {o.tol:g} × L and {o.tol:g} rad); {why}")
        return None

    def settle(self, si: int) -> None:
        """Correction steps straight at the stage target (eq. 4-19 with k = 1)."""
        o = self.opt
        target = self.targets[-1]
        for it in range(o.max_settle + 1):
            ok, dp, da = self._error_small(self.H, target, o.settle_tol, o.settle_length)
            if ok:
                return
            if it == o.max_settle:
                self.stop(TargetNotReached(self.gstep, si + 1, position_error=dp,
                                           angle_error_deg=math.degrees(da)),
                          f"stage {si + 1}: the target was not reached (error {dp:.3g} "
                          f"{self.model.length_unit}, {math.degrees(da):.3g} deg after "
                          f"{o.max_settle} correction steps): it is out of reach or beyond a "
                          "singularity")
                return
            self.gstep += 1
            damping = "auto" if o.singular == "damped" else None
            sol = self._solve(jacobian(self.model, self.q), twist_between(self.H, target),
                              damping)
            q_new = self.q + sol.dq
            self.events.append(SettleStep(self.gstep, si + 1, position_error=dp,
                                          angle_error_deg=math.degrees(da)))
            if self.limit_stop(q_new, si + 1):
                return
            self.accept(q_new, target, si)

    def result(self, notes: list[str]) -> GuidanceResult:
        ev = self.stop_event
        return GuidanceResult(
            model=self.model, q=np.array(self.rows_q), poses=np.array(self.rows_T),
            ideal=np.array(self.rows_ideal), stage=np.array(self.rows_stage),
            stage_targets=tuple(self.targets), steps=tuple(self.planned),
            events=tuple(self.events), length=self.L, stopped=ev is not None,
            stop_kind=None if ev is None else ev.kind, stop_message=self.stop_msg,
            notes=tuple(notes), substeps=self.substeps, stop_event=ev)


def run_guidance(
    model: ChainModel,
    q0,
    stages: Sequence[StageSpec],
    *,
    steps: Sequence[int | None] | int | None = None,
    options: GuidanceOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
    length: float | None = None,
    rule: StepRule | None = None,
    step_count: Callable[[Path], int] | None = None,
) -> GuidanceResult:
    """Guide the hand of ``model`` from joint values ``q0`` through ``stages`` (Nadkarni
    ch. IV: eq. 4-11 per step, the singularity and joint-limit rules of "Singularities").

    Args:
        stages: paths (:mod:`~kinestat.serial.guidance.planners`) or functions
            ``hand_pose -> path`` called with the actual hand pose when the stage starts (so a
            command continues where the last one ended).
        steps: one count for every stage, one per stage, or None/0 for automatic
            (:func:`~kinestat.serial.guidance.planners.auto_steps`).
        length: the characteristic length L (default: from ``q0``).
        progress: called as ``progress(steps_done, steps_planned_so_far)``.
        rule: a step rule (:class:`~kinestat.serial.guidance.rules.StepRule`) to use instead
            of the one ``options.step_rule`` names.
        step_count: for stages without a count, ``path -> k`` called with the stage's path
            at its start (e.g. DISP's inferred IT = 0 rule) instead of
            :func:`~kinestat.serial.guidance.planners.auto_steps`; such counts are refined
            into sub-steps only with ``options.counted_substep_deg``.

    >>> from kinestat.io.library import load
    >>> from kinestat.serial.guidance.planners import command_path
    >>> m = load("nadkarni-config2")
    >>> r = run_guidance(m, m.q_home, [lambda H: command_path(H, [0, 0, 1], 4.0, 0.0)],
    ...                  steps=8)
    >>> len(r.q), r.final_pose_error()[0] < 1e-9          # 8 steps + the initial row
    (9, True)
    """
    opt = options or GuidanceOptions()
    q = model.check_q(q0, "q0").astype(float)
    if q.ndim != 1:
        raise InputError(f"q0 must be one configuration of shape ({model.n},)")
    stages = list(stages)
    if not stages:
        raise InputError("no stages to run: give at least one target or command")
    per_stage = _per_stage_steps(steps, len(stages))
    L = characteristic_length(model, q) if length is None else \
        as_number(length, "length", positive=True)
    notes: list[str] = []
    if model.n != 6:
        notes.append(
            f"the chain has {model.n} joints, not 6: each step solves J δq = B in the "
            "least-squares sense" + (" (minimum-norm increments)" if model.n > 6 else
                                     " (the residual is reported in the events)"))
    run = _Run(model, q, opt, L, progress, rule, step_count)
    if run.limit_stop(q, None):
        return run.result(notes)
    try:
        for si, spec in enumerate(stages):
            run.run_stage(si, spec, per_stage[si])
            if run.stop_event is not None:
                break
    except KeyboardInterrupt as exc:
        if isinstance(exc, GuidanceInterrupted):
            raise
        raise GuidanceInterrupted(run.gstep, run.total_planned) from None
    return run.result(notes)


def _substeps(model: ChainModel, dq, L: float, max_joint_step_deg: float | None, *,
              nearest: bool = False) -> int:
    """Sub-steps so that no joint moves more than the limit (prismatic: in radians times L);
    ``nearest``: the ratio rounded to the nearest (up to 1.5 × the limit each), else up."""
    if max_joint_step_deg is None:
        return 1
    size = float(np.max(np.abs(np.where(model.prismatic, dq / L, dq))))
    x = size / math.radians(max_joint_step_deg)
    m = math.floor(x + 0.5) if nearest else math.ceil(x - 1e-9)
    return int(min(1000, max(1, m)))
