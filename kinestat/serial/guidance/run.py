"""Running a guidance analysis: the step loop, events, step counts, corrections.

For each stage (a path, or a function of the hand pose returning one) and each step j of k:

1. compute the Jacobian at the current joints; if it is (near) singular, handle it —
   ``"perturb"``: Nadkarni's remedy (small joint increments until regular, report the new
   configuration, replan the rest of the stage from the actual hand, continue),
   ``"damped"``: damped least squares for the step, ``"stop"``: stop;
2. B = the path's step twist (eq. 4-11's right-hand side); solve ``J δq = B``
   (:func:`~kinestat.serial.guidance.step.solve_step`); optionally refine with the second-order
   terms of eq. 5-5;
3. optionally (``closed_loop``) Newton-correct onto the ideal path pose of this step until the
   error twist is below ``tol``;
4. check the joint limits: a violation ends the run cleanly with a ``joint_limit`` event.

Nothing here raises for a motion that cannot be completed: the result carries the rows so far,
``stopped`` and the event that stopped it; :meth:`GuidanceResult.raise_if_stopped` turns that
into the matching :class:`~kinestat.errors.KinestatError` when the caller wants an exception.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from kinestat.errors import (
    InputError,
    JointLimitError,
    KinestatError,
    SingularityError,
    UnreachableError,
)
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.fk import fk
from kinestat.serial.guidance.planners import auto_steps, pose_error, twist_between
from kinestat.serial.guidance.step import (
    DEFAULT_COND_LIMIT,
    characteristic_length,
    conditioning,
    escape_singularity,
    limit_violation,
    origin_displacement_twist,
    scaled_jacobian,
    solve_second_order,
    solve_step,
    split_substep_count,
)
from kinestat.serial.jacobian import jacobian

__all__ = [
    "GuidanceOptions",
    "GuidanceResult",
    "run_guidance",
    "joint_display",
    "result_record",
    "SINGULAR_MODES",
]

SINGULAR_MODES = ("perturb", "damped", "stop")


@dataclass(frozen=True)
class GuidanceOptions:
    """How to run an analysis.

    - ``closed_loop``: after each first-order step, Newton iterations ``J δq = ε`` with ε the
      error twist from the actual to the ideal hand pose of the step, until
      ``|ε_ω| ≤ tol`` and ``|ε_p| ≤ tol·max(1, L)`` (beyond the thesis).
    - ``second_order``: solve eqs. 4-9 and 5-5 (Nadkarni suggestion 2) instead of 4-11.
    - ``singular``: ``"perturb"`` (the thesis), ``"damped"`` or ``"stop"``; a configuration is
      singular when the dimensionless condition number exceeds ``cond_limit``.
    - ``max_step_deg``, ``max_step_fraction``: the automatic step count (IT = 0): no step
      rotates the hand by more than ``max_step_deg`` or moves its origin by more than
      ``max_step_fraction`` × L; and, for automatically counted stages only, a step whose joint
      increments exceed ``max_joint_step_deg`` (prismatic: that angle in radians × L) is done
      as equal sub-steps (``None`` disables it). Explicit step counts are never refined.
    - ``settle``: after the last step of a stage, take first-order steps straight at the stage's
      target (the screw from the actual hand to it, eq. 4-19 with k = 1: Newton's method) until
      it is reached to ``settle_tol`` (angle in rad; origin in length × max(1, L)); each is a
      table row and a ``settle`` event. A target still missed after ``max_settle`` of them
      stops the run (``target_not_reached``).
    - ``origin_step`` (DISP 1977, Table A2-9): B's translation is the second-order displacement
      of the body point at the global origin, ``v + ½ ω×v``
      (:func:`~kinestat.serial.guidance.step.origin_displacement_twist`), solved to first
      order; ``split_substep_deg2``: every step is done as
      :func:`~kinestat.serial.guidance.step.split_substep_count` equal sub-steps with the
      same twist (the Jacobian recomputed for each). :meth:`disp_1977` sets both; with them
      Illustration 5 reproduces Table A2-9 (docs/seed-errata.md G1). Not combinable with
      ``second_order`` or ``closed_loop``.
    """

    closed_loop: bool = False
    second_order: bool = False
    singular: str = "perturb"
    cond_limit: float = DEFAULT_COND_LIMIT
    tol: float = 1e-12
    max_newton: int = 30
    perturb_deg: float = 1.0
    max_perturb_tries: int = 30
    max_perturbations: int = 25
    max_damping: float = 0.1
    max_step_deg: float = 1.0
    max_step_fraction: float = 0.01
    max_joint_step_deg: float | None = 2.0
    settle: bool = True
    settle_tol: float = 1e-9
    max_settle: int = 10
    check_limits: bool = True
    origin_step: bool = False
    split_substep_deg2: float | None = None

    @classmethod
    def disp_1977(cls, **changes) -> GuidanceOptions:
        """The step rule that reproduces Nadkarni's Table A2-9 (Illustration 5): B from the
        origin point's second-order displacement, ⌈(δθ°)²/40⌉ sub-steps per step."""
        return cls(**{"origin_step": True, "split_substep_deg2": 40.0, **changes})

    def __post_init__(self) -> None:
        if (self.origin_step or self.split_substep_deg2 is not None) and (
                self.second_order or self.closed_loop):
            raise InputError("origin_step / split_substep_deg2 (the DISP 1977 step) cannot be "
                             "combined with second_order or closed_loop")
        if self.split_substep_deg2 is not None:
            v = self.split_substep_deg2
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"split_substep_deg2 must be a positive number, got {v!r}")
        if self.singular not in SINGULAR_MODES:
            raise InputError(
                f"singular must be one of {', '.join(SINGULAR_MODES)}, got {self.singular!r}")
        for name in ("cond_limit", "tol", "perturb_deg", "max_step_deg", "max_step_fraction"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"{name} must be a positive number, got {v!r}")


@dataclass(frozen=True, eq=False)
class GuidanceResult:
    """Rows of a guidance run (row 0 is the initial configuration).

    ``q`` ``(R, n)`` joint values (radians / length), ``poses`` ``(R, 4, 4)`` actual hand
    poses, ``ideal`` ``(R, 4, 4)`` the ideal path pose of each row, ``stage`` ``(R,)`` the stage
    of each row (-1 for row 0), ``stage_targets`` the ideal end pose of each stage started,
    ``steps`` the planned step count per stage, ``events`` dicts with at least ``step`` (global,
    1-based) and ``kind``, ``stopped``/``stop_kind``/``stop_message`` when the run ended early.
    """

    model: ChainModel
    q: np.ndarray
    poses: np.ndarray
    ideal: np.ndarray
    stage: np.ndarray
    stage_targets: tuple[np.ndarray, ...]
    steps: tuple[int, ...]
    events: tuple[dict, ...]
    length: float
    stopped: bool = False
    stop_kind: str | None = None
    stop_message: str | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    substeps: int = 0

    @property
    def final_q(self) -> np.ndarray:
        return self.q[-1]

    @property
    def final_pose(self) -> np.ndarray:
        return self.poses[-1]

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
        """Raise the error matching the stop (JointLimitError, SingularityError, ...)."""
        if not self.stopped:
            return
        msg = self.stop_message or "the guidance run stopped"
        if self.stop_kind == "joint_limit":
            ev = next(e for e in self.events if e["kind"] == "joint_limit")
            raise JointLimitError(msg, joint=ev["joint"], step=ev["step"],
                                  limit=ev["limit_value"], value=ev["value"])
        if self.stop_kind == "singular":
            raise SingularityError(msg)
        if self.stop_kind in ("not_converged", "target_not_reached"):
            raise UnreachableError(msg)
        raise KinestatError(msg)


def joint_display(model: ChainModel, q) -> np.ndarray:
    """Joint values as the thesis prints them: degrees for revolute and screw joints, length
    units for prismatic joints (batched)."""
    q = np.asarray(q, dtype=float)
    return np.where(model.prismatic, q, np.degrees(q))


def result_record(result: GuidanceResult, *, hand_points_every_row: bool = False) -> dict:
    """A plain record of a run (arrays stay numpy; ``to_jsonable`` them for JSON).

    Keys: ``columns``, ``units``, ``table`` (joint values per row, initial first, degrees for
    revolute joints), ``hand_origins``, ``final_hand_points`` (origin, unit point on +z, unit
    point on +x), ``target_hand_points``, ``events``, ``steps``, ``substeps``,
    ``final_pose_error`` and ``max_path_deviation`` (``position``, ``angle_deg``), ``stopped``,
    ``stop_reason`` (``stop_message``), ``stage_hand_origins`` (the hand origin at the end of
    each stage) and, when asked, ``hand_points`` of every row.
    """
    from kinestat.mechanism.nadkarni import hand_points

    m = result.model
    rec: dict = {
        "columns": [(f"r{i + 1}" if m.prismatic[i] else f"theta{i + 1}") for i in range(m.n)],
        "units": [m.length_unit if p else "deg" for p in m.prismatic],
        "table": joint_display(m, result.q),
        "hand_origins": result.poses[:, :3, 3],
    }
    if hand_points_every_row:
        rec["hand_points"] = hand_points(result.poses)
    rec["final_hand_points"] = hand_points(result.final_pose)
    rec["target_hand_points"] = [hand_points(T) for T in result.stage_targets]
    rec["stage_hand_origins"] = [result.poses[i, :3, 3] for i in result.stage_end_rows()]
    rec["events"] = list(result.events)
    rec["steps"] = list(result.steps)
    rec["substeps"] = result.substeps
    dp, da = result.final_pose_error()
    rec["final_pose_error"] = {"position": dp, "angle_deg": math.degrees(da)}
    mp, ma = result.max_path_deviation()
    rec["max_path_deviation"] = {"position": mp, "angle_deg": math.degrees(ma)}
    rec["stopped"] = result.stopped
    rec["stop_reason"] = result.stop_kind
    if result.stop_message:
        rec["stop_message"] = result.stop_message
    rec["length_scale"] = result.length
    return rec


def _unit(model: ChainModel, i: int) -> str:
    return model.length_unit if model.prismatic[i] else "deg"


def _error_small(T, T_ref, tol: float, length: float) -> tuple[bool, float, float]:
    dp, da = pose_error(T, T_ref)
    return bool(da <= tol and dp <= tol * max(1.0, length)), float(dp), float(da)


def run_guidance(
    model: ChainModel,
    q0,
    stages: Sequence[object],
    *,
    steps: Sequence[int | None] | int | None = None,
    options: GuidanceOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
    length: float | None = None,
) -> GuidanceResult:
    """Guide the hand of ``model`` from joint values ``q0`` through ``stages``.

    Args:
        stages: paths (:mod:`~kinestat.serial.guidance.planners`) or functions
            ``hand_pose -> path`` called with the actual hand pose when the stage starts (so a
            command continues where the last one ended).
        steps: one count for every stage, one per stage, or None/0 for automatic
            (:func:`~kinestat.serial.guidance.planners.auto_steps`).
        length: the characteristic length L (default: from ``q0``).
        progress: called as ``progress(steps_done, steps_planned_so_far)``.
    """
    opt = options or GuidanceOptions()
    q = model.check_q(q0).astype(float)
    if q.ndim != 1:
        raise InputError(f"q0 must be one configuration of shape ({model.n},)")
    stages = list(stages)
    if not stages:
        raise InputError("no stages to run: give at least one target or command")
    if steps is None or isinstance(steps, (int, np.integer)):
        per_stage: list[int | None] = [None if not steps else int(steps)] * len(stages)
    else:
        per_stage = [None if not s else int(s) for s in steps]
        if len(per_stage) != len(stages):
            raise InputError(
                f"{len(per_stage)} step counts given for {len(stages)} stages; give one count "
                "for all or one per stage")
    if any(s is not None and s < 1 for s in per_stage):
        raise InputError("step counts must be positive integers (0 means automatic)")
    L = characteristic_length(model, q) if length is None else float(length)
    pris = model.prismatic
    notes: list[str] = []
    if model.n != 6:
        notes.append(
            f"the chain has {model.n} joints, not 6: each step solves J δq = B in the "
            "least-squares sense" + (" (minimum-norm increments)" if model.n > 6 else
                                     " (the residual is reported in the events)"))

    H = fk(model, q)
    rows_q = [q.copy()]
    rows_T = [H]
    rows_ideal = [H]
    rows_stage = [-1]
    events: list[dict] = []
    targets: list[np.ndarray] = []
    planned: list[int] = []
    stop_kind = None
    stop_msg = None
    gstep = 0
    perturbations = 0
    total_planned = 0
    substeps = 0

    if opt.check_limits and (v := limit_violation(model, q)) is not None:
        i, side, lim, val = v
        disp = joint_display(model, np.array([lim if j == i else 0.0 for j in range(model.n)]))
        events.append({"step": 0, "kind": "joint_limit", "joint": i + 1, "limit": side,
                       "limit_value": float(disp[i]),
                       "value": float(joint_display(model, q)[i]), "unit": _unit(model, i),
                       "action": "stopped"})
        stop_kind = "joint_limit"
        stop_msg = (f"joint {i + 1} starts outside its {side} limit "
                    f"({float(joint_display(model, q)[i]):.6g} {_unit(model, i)})")
        return GuidanceResult(model, np.array(rows_q), np.array(rows_T), np.array(rows_ideal),
                              np.array(rows_stage), (), (), tuple(events), L, True, stop_kind,
                              stop_msg, tuple(notes))

    for si, spec in enumerate(stages):
        path = spec(H) if callable(spec) and not hasattr(spec, "pose_at") else spec
        k = per_stage[si]
        refine = None
        if k is None:
            refine = opt.max_joint_step_deg
            k = auto_steps(path, L, max_step_deg=opt.max_step_deg,
                           max_step_fraction=opt.max_step_fraction)
        planned.append(k)
        total_planned += k
        targets.append(np.asarray(path.end, dtype=float))
        j0 = 0  # step index at which the current path object starts (replanning)
        for j in range(1, k + 1):
            gstep += 1
            s0 = (j - 1 - j0) / (k - j0)
            s1 = (j - j0) / (k - j0)
            J = jacobian(model, q)
            smin, cond = conditioning(scaled_jacobian(J, pris, L))
            damping = None
            if cond > opt.cond_limit:
                ev = {"step": gstep, "stage": si + 1, "kind": "singular",
                      "sigma_min": float(smin), "cond": float(cond)}
                if opt.singular == "stop" or (opt.singular == "perturb"
                                              and perturbations >= opt.max_perturbations):
                    ev["action"] = "stopped"
                    events.append(ev)
                    stop_kind = "singular"
                    stop_msg = (f"singular configuration at step {gstep} (condition number "
                                f"{float(cond):.3g} > {opt.cond_limit:g})")
                    break
                if opt.singular == "perturb":
                    q_new, cond_new, tries = escape_singularity(
                        model, q, length=L, cond_limit=opt.cond_limit,
                        increment_deg=opt.perturb_deg, max_tries=opt.max_perturb_tries)
                    perturbations += 1
                    ev["joint_increments"] = joint_display(model, q_new - q)
                    ev["tries"] = tries
                    ev["cond_after"] = cond_new
                    if cond_new >= opt.cond_limit:
                        ev["action"] = "stopped"
                        events.append(ev)
                        stop_kind = "singular"
                        stop_msg = (
                            f"singular at step {gstep}: {tries} small joint increments did not "
                            f"bring the condition number below {opt.cond_limit:g} "
                            f"(best {cond_new:.3g}); the motion cannot continue")
                        break
                    if opt.check_limits and limit_violation(model, q_new) is not None:
                        ev["action"] = "stopped"
                        events.append(ev)
                        stop_kind = "singular"
                        stop_msg = f"singular at step {gstep} and no perturbation within limits"
                        break
                    H_new = fk(model, q_new)
                    dp, da = pose_error(H_new, H)
                    ev.update(action="perturbed", q=joint_display(model, q_new),
                              hand_shift=float(dp), hand_rotation_deg=math.degrees(float(da)))
                    events.append(ev)
                    q, H = q_new, H_new
                    path = path.replan(H, s0)
                    j0 = j - 1
                    s0, s1 = 0.0, 1.0 / (k - j0)
                    J = jacobian(model, q)
                else:  # damped
                    damping = "auto"
                    ev["action"] = "damped"
                    events.append(ev)
            if opt.origin_step or opt.split_substep_deg2 is not None:
                dq, sol, m_disp = _disp_1977_increment(model, q, H, J, path, s0, s1, L,
                                                       damping, opt)
                substeps += m_disp - 1
                refine_now = None
            else:
                dq, sol = _increment(model, q, H, J, path, s0, s1, L, damping, opt)
                refine_now = refine
            if damping is not None:
                events[-1]["damping"] = float(sol.damping)
            if model.n != 6 and sol.residual > 1e-9:
                events.append({"step": gstep, "stage": si + 1, "kind": "least_squares",
                               "residual": float(sol.residual)})
            q_new = q + dq
            m_sub = _substeps(model, dq, L, refine_now)
            if m_sub > 1:  # refine: the same hand motion in m_sub smaller first-order steps
                q_new = q
                H_sub = H
                for i in range(m_sub):
                    a = s0 + (s1 - s0) * i / m_sub
                    b = s0 + (s1 - s0) * (i + 1) / m_sub
                    J_sub = J if i == 0 else jacobian(model, q_new)
                    dq_i, _ = _increment(model, q_new, H_sub, J_sub, path, a, b, L, damping,
                                         opt)
                    q_new = q_new + dq_i
                    H_sub = fk(model, q_new)
                substeps += m_sub - 1
            ideal = path.pose_at(s1)
            if opt.closed_loop:
                q_new, ok, dp, da, iters = _newton(model, q_new, ideal, L, opt, pris)
                if not ok:
                    events.append({"step": gstep, "stage": si + 1, "kind": "not_converged",
                                   "position_error": dp, "angle_error_deg": math.degrees(da),
                                   "iterations": iters, "action": "stopped"})
                    stop_kind = "not_converged"
                    stop_msg = (f"step {gstep}: the closed-loop correction did not reach the "
                                f"path (error {dp:.3g} {model.length_unit}, "
                                f"{math.degrees(da):.3g} deg after {iters} iterations): "
                                "the path leaves the workspace or crosses a singularity")
                    break
            if opt.check_limits and (v := limit_violation(model, q_new)) is not None:
                stop_kind, stop_msg = _limit_event(model, v, q_new, gstep, si, events)
                break
            q = q_new
            H = fk(model, q)
            rows_q.append(q.copy())
            rows_T.append(H)
            rows_ideal.append(np.asarray(ideal, dtype=float))
            rows_stage.append(si)
            if progress is not None:
                progress(gstep, total_planned)
        if stop_kind is None and opt.settle:
            target = targets[-1]
            for it in range(opt.max_settle + 1):
                ok, dp, da = _error_small(H, target, opt.settle_tol, L)
                if ok:
                    break
                if it == opt.max_settle:
                    events.append({"step": gstep, "stage": si + 1, "kind": "target_not_reached",
                                   "position_error": dp, "angle_error_deg": math.degrees(da),
                                   "action": "stopped"})
                    stop_kind = "target_not_reached"
                    stop_msg = (f"stage {si + 1}: the target was not reached (error {dp:.3g} "
                                f"{model.length_unit}, {math.degrees(da):.3g} deg after "
                                f"{opt.max_settle} correction steps): it is out of reach or "
                                "beyond a singularity")
                    break
                gstep += 1
                damping = "auto" if opt.singular == "damped" else None
                sol = solve_step(jacobian(model, q), twist_between(H, target), prismatic=pris,
                                 length=L, damping=damping, cond_limit=opt.cond_limit,
                                 max_damping=opt.max_damping)
                q_new = q + sol.dq
                events.append({"step": gstep, "stage": si + 1, "kind": "settle",
                               "position_error": dp, "angle_error_deg": math.degrees(da)})
                if opt.check_limits and (v := limit_violation(model, q_new)) is not None:
                    stop_kind, stop_msg = _limit_event(model, v, q_new, gstep, si, events)
                    break
                q = q_new
                H = fk(model, q)
                rows_q.append(q.copy())
                rows_T.append(H)
                rows_ideal.append(target)
                rows_stage.append(si)
        if stop_kind in ("singular", "not_converged"):
            dp, _ = pose_error(H, targets[-1])
            if dp > 1e-6 * max(1.0, L):
                stop_msg += (f"; the hand is still {float(dp):.4g} {model.length_unit} from "
                             f"the target of stage {si + 1}, which may be out of reach")
        if stop_kind is not None:
            break

    return GuidanceResult(
        model=model, q=np.array(rows_q), poses=np.array(rows_T), ideal=np.array(rows_ideal),
        stage=np.array(rows_stage), stage_targets=tuple(targets), steps=tuple(planned),
        events=tuple(events), length=L, stopped=stop_kind is not None, stop_kind=stop_kind,
        stop_message=stop_msg, notes=tuple(notes), substeps=substeps)


def _limit_event(model, v, q_new, gstep: int, si: int, events: list) -> tuple[str, str]:
    i, side, lim, _ = v
    dv = float(joint_display(model, np.where(np.arange(model.n) == i, lim, 0.0))[i])
    events.append({"step": gstep, "stage": si + 1, "kind": "joint_limit", "joint": i + 1,
                   "limit": side, "limit_value": dv,
                   "value": float(joint_display(model, q_new)[i]), "unit": _unit(model, i),
                   "action": "stopped"})
    return "joint_limit", (f"joint {i + 1} would pass its {side} limit ({dv:.6g} "
                           f"{_unit(model, i)}) at step {gstep}: stopped with the configuration "
                           f"of step {gstep - 1}")


def _increment(model, q, H, J, path, s0, s1, L, damping, opt: GuidanceOptions):
    """First-order (or second-order) joint increments for the path from s0 to s1."""
    B = path.step_twist(s0, s1, H)
    sol = solve_step(J, B, prismatic=model.prismatic, length=L, damping=damping,
                     cond_limit=opt.cond_limit, max_damping=opt.max_damping)
    dq = sol.dq
    if opt.second_order:
        target = path.step_target(s0, s1, H)
        dq, _, _ = solve_second_order(model, q, B, target[:3, 3] - H[:3, 3], length=L,
                                      dq0=dq)
    return dq, sol


def _disp_1977_increment(model, q, H, J, path, s0, s1, L, damping, opt: GuidanceOptions):
    """The step of DISP's Illustration 5 run (docs/seed-errata.md G1): the path's step
    twist B split into m equal parts (``split_substep_deg2``), each solved to first order at
    the current joints with, for ``origin_step``, the origin point's second-order
    displacement as its translation. Returns ``(dq, last solution, m)``."""
    B = path.step_twist(s0, s1, H)
    m = 1 if opt.split_substep_deg2 is None else split_substep_count(B, opt.split_substep_deg2)
    Bi = B / m
    if opt.origin_step:
        Bi = origin_displacement_twist(Bi)
    q_i = np.array(q, dtype=float)
    sol = None
    for i in range(m):
        J_i = J if i == 0 else jacobian(model, q_i)
        sol = solve_step(J_i, Bi, prismatic=model.prismatic, length=L, damping=damping,
                         cond_limit=opt.cond_limit, max_damping=opt.max_damping)
        q_i = q_i + sol.dq
    return q_i - q, sol, m


def _substeps(model: ChainModel, dq, L: float, max_joint_step_deg: float | None) -> int:
    """Sub-steps needed so that no joint moves more than the limit (prismatic: the limit in
    radians times L)."""
    if max_joint_step_deg is None:
        return 1
    size = float(np.max(np.abs(np.where(model.prismatic, dq / L, dq))))
    return int(min(1000, max(1, math.ceil(size / math.radians(max_joint_step_deg) - 1e-9))))


def _newton(model, q, target, L, opt: GuidanceOptions, pris):
    """Newton iterations ``J δq = twist(actual → target)`` until the pose error ≤ tol."""
    damping = "auto" if opt.singular == "damped" else None
    dp = da = math.inf
    for it in range(opt.max_newton + 1):
        T = fk(model, q)
        ok, dp, da = _error_small(T, target, opt.tol, L)
        if ok:
            return q, True, dp, da, it
        if it == opt.max_newton:
            break
        E = twist_between(T, target)
        sol = solve_step(jacobian(model, q), E, prismatic=pris, length=L, damping=damping,
                         cond_limit=opt.cond_limit, max_damping=opt.max_damping)
        q = q + sol.dq
    return q, False, dp, da, opt.max_newton
