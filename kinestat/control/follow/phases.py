"""The follow task's phases as a state machine, one call per cycle (:func:`decide_follow`).

``approach`` (label ``a``): along S6 until the force reaches the contact threshold (``b``);
``probe`` (``p``): touches around the first contact give the normal by a plane fit
(:mod:`kinestat.control.probe`); ``settle`` (``d``): S6 turned onto the lean axis and the
normal force raised until within ``settle_tol``; ``travel`` (``f``): the estimator
(:mod:`.estimator`) and the law (:mod:`.law`) each cycle; ``finish`` (``e``): the requested
travel done. Every move goes through the press task's move path and the envelope.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from kinestat.control.controller import (
    Command,
    ControllerState,
    Refusal,
    Target,
    approach_refusal,
    contact_at_start,
    move_command,
)
from kinestat.control.cycle import cross3
from kinestat.control.envelope import check_measurement
from kinestat.control.follow.config import FollowConfig, FollowState
from kinestat.control.follow.estimator import (
    ContactEstimate,
    developed_step,
    observe_travel,
    settle_sample,
    start_travel,
)
from kinestat.control.follow.law import (
    accel_limit,
    base_twist,
    lean_axis,
    lean_of,
    target_of,
    turn_towards,
)
from kinestat.control.probe import probe_normal, probe_step, start_probe
from kinestat.control.wrench import Measurement
from kinestat.errors import InputError

__all__ = ["decide_follow", "FOLLOW_STATES"]

FOLLOW_STATES = {
    "a": "approach along S6, no contact",
    "b": "first contact",
    "p": "probing: touching the surface around the first contact to measure its normal",
    "d": "settling the normal force before travel",
    "f": "following the surface: travel + force control",
    "e": "requested travel done",
}
"""The labels of a follow run's cycles."""

_LABELS = {"approach": "a", "probe": "p", "settle": "d", "travel": "f"}


def decide_follow(config: FollowConfig, state: ControllerState,
                  meas: Measurement) -> tuple[Command, FollowState]:
    """One cycle of the follow task: the next command and the new state (pure).

    ``state`` is the press task's start state (:func:`~kinestat.control.controller.start`) on
    the first cycle, then the :class:`FollowState` this function returned.
    """
    if state.done:
        raise InputError("decide_follow: the run is over (state.done); start a new one")
    base = config.base
    st = (state if isinstance(state, FollowState)
          else FollowState(**vars(state), leaning=config.auto_tilt is True))
    st = replace(st, cycle=st.cycle + 1, top_pose=meas.top_pose)
    F = meas.estimate(base.estimator)
    contact = float(np.linalg.norm(F)) >= base.contact_force
    st = _observe(config, st, meas, F, contact)
    label = _LABELS[st.phase]
    if contact and (st.phase == "approach" or (st.phase == "probe" and st.probe.cycles == 0)):
        label = "b"
    kw = _report(config, st, meas, F, contact)
    bad = check_measurement(base.envelope, base.model, meas)
    if bad:
        return _stop(st, label, "measurement outside the envelope: " + "; ".join(bad),
                     violations=tuple(bad), **kw)
    if contact and state.last_action == "start":
        return _stop(st, label, contact_at_start(float(np.linalg.norm(F))), **kw)
    if st.cycle >= base.max_iterations:
        return _stop(st, label, f"travel not completed after {st.cycle} cycles "
                     f"({st.travel:.3f} of {config.travel:g} mm)", **kw)
    if st.phase == "probe":
        return _probe(config, st, meas, label, contact, kw)
    if not contact:
        return _regain(config, st, meas, label, kw)
    return _act(config, st, meas, label, kw)


def _report(config: FollowConfig, st: FollowState, meas: Measurement, F: np.ndarray,
            contact: bool) -> dict:
    """The cycle's figures (the report's per-cycle ``info``) and the force error."""
    est = st.estimate
    n = None if est is None else est.normal
    fn = float(-(F @ n)) if (contact and n is not None) else 0.0
    ft = float(np.linalg.norm(F + fn * n)) if (contact and n is not None) else 0.0
    info = {"phase": st.phase, "tip": meas.tip(config.base.model), "normal_estimate": n,
            "normal_force": fn, "tangential_force": ft, "travel": st.travel,
            "in_contact": contact,
            "friction_ratio": 0.0 if est is None else est.mu,
            "workpiece_compliance": 0.0 if est is None else est.compliance,
            "curvature": 0.0 if est is None else est.curvature, "auto_tilt": st.leaning}
    return {"force_error": config.base.force_target - fn, "info": info}


def _observe(config: FollowConfig, st: FollowState, meas: Measurement, F: np.ndarray,
             contact: bool) -> FollowState:
    """The estimator's part of the cycle: first contact, and each travel cycle's update."""
    if not contact:
        return st
    tun = config.tuning
    tip = meas.tip_centre(config.base.model)  # a ball tip's centre: on the offset surface
    if st.estimate is None:  # first contact: the force's direction until the probe's fit
        est = ContactEstimate(normal=-F / np.linalg.norm(F), normal_var=math.atan(
            tun.max_friction) ** 2, tips=(tip.copy(),))
        st = replace(st, estimate=est, phase="settle")
        if config.probe_span > 0.0:
            st = replace(st, phase="probe", probe=start_probe(
                tip, st.target.tool_point, st.target.s6, config.travel_dir, config.probe_span))
        return st
    if st.phase != "travel":
        if st.phase == "settle":  # the tip stuck while the force rises: the workpiece's give
            sample = settle_sample(st.estimate, tip, F)
            st = replace(st, settle_samples=st.settle_samples + (sample,))
        return replace(st, estimate=replace(st.estimate, tips=(tip.copy(),), path=(tip.copy(),)))
    est, tip = start_travel(tun, st.estimate, st.settle_samples, tip, F)
    st = replace(st, settle_samples=(), estimate=est)
    est = observe_travel(tun, est, tip, F, st.tangent)
    # the centre's path is the contact's offset by the radius: shorter by 1 − r κ on it
    shrink = 1.0 - config.base.model.tip_radius * est.curvature
    developed = developed_step(st.developed, est.normal,
                               shrink * (tip - st.estimate.tips[-1]), st.tangent)
    stuck = st.stuck + 1 if (st.step > 0.0 or st.stuck) and not est.sliding else 0
    leaning = st.leaning or (config.auto_tilt is None and config.tilt_deg == 0.0
                             and stuck >= 2 and _frictional(tun, est))
    settled = abs(config.base.force_target + float(F @ est.normal)) <= config.settle_tol
    slides = st.slides + 1 if est.sliding and settled else 0
    return replace(st, estimate=est, developed=developed, travel=math.hypot(*developed),
                   stuck=stuck, leaning=leaning, slides=slides)


def _frictional(tun, est: ContactEstimate) -> bool:
    """A stuck tip is friction unless slides measured μ at zero."""
    return est.samples == 0 or est.friction_known(tun)


def _probe(config: FollowConfig, st: FollowState, meas: Measurement, label: str,
           contact: bool, kw: dict) -> tuple[Command, FollowState]:
    """A probing cycle; when the touches are done, the probe's plane is the normal."""
    base = config.base
    tgt = st.target
    tip = meas.tip_centre(base.model)
    ps = probe_step(st.probe, tgt.tool_point, contact, tip, base.approach_step)
    st = replace(st, probe=ps.probe)
    if ps.reason:
        return _stop(st, label, ps.reason, **kw)
    if not ps.done:
        return _command(config, st, meas, Target(ps.tool_point, tgt.s6, tgt.a67), label,
                        "probe", 0.0, 0.0, kw)
    n, fit = probe_normal(ps.probe.points, st.estimate.normal, tgt.s6)
    tun = config.tuning
    var = ((tun.tip_sigma / config.probe_span) ** 2 if fit["used"]
           else st.estimate.normal_var)
    est = replace(st.estimate, normal=n, normal_var=var, tips=(tip.copy(),), path=(tip.copy(),),
                  line=tuple(np.asarray(p).copy() for p in ps.probe.line))
    st = replace(st, phase="settle", estimate=est)
    kw = _report(config, st, meas, meas.estimate(base.estimator), contact)
    kw["info"]["probe"] = fit
    return _act(config, st, meas, label, kw)


def _regain(config: FollowConfig, st: FollowState, meas: Measurement, label: str,
            kw: dict) -> tuple[Command, FollowState]:
    """No contact: approach along S6 (before contact) or along the last normal (travel)."""
    base = config.base
    tgt = st.target
    d = tgt.s6
    if st.phase == "travel":
        lost = st.contact_lost + 1
        st = replace(st, contact_lost=lost)
        if lost > config.max_contact_lost:
            return _stop(st, label, f"contact lost for {lost} cycles during travel", **kw)
        d = -st.estimate.normal
    new = Target(tgt.tool_point + base.approach_step * d, tgt.s6, tgt.a67)
    refused = approach_refusal(base, new.tool_point) if st.phase == "approach" else ""
    if refused:
        return _stop(st, label, refused, **kw)
    return _command(config, st, meas, new, label, "approach", base.approach_step, 0.0, kw)


def _tangent(config: FollowConfig, st: FollowState) -> np.ndarray | None:
    n = st.estimate.normal
    t0 = st.tangent if st.tangent is not None else config.travel_dir
    t = t0 - float(t0 @ n) * n
    if np.linalg.norm(t) < math.sin(math.radians(config.min_angle_deg)):
        return None
    return t / np.linalg.norm(t)


def _act(config: FollowConfig, st: FollowState, meas: Measurement, label: str,
         kw: dict) -> tuple[Command, FollowState]:
    """A contact cycle of settle or travel: the phase transition and the law."""
    n = st.estimate.normal
    t = _tangent(config, st)
    if t is None:
        return _stop(st, label, f"the travel direction is within {config.min_angle_deg:g}° "
                     f"of the measured normal {np.round(n, 4).tolist()}: it points into the "
                     "surface", **kw)
    err = kw["force_error"]
    phase = "settle" if st.phase == "approach" else st.phase
    if phase == "settle" and abs(err) <= config.settle_tol:
        phase = "travel"
    st = replace(st, phase=phase, tangent=t)
    kw["info"]["phase"] = phase
    remaining = config.travel - st.travel
    if phase == "travel" and remaining <= 3.0 * config.tuning.step_resolution:
        return (Command(kind="done", label="e", reason=f"travelled {st.travel:.3f} mm along the "
                        "surface", **kw), replace(st, label="e", done=True, phase="finish"))
    return _move(config, st, meas, label, kw, n, t, remaining)


def _lean_goal(config: FollowConfig, st: FollowState, meas: Measurement, n: np.ndarray,
               t: np.ndarray) -> tuple[float, bool]:
    """The lean the law aims at (rad) and whether the tip is held (the breakaway: no travel
    step, the lean grows at the rate the soft mode allows) while it sticks, or creeps before
    a slide measured μ (stick or slip uncertain: a step would run it ahead)."""
    tun, est = config.tuning, st.estimate
    if not st.leaning:
        return math.radians(config.tilt_deg), False
    if st.phase == "travel" and (st.stuck or not est.samples):  # stuck, or creeping
        F = meas.estimate(config.base.estimator)
        now = lean_of(F / np.linalg.norm(F), n, t)  # the force's lean: S6 leads it by a step
        if _force_fell(config, F, n):  # the tip may be breaking away: lean no further
            return now, True
        return now + lean_rate(config, now), True
    if est.friction_known(tun):
        return math.atan(est.mu) + edge_margin(tun, est, config.base.force_target,
                                               config.travel_step), False
    return st.lean, False


def _force_fell(config: FollowConfig, F: np.ndarray, n: np.ndarray) -> bool:
    """Whether the normal force fell below the target by more than half the drop a lean step
    may cause at a slip (``settle_tol``, :func:`lean_rate`) and significantly (``confidence``
    standard deviations of a change, ``√2 σ_F``): under a held lean the first sign of a slip,
    the tip running ahead in the platform's soft mode before its advance is significant."""
    tun = config.tuning
    drop = config.base.force_target + float(F @ n)
    return drop > max(0.5 * config.settle_tol,
                      tun.confidence * math.sqrt(2.0) * tun.force_sigma)


def lean_rate(config: FollowConfig, lean: float) -> float:
    """rad per cycle: the largest change of the lean of S6 past a sliding tip's force. Each
    radian runs the tip ahead in the platform's soft mode by ``F/k_t`` and, the tool leaning
    by θ, drops the normal force by ``k_a F sin θ / k_t``: the step that drops it by
    ``settle_tol`` (at most ``max_turn_deg``)."""
    tun = config.tuning
    drop = (tun.axial_stiffness / tun.tangential_stiffness * config.base.force_target
            * max(math.sin(abs(lean)), 1e-3))
    return min(config.settle_tol / drop, math.radians(config.max_turn_deg))


def edge_margin(tun, est: ContactEstimate, force: float, step: float) -> float:
    """rad: how far the tool leans past the estimated cone edge, ``confidence`` standard
    deviations of where the edge is (the normal's, μ̂'s and the force direction's errors):
    the tip then slides on the true edge despite the estimate's error; at least the turn a
    travel step of ``step`` mm gives a stuck tip's force (``k_t step / F``), so that the
    steps do not stop the tip on the edge (a stick-slip) when the edge is known well."""
    var = (est.normal_var + est.mu_var / (1.0 + est.mu ** 2) ** 2
           + (tun.force_sigma / force) ** 2)
    return max(tun.confidence * math.sqrt(var), tun.tangential_stiffness * step / force)


def step_cap(config: FollowConfig, st: FollowState) -> float:
    """mm: the largest travel step. While leaning on friction, a step the tip does not follow
    pushes it along the leaning tool's axis, one it runs ahead of relaxes it (``k_axial sin θ``
    N per mm): the first step after a stick, or after a cycle whose normal force was not
    settled (beyond ``settle_tol``), changes the force by at most ``settle_tol``, and each
    cycle the tip slid with the force settled doubles it (up to ``travel_step``)."""
    if not st.leaning:
        return config.travel_step
    tun = config.tuning
    s = max(math.sin(abs(st.lean)), 1e-3)
    first = config.settle_tol / (tun.axial_stiffness * s)
    return min(config.travel_step, first * 2.0 ** min(st.slides, 30))


def _move(config: FollowConfig, st: FollowState, meas: Measurement, label: str, kw: dict,
          n: np.ndarray, t: np.ndarray, remaining: float) -> tuple[Command, FollowState]:
    """The law's command for a settle or travel cycle."""
    base, tun, est = config.base, config.tuning, st.estimate
    lean, held = _lean_goal(config, st, meas, n, t)
    F = meas.estimate(base.estimator)
    s = t if held else _friction_dir(config, st, F, n, t)
    axis = lean_axis(n, s, lean)
    mis = math.degrees(math.acos(max(-1.0, min(1.0, float(meas.s6 @ axis)))))
    kw["misalignment_deg"] = mis
    step = 0.0
    if st.phase == "travel" and not held:
        step = min(step_cap(config, st), max(0.5 * remaining,
                                                 min(4.0 * tun.step_resolution, remaining)))
    omega = turn_towards(meas.s6, axis, math.radians(config.max_turn_deg))
    if not st.leaning:
        omega = tun.turn_gain * omega  # a free tip swings under the turn: half a turn a cycle
    w_surf = est.curvature * step * cross3(n, t)
    omega = omega + w_surf
    stuck = held
    sliding = st.phase == "travel" and est.sliding and not held
    hold = (-F, w_surf) if sliding else None
    if stuck:  # the whole force is the law's: along the lean axis, its normal part F_req
        f_des = base.force_target / max(-float(axis @ n), 0.5) * axis
        dF = config.gain * (f_des - (F + cross3(omega, F)))
    else:
        mu = est.mu if (sliding and est.friction_known(tun)) else 0.0
        dF = -config.gain * kw["force_error"] * (n - mu * s)
    if st.phase == "settle" and mis > 2.0 * config.max_turn_deg:
        dF = dF - max(float(-(dF @ n)), 0.0) * -n  # turn first: pressing a tilted tool slides it
    try:
        T = base_twist(base.model, meas, meas.tip_centre(base.model), n, omega, step * t, dF,
                       (config.max_correction, config.travel_step), stuck, hold)
    except (InputError, np.linalg.LinAlgError) as exc:
        return _stop(st, label, f"the contact basis is singular for the platform stiffness: "
                     f"{exc}", **kw)
    st = replace(st, lean=lean)
    action = "follow" if st.phase == "travel" else "settle"
    return _command(config, st, meas, target_of(base.model, meas, T), label, action, step,
                    math.degrees(float(np.linalg.norm(omega))), kw,
                    accel_limit=accel_limit(config, meas, T))


def _friction_dir(config: FollowConfig, st: FollowState, F: np.ndarray, n: np.ndarray,
                  t: np.ndarray) -> np.ndarray:
    """The direction the tool leans towards: the travel ``t``, or, once the tip slides on a
    measured cone, the measured tangential force's (the friction's) direction, which need
    not be the travel's (MuJoCo's soft contact): S6 then stays along the force."""
    est = st.estimate
    if not (st.leaning and st.phase == "travel" and est.sliding
            and est.friction_known(config.tuning)):
        return t
    g = F - float(F @ n) * n
    a = float(np.linalg.norm(g))
    return g / a if a > 0.0 and float(g @ t) > 0.0 else t


def _stop(st: FollowState, label: str, reason: str, **kw) -> tuple[Command, FollowState]:
    return Command(kind="stop", label=label, reason=reason, **kw), replace(st, label=label,
                                                                           done=True)


def _command(config: FollowConfig, st: FollowState, meas: Measurement, new: Target, label: str,
             action: str, step: float, rotation_deg: float,
             kw: dict, accel_limit: float | None = None) -> tuple[Command, FollowState]:
    """Command ``new`` through the shared move path (or stop), its accelerations capped by
    ``accel_limit`` (1/s², :attr:`Command.accel_limit`)."""
    base = config.base
    cmd = move_command(base.model, base.envelope, base.vernier, meas, new, st.axis_counts,
                       label=label, action=action, step=step, rotation_deg=rotation_deg, info=kw)
    if isinstance(cmd, Refusal):
        return _stop(st, label, cmd.reason + _lean_hint(config, st, meas), **cmd.extra, **kw)
    if accel_limit is not None:
        cmd = replace(cmd, accel_limit=accel_limit)
    return cmd, replace(st, label=label, last_action=action, target=new,
                        axis_counts=cmd.axis_counts, step=step if action == "follow" else 0.0)


def _lean_hint(config: FollowConfig, st: FollowState, meas: Measurement) -> str:
    """What a refusal during travel with friction came from (empty otherwise)."""
    if st.phase != "travel" or st.estimate is None:
        return ""
    est = st.estimate
    lean = math.degrees(lean_of(meas.s6, est.normal, st.tangent))
    if not st.leaning:
        if not st.stuck:
            return ""
        return ("; the tip sticks on the workpiece: with friction use the automatic tilt "
                "(--auto-tilt, FollowConfig.auto_tilt=True; by default it switches itself on "
                "when the tip sticks under a travel step, unless --no-auto-tilt or --tilt-deg "
                "is given), which leans the tool onto the friction cone")
    why = (f"friction ratio measured {est.mu:.2f}" if est.samples else
           "the tip had not slid yet")
    return (f"; the automatic tilt leaned the tool {lean:.1f}° from the measured normal onto "
            f"the friction cone ({why}); at {config.base.force_target:.3g} N the platform cannot "
            "carry that lean: a lower --force (or less friction) keeps the top inside its range")
