"""The kinestatic controller: pure decision logic, no I/O (Vibhute 2011 ch. 4, App. D.1).

The press's start and its one decision per cycle; its settings and memory are in
:mod:`kinestat.control.config`, the command and the move path every task shares
(:func:`~kinestat.control.command.move_command`) in :mod:`kinestat.control.command`, the rules
of the turn and the step in :mod:`kinestat.control.align`, the counts in
:mod:`kinestat.control.vernier`, the predictions in :mod:`kinestat.control.predict`, the checks
in :mod:`kinestat.control.envelope` and the tuning in :mod:`kinestat.control.tuning`. The task
protocol runs it as :class:`~kinestat.control.press_task.PressTask`.

One call per cycle, :func:`decide`, takes the controller's state and the cycle's
:class:`~kinestat.control.wrench.Measurement` and returns the next :class:`Command` and the new
state. The procedure is the thesis's ForceCorrection.m:

1. move to the commanded pose (closed-form reverse analysis of the PUMA 762 and the solution
   nearest the current configuration within the axis limits) — :func:`start`;
2. measure the equivalent wrench ``W_eq`` (:mod:`kinestat.control.wrench`);
3. align S6 with the wrench's force while keeping the tool point ``P_tool_F`` (the unloaded
   tool point; this cancels the torque about it), then move along S6 until the force
   magnitude is within ``force_tol`` of ``|F_req|``.

Each cycle is labelled with the states of Vibhute's Figure 5-2:

* ``a`` — platform at rest, unloaded (no contact force measured): approach along S6;
* ``b`` — the tool has hit the workpiece: first loaded measurement after an approach;
* ``c`` — measured after the robot reoriented the tool along the equivalent wrench;
* ``d`` — measured while the force magnitude is being controlled;
* ``e`` — goal attained: force within tolerance and S6 along the force.

Step along S6 (``method``): ``"fixed"`` is the thesis's 1 mm step with the sign of the force
error (``step``); ``"stiffness"`` is a Newton step ``δ = (|F_req| − |F|) / k_axial`` with
``k_axial = s6ᵀ K_tip s6`` the platform's point stiffness at the tip along S6
(:func:`kinestat.control.predict.tip_stiffness`), clipped to ``step``.

The commanded axis angles are rounded to whole encoder counts of the robot. With ``vernier``
the controller picks, among the count vectors next to the ideal one (±4 counts on axes 1..3,
±1 on axes 4..5), the one whose tool point (forward analysis, including the axis-5 rounding
left by the axis 4 → 5 compensation) lies nearest the target along S6, with small lateral and
angular deviations — the robot's counts are ~0.02 mm at the tool, which is 0.2 N of force on
this platform; the search resolves the target to ~0.1 µm.

When S6 is misaligned AND the force is out of tolerance, the reorientation and the step along
the new axis are commanded together (at light contact the measured direction is noisy; pushing
towards the target force makes it precise).

The move in contact is :func:`kinestat.control.align.contact_move`: the turn is at most
the tuning's ``max_align_turn_deg`` a cycle and a large one is made before pushing along the
new axis; a turn that overshot the force makes the next ones a fraction of the misalignment (on a
frictionless curved surface the free tip slides as S6 turns, and the whole turn lands past the
new normal); and where a stuck tip carries the turns, the force is shed across S6 instead.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np

from kinestat.control.align import (
    align_progress,
    align_stall_reason,
    align_stalled,
    contact_move,
)
from kinestat.control.approach import approach_waypoints, check_approach
from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.control.command import (
    Action,
    Command,
    CommandKind,
    Refusal,
    Target,
    move_command,
    solve_counts,
)
from kinestat.control.config import (
    ESTIMATORS,
    METHODS,
    PROCEDURES,
    STATES,
    THESIS_FORCE_DIRECTION,
    ControllerConfig,
    ControllerState,
    Procedure,
    StepMethod,
    default_a67,
)
from kinestat.control.envelope import AXIS_STEP_VIOLATION, check_measurement, check_target
from kinestat.control.vernier import axis_counts_to_q, q_to_axis_counts
from kinestat.control.wrench import Measurement
from kinestat.errors import InputError, JointLimitError, UnreachableError

__all__ = [
    "THESIS_FORCE_DIRECTION",
    "STATES",
    "METHODS",
    "MAX_ITERATIONS",
    "Target",
    "ControllerConfig",
    "ControllerState",
    "Command",
    "StepMethod",
    "Procedure",
    "PROCEDURES",
    "CommandKind",
    "Action",
    "start",
    "decide",
    "default_a67",
    "axis_counts_to_q",
    "move_command",
    "Refusal",
    "ESTIMATORS",
]

_solve_counts = solve_counts  # the older name

def approach_refusal(config: ControllerConfig, tool_point) -> str:
    """Why an approach without contact to ``tool_point`` is refused ("" when it is not): it
    would carry the tool point more than ``config.max_approach`` from the start tool point, so
    the workpiece is not where the request put it (or the sensor does not see the contact).

    >>> cfg = ControllerConfig(model=None, force=[4.0, 0.0, 0.0], start_tool_point=[0, 0, 0],
    ...                        max_approach=10.0)
    >>> approach_refusal(cfg, [9.5, 0.0, 0.0])
    ''
    >>> approach_refusal(cfg, [10.5, 0.0, 0.0])[:62]
    'no contact: the approach would carry the tool point 10.50 mm f'
    """
    far = float(np.linalg.norm(np.asarray(tool_point, dtype=float) - config.start_tool_point))
    if far <= config.max_approach:
        return ""
    return (f"no contact: the approach would carry the tool point {far:.2f} mm from the start "
            f"tool point, beyond max_approach = {config.max_approach:g} mm; is the workpiece "
            "ahead of the tool along F_req?")


# -- the procedure ---------------------------------------------------------------------------------
def start(config: ControllerConfig, q_now, *, counts_now=None) -> tuple[Command, ControllerState]:
    """Step 1: the command that takes the robot to the start pose, and the initial state.

    ``q_now`` are the robot's current joint angles (radians); ``counts_now`` its current axis
    counts (default: computed from ``q_now``). The target force is checked against the envelope
    first; a violation yields a "stop" command and nothing moves.
    """
    model = config.model
    q_now = np.asarray(q_now, dtype=float)
    if counts_now is None:
        counts_now = q_to_axis_counts(model, model.arm.axis_from_q(q_now))
    counts_now = np.asarray(counts_now, dtype=np.int64)
    target = Target(config.start_tool_point, config.start_s6, config.start_a67)
    state = ControllerState(cycle=0, label="", last_action="start", target=target,
                            axis_counts=counts_now, top_pose=model.platform.home_pose.copy())
    bad = check_target(config.envelope, config.force)
    if bad:
        return (Command(kind="stop", label="", reason="; ".join(bad), violations=tuple(bad)),
                replace(state, done=True))
    try:
        counts, _ = solve_counts(model, target, q_now, counts_now, config.vernier,
                                 config.tuning)
    except (UnreachableError, JointLimitError) as exc:
        msg = f"the start pose cannot be commanded: {exc}"
        return Command(kind="stop", label="", reason=msg), replace(state, done=True)
    axis_deg = counts * model.axis_deg_per_count
    # a long move goes as a sequence of commands, each within the per-command step
    wps = approach_waypoints(config.envelope, model, counts_now, counts, config.tuning)
    bad = check_approach(config.envelope, model, counts_now, wps)
    if bad:
        return (Command(kind="stop", label="", reason="start move: " + "; ".join(bad),
                        violations=tuple(bad)), replace(state, done=True))
    cmd = Command(kind="move", label="", action="start", target=target, axis_counts=counts,
                  axis_deg=axis_deg, q=axis_counts_to_q(model, counts),
                  waypoints=tuple(wps[:-1]))
    return cmd, replace(state, axis_counts=counts, history=(target.key(),))


def _stop(state: ControllerState, label: str, reason: str, **kw) -> tuple[Command, ControllerState]:
    return Command(kind="stop", label=label, reason=reason, **kw), replace(state, done=True)


def contact_at_start(force_magnitude: float) -> str:
    """The stop reason for a contact force measured right after the start move, before any
    approach step. Every procedure starts out of contact (Vibhute Fig. 5-2, state a: the
    platform at rest, unloaded) and approaches along S6; a force there means the tool already
    touches something, or the leg calibration does not match the platform (the design springs'
    map on the 2011 prototype reads 0.70 N at rest), and aligning on it would turn the tool
    about a force no contact exerts.

    >>> contact_at_start(0.7013)[:60]
    'a force of 0.701 N is measured at the start pose, before any'
    """
    return (f"a force of {force_magnitude:.3g} N is measured at the start pose, before any "
            "approach: the tool already touches something, or the leg calibration does not "
            "match the platform (--calibration); the procedure starts out of contact")


def _contact_command(config: ControllerConfig, state: ControllerState, meas, F, mis, err,
                     label: str, info: dict):
    """The move of a cycle in contact (:func:`~kinestat.control.align.contact_move`) and its
    command: ``(command or Refusal, target, action, step, rotation, memo)``. An align turn
    refused because an axis would move more than its per-command step is made smaller, half
    the turn at a time, up to the tuning's ``turn_retries`` times (a wrist near its singular
    pose: a 20° turn of S6 swung axis 4 by 30–42°)."""
    cap, retries = config.tuning.max_align_turn_deg, config.tuning.turn_retries
    for attempt in range(retries + 1):
        action, (point, axis, a67), step, rotation, memo = contact_move(
            config, state, meas, F, mis, err, max_turn_deg=cap)
        new = Target(point, axis, a67)
        cmd = move_command(config.model, config.envelope, config.vernier, meas, new,
                           state.axis_counts, label=label, action=action, step=step,
                           rotation_deg=rotation, info=info, tuning=config.tuning)
        refused_step = (isinstance(cmd, Refusal) and action == "align"
                        and any(AXIS_STEP_VIOLATION in v
                                for v in cmd.extra.get("violations", ())))
        if not refused_step or attempt == retries:
            return cmd, new, action, step, rotation, memo
        cap = 0.5 * rotation
    raise AssertionError("unreachable")


def decide(config: ControllerConfig, state: ControllerState,
           meas: Measurement) -> tuple[Command, ControllerState]:
    """One cycle of the kinestatic procedure: the next command and the new state.

    Pure: the same inputs give the same outputs. Envelope violations (measured or predicted),
    an unreachable target, a limit cycle or too many cycles give a "stop" command.
    """
    if state.done:
        raise InputError("decide: the run is over (state.done); start a new one")
    c = _reading(config, state, meas)
    ended = _ended(config, state, meas, c)
    if ended is not None:
        return ended
    best, stall = state.align_best_deg, state.align_stall
    if c.contact:  # the align turns' progress
        best, stall = align_progress(best, stall, c.mis, config.align_tol_deg, config.tuning)
        if config.method == "stiffness" and align_stalled(stall, state.align_gain,
                                                          config.tuning):
            return _stop(c.st(label=c.label, align_best_deg=best, align_stall=stall), c.label,
                         align_stall_reason(stall, best, c.mis, config.tuning)
                         + f" (|F| = {c.fmag:.4g} N, error {c.err:+.4g} N)", **c.info)
    return _move(config, state, meas, c, {"align_best_deg": best, "align_stall": stall})


@dataclass(frozen=True)
class _Reading:
    """What :func:`decide` reads off one measurement."""

    st: functools.partial  # st(**changes): the new state (one replace per cycle)
    cycle: int
    force: np.ndarray
    fmag: float
    contact: bool
    err: float
    mis: float | None
    label: str
    info: dict


def _reading(config: ControllerConfig, state: ControllerState, meas: Measurement) -> _Reading:
    """The cycle's force, its error and misalignment, and its state a-d (Vibhute Fig. 5-2)."""
    cycle = state.cycle + 1
    F = meas.estimate(config.estimator)
    Fmag = np.linalg.norm(F)
    contact = Fmag >= config.contact_force
    err = config.force_target - Fmag
    s6 = state.target.s6
    mis = math.degrees(math.acos(max(-1.0, min(1.0, float(F @ s6) / Fmag)))) if contact else None
    if not contact:
        label = "a"
    elif state.last_action in ("start", "approach"):
        label = "b"
    elif state.last_action == "align":
        label = "c"
    else:
        label = "d"
    st = functools.partial(replace, state, cycle=cycle, top_pose=meas.top_pose)
    return _Reading(st, cycle, F, Fmag, contact, err, mis, label,
                    {"force_error": err, "misalignment_deg": mis})


def _ended(config: ControllerConfig, state: ControllerState, meas: Measurement,
           c: _Reading) -> tuple[Command, ControllerState] | None:
    """The cycle's stop or goal, before any move is planned (None: go on)."""
    label, info = c.label, c.info
    bad = check_measurement(config.envelope, config.model, meas)
    if bad:
        return _stop(c.st(label=label), label, "measurement outside the envelope: "
                     + "; ".join(bad), violations=tuple(bad), **info)
    if c.contact and state.last_action == "start":
        return _stop(c.st(label=label), label, contact_at_start(c.fmag), **info)
    if c.contact and abs(c.err) <= config.force_tol and c.mis <= config.align_tol_deg:
        return (Command(kind="done", label="e", reason="goal attained", **info),
                c.st(label="e", done=True))
    if c.cycle >= config.max_iterations:
        return _stop(c.st(label=label), label,
                     f"not converged after {c.cycle} cycles (|F| = {c.fmag:.4g} N, error "
                     f"{c.err:+.4g} N" + (f", misalignment {c.mis:.3g}°)" if c.mis is not None
                                          else ")"), **info)
    return None


def _move(config: ControllerConfig, state: ControllerState, meas: Measurement, c: _Reading,
          memo: dict) -> tuple[Command, ControllerState]:
    """The cycle's move: the approach step out of contact, the contact move in it; stopped on
    a limit cycle or a refusal."""
    label, info, tgt = c.label, c.info, state.target
    if not c.contact:
        action, step, rotation = "approach", config.approach, 0.0
        new = Target(tgt.tool_point + step * tgt.s6, tgt.s6, tgt.a67)
        refused = approach_refusal(config, new.tool_point)
        if refused:
            return _stop(c.st(label=label), label, refused, **info)
        cmd = move_command(config.model, config.envelope, config.vernier, meas, new,
                           state.axis_counts, label=label, action=action, step=step,
                           rotation_deg=rotation, info=info, tuning=config.tuning)
    else:
        cmd, new, action, step, rotation, move_memo = _contact_command(
            config, state, meas, c.force, c.mis, c.err, label, info)
        memo.update(move_memo)
    key = new.key()
    if state.history.count(key) + 1 >= config.repeat_limit:
        return _stop(c.st(label=label), label,
                     f"limit cycle: the same target has now been commanded {config.repeat_limit} "
                     f"times without reaching the goal (|F| = {c.fmag:.4g} N, error "
                     f"{c.err:+.4g} N)"
                     + (f"; the fixed {config.step:g} mm step is too coarse for this stiffness "
                        "— use method 'stiffness' or a smaller step"
                        if config.method == "fixed" else ""), **info)
    if isinstance(cmd, Refusal):
        return _stop(c.st(label=label), label, cmd.reason, **cmd.extra, **info)
    return cmd, c.st(label=label, last_action=action, target=new,
                     axis_counts=cmd.axis_counts, history=state.history + (key,), **memo)
