"""The thesis's own procedure: ForceCorrection.m's steps as written (Vibhute 2011 App. D.1).

:func:`decide_thesis` is the pure decision of one cycle of ``kinestat control --procedure
thesis``; the loop (:mod:`kinestat.control.loop`) runs it in place of
:func:`kinestat.control.controller.decide`. The steps:

1. go to the start pose by the reverse analysis (:func:`~kinestat.control.controller.start`,
   shared with the improved procedure);
2. measure the legs and the equivalent wrench ``W_eq`` (eq_wrench.m) — the first cycle only
   measures (action ``measure``; ForceCorrection.m acquires the legs again before step 4, so
   the next cycle measures afresh);
3. if S6 is not on the wrench (angle above ``align_tol_deg``): ONE pure reorientation — S6
   onto ``W_eq``'s force, about the commanded tool point ``P_tool_F`` (unchanged), with
   ``P_tool_6`` reset to its unloaded coordinates (the model's ``tool_point_6``) and a67 the
   step-1 a67 made perpendicular to the new S6 (action ``reorient``);
4. then translation-only steps along S6 of exactly ``step`` (1 mm default), towards more force
   when ``|F| < |F_req|`` and away otherwise (``P_tool_F + S6 · step · sign(f_mag_err)``),
   until ``| |F_req| − |F| | ≤ force_tol`` (``done``). The robot's S6 and a67 are not changed
   again.

The force is always ``W_eq``'s (the thesis has no point-contact estimate). Differences from
the MATLAB, each forced by a gap in it:

* before the tool touches (|W_eq| below ``contact_force``) the wrench has no direction, so the
  reorientation waits for the first loaded measurement; until then the same translation
  steps (towards more force) approach the workpiece;
* the translation adds the step to the COMMANDED tool point; the MATLAB re-reads it from the
  forward analysis of the robot's encoders, which agrees to the encoders' resolution — using
  the command keeps that rounding from accumulating over the steps;
* "cannot settle": a translation target commanded before means the fixed step jumps across
  the tolerance band (|F| alternates above and below it) — the MATLAB would loop forever; the
  run stops and says so. Likewise after ``max_iterations`` cycles, and when the steps
  without contact would carry the tool point beyond ``max_approach`` from the start.

Every command passes the same envelope checks as the improved procedure.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from kinestat.control.controller import (
    Command,
    ControllerConfig,
    ControllerState,
    Refusal,
    Target,
    _stop,
    approach_refusal,
    contact_at_start,
    move_command,
)
from kinestat.control.envelope import check_measurement
from kinestat.control.wrench import Measurement
from kinestat.errors import InputError

__all__ = ["decide_thesis"]


def _label(state: ControllerState, contact: bool) -> str:
    if not contact:
        return "a"
    if state.last_action == "reorient":
        return "c"
    return "d" if state.reoriented else "b"


def _reoriented_target(config: ControllerConfig, tgt: Target, s6_new: np.ndarray) -> Target:
    """The pure reorientation: same tool point, S6 along the force, a67 the step-1 a67 made
    perpendicular to the new S6 (ForceCorrection.m keeps a67_F of step 1)."""
    a67 = config.start_a67 - (config.start_a67 @ s6_new) * s6_new
    if np.linalg.norm(a67) < 1e-6:  # the force is along the old a67: keep the current one's
        a67 = tgt.a67 - (tgt.a67 @ s6_new) * s6_new
    return Target(tgt.tool_point.copy(), s6_new, a67 / np.linalg.norm(a67))


def decide_thesis(config: ControllerConfig, state: ControllerState,
                  meas: Measurement) -> tuple[Command, ControllerState]:
    """One cycle of ForceCorrection.m (see the module docstring): pure, like
    :func:`~kinestat.control.controller.decide`."""
    if state.done:
        raise InputError("decide_thesis: the run is over (state.done); start a new one")
    model = config.model
    cycle = state.cycle + 1
    st = replace(state, cycle=cycle, top_pose=meas.top_pose)
    F = meas.wrench[:3]
    Fmag = float(np.linalg.norm(F))
    contact = Fmag >= config.contact_force
    err = config.force_target - Fmag
    tgt = state.target
    mis = (math.degrees(math.acos(max(-1.0, min(1.0, float(F @ tgt.s6) / Fmag))))
           if contact else None)
    label = _label(state, contact)
    info = {"force_error": err, "misalignment_deg": mis}
    bad = check_measurement(config.envelope, model, meas)
    if bad:
        return _stop(replace(st, label=label), label, "measurement outside the envelope: "
                     + "; ".join(bad), violations=tuple(bad), **info)
    if contact and state.last_action == "start":
        return _stop(replace(st, label=label), label, contact_at_start(Fmag), **info)
    if state.last_action == "start":  # step 2: measure W_eq; step 4 measures afresh
        return (Command(kind="measure", label=label, action="measure", **info),
                replace(st, label=label, last_action="measure"))
    reorient = contact and not state.reoriented and mis > config.align_tol_deg
    if not reorient and abs(err) <= config.force_tol:
        return (Command(kind="done", label="e", reason="goal attained: |F| within f_tol "
                        "(ForceCorrection.m)", **info), replace(st, label="e", done=True))
    if cycle >= config.max_iterations:
        return _stop(replace(st, label=label), label,
                     f"cannot settle: not within f_tol after {cycle} cycles (|F| = {Fmag:.4g} N,"
                     f" error {err:+.4g} N)", **info)
    if reorient:
        action, step, new = "reorient", 0.0, _reoriented_target(config, tgt, F / Fmag)
    else:
        action, step = "translate", math.copysign(config.step, err)
        new = Target(tgt.tool_point + step * tgt.s6, tgt.s6, tgt.a67)
        refused = "" if contact else approach_refusal(config, new.tool_point)
        if refused:
            return _stop(replace(st, label=label), label, refused, **info)
    key = new.key()
    if action == "translate" and key in state.history:
        return _stop(replace(st, label=label), label,
                     f"cannot settle: the fixed {config.step:g} mm step jumps across the "
                     f"±{config.force_tol:g} N band (|F| = {Fmag:.4g} N, error {err:+.4g} N; "
                     "this target was commanded before)", **info)
    return _move(config, state, st, label, action, new, meas, step,
                 mis if reorient else 0.0, contact, info)


def _move(config, state, st, label, action, new, meas, step, rotation, contact, info):
    """Command ``new`` through the shared move path (or stop)."""
    cmd = move_command(config.model, config.envelope, config.vernier, meas, new,
                       state.axis_counts, label=label, action=action, step=step,
                       rotation_deg=rotation, info=info)
    if isinstance(cmd, Refusal):
        return _stop(replace(st, label=label), label, cmd.reason, **cmd.extra, **info)
    reoriented = state.reoriented or action == "reorient" or contact
    return cmd, replace(st, label=label, last_action=action, target=new,
                        axis_counts=cmd.axis_counts, history=state.history + (new.key(),),
                        reoriented=reoriented)
