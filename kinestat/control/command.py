"""What a task commands: the end-effector :class:`Target`, the cycle's :class:`Command`,
the :class:`Refusal` that stops a run, and :func:`move_command`, the one path from a target to
checked axis counts that every task and procedure shares (the closed-form reverse analysis,
Vibhute App. C, the vernier and the envelope's check)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from kinestat.control.envelope import AXIS_STEP_VIOLATION, check_command
from kinestat.control.model import ControlModel
from kinestat.control.predict import Prediction, predict
from kinestat.control.tuning import TUNING, Tuning
from kinestat.control.vernier import axis_counts_to_q, q_to_axis_counts, vernier_search
from kinestat.errors import JointLimitError, UnreachableError

__all__ = ["CommandKind", "Action", "Target", "Command", "Refusal", "solve_counts",
           "move_command"]

CommandKind = Literal["move", "measure", "done", "stop"]
"""What a :class:`Command` asks for: send axis counts, measure again without moving (the
thesis's procedure, :mod:`kinestat.control.procedure`), report the goal, or stop safely."""
Action = Literal["start", "approach", "align", "shed", "force", "measure", "reorient", "translate",
                 ""]
"""Why a move is made (Vibhute Fig. 5-2 steps; "measure", "reorient", "translate" are the steps
of ForceCorrection.m as written); "" for done/stop."""


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
        accel_limit: 1/s², the move's largest acceleration per unit of travel (each axis
            accelerates at most this times its own travel: :func:`kinestat.devices.motion.
            limit_accel`), set where the top + tool's inertia must not load the contact
            (the follow task on a massive top); None: the move rule's own.
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
    accel_limit: float | None = None


# -- joint-space helpers: kinestat.control.vernier --------------------------------------------
def solve_counts(model: ControlModel, target: Target, q_now, counts_now,
                 vernier: bool, tuning: Tuning = TUNING) -> tuple[np.ndarray, float]:
    """Reverse analysis, selection within limits, rounding to counts (with the vernier).

    Returns (counts, residual along S6 in mm of the chosen counts). Raises UnreachableError or
    JointLimitError. The vernier searches the count vectors next to the rounded ones
    (:func:`kinestat.control.vernier.vernier_search`)."""
    axis = model.arm.solve_axis(target.tool_point, target.s6, target.a67, model.tool_point_6,
                                np.asarray(q_now, dtype=float), model.limits_deg)
    return vernier_search(model, target, q_to_axis_counts(model, axis), counts_now, vernier,
                          tuning)


@dataclass(frozen=True)
class Refusal:
    """Why a move was not commanded: ``reason`` and the extra fields of the stop command."""

    reason: str
    extra: dict


def move_command(model: ControlModel, envelope, vernier: bool, meas, new: Target,
                 counts_now, *, label: str, action: str, step: float, rotation_deg: float,
                 info: dict, tuning: Tuning = TUNING) -> Command | Refusal:
    """The move onto target ``new``: its axis counts by the closed form (Vibhute App. C, with
    the vernier when asked), checked against the envelope's joint limits, per-command step and
    predicted platform state (:func:`~kinestat.control.envelope.check_command`); or the
    :class:`Refusal` that stops the run. One path for every task and procedure."""
    try:
        counts, _ = solve_counts(model, new, meas.q, counts_now, vernier, tuning)
    except (UnreachableError, JointLimitError) as exc:
        return Refusal(f"{action} target not reachable: {exc}", {})
    q_new = axis_counts_to_q(model, counts)
    T_new = model.arm.flange_pose(q_new)
    axis_deg = counts * model.axis_deg_per_count
    pred = predict(model, meas, T_new)
    bad = check_command(envelope, model, axis_deg, counts_now * model.axis_deg_per_count, pred)
    if bad:
        jump = float(np.max(np.abs(axis_deg - counts_now * model.axis_deg_per_count)))
        hint = (_branch_change_hint() if jump > tuning.branch_change_deg
                and any(AXIS_STEP_VIOLATION in b for b in bad) else "")
        return Refusal(f"{action} command refused by the envelope: " + "; ".join(bad) + hint,
                       {"violations": tuple(bad), "prediction": pred})
    return Command(kind="move", label=label, action=action, target=new, axis_counts=counts,
                   axis_deg=axis_deg, q=q_new, step=step, rotation_deg=rotation_deg,
                   prediction=pred, **info)


def _branch_change_hint() -> str:
    """Said when an axis would move more than the tuning's ``branch_change_deg`` in one
    command for a small move of the tool."""
    return (" (the nearest solution within the axis limits is far from the present pose: a "
            "change of the arm's inverse-kinematics branch, such as a wrist flip where the "
            "continuous one leaves the limits, or a pass near a singular wrist; the arm is at "
            "the edge of its workspace here: choose another --start or --direction)")
