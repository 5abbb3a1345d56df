"""The kinestatic controller: pure decision logic, no I/O (Vibhute 2011 ch. 4, App. D.1).

Over 600 lines on purpose: the procedure's types (configuration, state, command), its one
decision per cycle and the move path every task and procedure shares (:func:`move_command`)
are one unit; the rules of the turn and the step live in :mod:`kinestat.control.align`, the
counts in :mod:`kinestat.control.vernier`, the predictions in :mod:`kinestat.control.predict`
and the checks in :mod:`kinestat.control.envelope`.

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
``MAX_ALIGN_TURN_DEG`` a cycle and a large one is made before pushing along the new axis; a
turn that overshot the force makes the next ones a fraction of the misalignment (on a
frictionless curved surface the free tip slides as S6 turns, and the whole turn lands past the
new normal); and where a stuck tip carries the turns, the force is shed across S6 instead.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace
from typing import Literal, get_args

import numpy as np

from kinestat.control.align import (
    MAX_ALIGN_TURN_DEG,
    TURN_RETRIES,
    align_progress,
    align_stall_reason,
    align_stalled,
    contact_move,
)
from kinestat.control.approach import approach_waypoints, check_approach
from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.control.envelope import (
    AXIS_STEP_VIOLATION,
    Envelope,
    check_command,
    check_measurement,
    check_target,
)
from kinestat.control.model import ControlModel
from kinestat.control.predict import Prediction, predict
from kinestat.control.vernier import (
    axis_counts_to_q,
    q_to_axis_counts,
    vernier_search,
)
from kinestat.control.wrench import Estimator, Measurement
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
]

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
CommandKind = Literal["move", "measure", "done", "stop"]
"""What a :class:`Command` asks for: send axis counts, measure again without moving (the
thesis's procedure, :mod:`kinestat.control.procedure`), report the goal, or stop safely."""
Action = Literal["start", "approach", "align", "shed", "force", "measure", "reorient", "translate",
                 ""]
"""Why a move is made (Vibhute Fig. 5-2 steps; "measure", "reorient", "translate" are the steps
of ForceCorrection.m as written); "" for done/stop."""
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
class Target:
    """The end effector as the thesis commands it: tool point, S6 and a67 (fixed frame)."""

    tool_point: np.ndarray
    s6: np.ndarray
    a67: np.ndarray

    def key(self) -> tuple:
        """Hashable rounding (1 nm, 1e-9) used to spot a repeated target (a limit cycle):
        the nearest integers, ties to even (as ``numpy.round``)."""
        v = ([x * 1e6 for x in self.tool_point.tolist()] + [x * 1e9 for x in self.s6.tolist()]
             + [x * 1e9 for x in self.a67.tolist()])
        if all(map(math.isfinite, v)):
            return tuple(int(round(x)) for x in v)
        return tuple(np.round(np.asarray(v)).astype(np.int64).tolist())  # NaN: as NumPy casts it




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
            below ``ALIGN_PROGRESS`` of the previous value.
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


@dataclass(frozen=True, eq=False)
class Command:
    """The controller's decision for one cycle.

    Attributes:
        kind: "move" (send ``axis_counts``), "done" (goal reached) or "stop" (safe stop).
        label: the cycle's state a–e ("" for the start move).
        action: "start", "approach", "align", "force" or "" (done/stop).
        reason: why (always set for "stop").
        target: the commanded end effector (moves only).
        axis_counts: (6,) absolute axis positions in robot encoder counts (moves only).
        axis_deg: (6,) the same in degrees; q: (6,) joint angles (radians).
        step: signed step along S6 (mm) for approach/force moves.
        rotation_deg: reorientation angle for align moves.
        force_error: |F_req| − |F| (N); misalignment_deg: angle(S6, F).
        prediction: predicted force and deflections after the move.
        violations: envelope violations that caused a stop.
        info: task-specific figures of the cycle for the report's ``cycles`` (the follow
            task's phase, measured tip, normal estimate, normal force, travel); empty for the
            press task.
        waypoints: for the start move, the intermediate axis counts commanded before
            ``axis_counts`` (:func:`kinestat.control.approach.approach_waypoints`).
    """

    kind: CommandKind
    label: str
    action: Action = ""
    reason: str = ""
    target: Target | None = None
    axis_counts: np.ndarray | None = None
    axis_deg: np.ndarray | None = None
    q: np.ndarray | None = None
    step: float = 0.0
    rotation_deg: float = 0.0
    force_error: float | None = None
    misalignment_deg: float | None = None
    prediction: Prediction | None = None
    violations: tuple[str, ...] = ()
    info: dict = field(default_factory=dict)
    waypoints: tuple[np.ndarray, ...] = ()


# -- joint-space helpers: kinestat.control.vernier --------------------------------------------
def _solve_counts(model: ControlModel, target: Target, q_now, counts_now,
                  vernier: bool) -> tuple[np.ndarray, float]:
    """Reverse analysis, selection within limits, rounding to counts (with the vernier).

    Returns (counts, residual along S6 in mm of the chosen counts). Raises UnreachableError or
    JointLimitError. The vernier searches the count vectors next to the rounded ones
    (:func:`kinestat.control.vernier.vernier_search`)."""
    axis = model.arm.solve_axis(target.tool_point, target.s6, target.a67, model.tool_point_6,
                                np.asarray(q_now, dtype=float), model.limits_deg)
    return vernier_search(model, target, q_to_axis_counts(model, axis), counts_now, vernier)


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
        counts, _ = _solve_counts(model, target, q_now, counts_now, config.vernier)
    except (UnreachableError, JointLimitError) as exc:
        msg = f"the start pose cannot be commanded: {exc}"
        return Command(kind="stop", label="", reason=msg), replace(state, done=True)
    axis_deg = counts * model.axis_deg_per_count
    # a long move goes as a sequence of commands, each within the per-command step
    wps = approach_waypoints(config.envelope, model, counts_now, counts)
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


@dataclass(frozen=True)
class Refusal:
    """Why a move was not commanded: ``reason`` and the extra fields of the stop command."""

    reason: str
    extra: dict


def move_command(model: ControlModel, envelope, vernier: bool, meas, new: Target,
                 counts_now, *, label: str, action: str, step: float, rotation_deg: float,
                 info: dict) -> Command | Refusal:
    """The move onto target ``new``: its axis counts by the closed form (Vibhute App. C, with
    the vernier when asked), checked against the envelope's joint limits, per-command step and
    predicted platform state (:func:`~kinestat.control.envelope.check_command`); or the
    :class:`Refusal` that stops the run. One path for every task and procedure."""
    try:
        counts, _ = _solve_counts(model, new, meas.q, counts_now, vernier)
    except (UnreachableError, JointLimitError) as exc:
        return Refusal(f"{action} target not reachable: {exc}", {})
    q_new = axis_counts_to_q(model, counts)
    T_new = model.arm.flange_pose(q_new)
    axis_deg = counts * model.axis_deg_per_count
    pred = predict(model, meas, T_new)
    bad = check_command(envelope, model, axis_deg, counts_now * model.axis_deg_per_count, pred)
    if bad:
        jump = float(np.max(np.abs(axis_deg - counts_now * model.axis_deg_per_count)))
        hint = (BRANCH_CHANGE_HINT if jump > BRANCH_CHANGE_DEG
                and any(AXIS_STEP_VIOLATION in b for b in bad) else "")
        return Refusal(f"{action} command refused by the envelope: " + "; ".join(bad) + hint,
                       {"violations": tuple(bad), "prediction": pred})
    return Command(kind="move", label=label, action=action, target=new, axis_counts=counts,
                   axis_deg=axis_deg, q=q_new, step=step, rotation_deg=rotation_deg,
                   prediction=pred, **info)


BRANCH_CHANGE_DEG = 90.0
"""An axis that would move more than this in one command for a small move of the tool has
changed inverse-kinematics branch (:data:`BRANCH_CHANGE_HINT`)."""
BRANCH_CHANGE_HINT = (" (the nearest solution within the axis limits is far from the present "
                      "pose: a change of the arm's inverse-kinematics branch, such as a wrist "
                      "flip where the continuous one leaves the limits, or a pass near a "
                      "singular wrist; the arm is at the edge of its workspace here: choose "
                      "another --start or --direction)")


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
    the turn at a time, up to ``TURN_RETRIES`` times (a wrist near its singular pose: a 20°
    turn of S6 swung axis 4 by 30–42°)."""
    cap = MAX_ALIGN_TURN_DEG
    for attempt in range(TURN_RETRIES + 1):
        action, (point, axis, a67), step, rotation, memo = contact_move(
            config, state, meas, F, mis, err, max_turn_deg=cap)
        new = Target(point, axis, a67)
        cmd = move_command(config.model, config.envelope, config.vernier, meas, new,
                           state.axis_counts, label=label, action=action, step=step,
                           rotation_deg=rotation, info=info)
        refused_step = (isinstance(cmd, Refusal) and action == "align"
                        and any(AXIS_STEP_VIOLATION in v
                                for v in cmd.extra.get("violations", ())))
        if not refused_step or attempt == TURN_RETRIES:
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
    model = config.model
    env = config.envelope
    cycle = state.cycle + 1

    def st(**kw) -> ControllerState:  # the new state: one replace per cycle
        return replace(state, cycle=cycle, top_pose=meas.top_pose, **kw)

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
    info = {"force_error": err, "misalignment_deg": mis}
    bad = check_measurement(env, model, meas)
    if bad:
        return _stop(st(label=label), label, "measurement outside the envelope: "
                     + "; ".join(bad), violations=tuple(bad), **info)
    if contact and state.last_action == "start":
        return _stop(st(label=label), label, contact_at_start(Fmag), **info)
    if contact and abs(err) <= config.force_tol and mis <= config.align_tol_deg:
        return (Command(kind="done", label="e", reason="goal attained", **info),
                st(label="e", done=True))
    if cycle >= config.max_iterations:
        return _stop(st(label=label), label,
                     f"not converged after {cycle} cycles (|F| = {Fmag:.4g} N, error "
                     f"{err:+.4g} N" + (f", misalignment {mis:.3g}°)" if mis is not None else ")"),
                     **info)
    best, stall = state.align_best_deg, state.align_stall
    if contact:  # the align turns' progress
        best, stall = align_progress(best, stall, mis, config.align_tol_deg)
        if config.method == "stiffness" and align_stalled(stall, state.align_gain):
            return _stop(st(label=label, align_best_deg=best, align_stall=stall), label,
                         align_stall_reason(stall, best, mis)
                         + f" (|F| = {Fmag:.4g} N, error {err:+.4g} N)", **info)
    tgt = state.target
    rotation = 0.0
    step = 0.0
    memo: dict = {"align_best_deg": best, "align_stall": stall}
    if not contact:
        action = "approach"
        step = config.approach
        new = Target(tgt.tool_point + step * tgt.s6, tgt.s6, tgt.a67)
        refused = approach_refusal(config, new.tool_point)
        if refused:
            return _stop(st(label=label), label, refused, **info)
        cmd = move_command(model, env, config.vernier, meas, new, state.axis_counts,
                           label=label, action=action, step=step, rotation_deg=rotation,
                           info=info)
    else:
        cmd, new, action, step, rotation, move_memo = _contact_command(config, state, meas, F,
                                                                       mis, err, label, info)
        memo.update(move_memo)
    key = new.key()
    if state.history.count(key) + 1 >= config.repeat_limit:
        return _stop(st(label=label), label,
                     f"limit cycle: the same target has now been commanded {config.repeat_limit} "
                     f"times without reaching the goal (|F| = {Fmag:.4g} N, error {err:+.4g} N)"
                     + (f"; the fixed {config.step:g} mm step is too coarse for this stiffness "
                        "— use method 'stiffness' or a smaller step"
                        if config.method == "fixed" else ""), **info)
    if isinstance(cmd, Refusal):
        return _stop(st(label=label), label, cmd.reason, **cmd.extra, **info)
    new_state = st(label=label, last_action=action, target=new,
                   axis_counts=cmd.axis_counts, history=state.history + (key,), **memo)
    return cmd, new_state
