"""Probing a surface's normal by touching it around a first contact (the follow task, issue 13).

Before the follow task raises the force, the tip sticks where it touched, and with friction its
force can lie anywhere in the friction cone (16.7° off the normal at μ = 0.3): the normal is
not observable from the force. A touch's measured tip, though, is a point of the surface. So
the tool lifts off along −S6 until out of contact and ``ProbeTuning.step_mm`` more (``lift``), moves
across to the next offset (``shift``, in steps of ``ProbeTuning.step_mm``; a surface rising into the
tool on the way is touched lightly and recorded as a touch), and is lowered along S6 until
contact (``descend``); the offsets (:func:`probe_offsets`) lie ``span`` either side of the
first contact across and along the travel, then at the centre again, where the force is
raised. S6 does not turn. The plane fitted to the touches' heights
(:func:`~kinestat.control.contact_estimate.fit_plane`) gives the normal
(:func:`probe_normal`); the symmetric pattern makes its slope the surface's central
difference, exact for a quadric, so a cylinder's curvature costs no bias at the centre.

:func:`probe_step` is one cycle: pure, a new :class:`Probe` and the next tool point (the
follow task turns it into a command through the shared move path and the envelope).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from kinestat.control.contact_estimate import fit_plane
from kinestat.spatial.transforms import cross3

__all__ = [
    "PROBE_TUNING",
    "ProbeTuning",
    "Probe",
    "ProbeStep",
    "probe_offsets",
    "probe_normal",
    "start_probe",
    "probe_step",
]

@dataclass(frozen=True)
class ProbeTuning:
    """The probe's settings (one frozen object; mm, cycles, degrees)."""

    span_mm: float = 3.0
    """Default span: the touches lie this far either side of the first contact. The fitted
    normal's error from a sensor's tip jitter ``e`` is about ``e / span`` rad (the thesis's
    counts: ~0.1 mm, so ~1°)."""
    descent_mm: float = 20.0
    """Largest descent along S6 below the first contact's height at an offset before the
    probe gives up: the surface is not there (an edge)."""
    step_mm: float = 1.0
    """The lift above the surface once out of contact and the largest step across (the
    approach step when that is larger). A slope of 10° rises 0.18 mm over a step."""
    max_cycles: int = 150
    """Largest number of probing cycles."""
    fit_rms_mm: float = 0.5
    """Largest RMS height residual of the touches from their plane: beyond it the surface is
    not smooth there (an edge, a step) and the fit is not used."""
    max_cone_deg: float = 45.0
    """Largest angle between the fitted plane's normal and the first contact force's
    direction (the steepest friction cone the follow task's estimator takes, μ = 1)."""


PROBE_TUNING = ProbeTuning()
"""The default probe settings."""



@dataclass(frozen=True, eq=False)
class Probe:
    """A probe's progress (immutable).

    Attributes:
        origin: (3,) the commanded tool point at first contact (the pattern's centre).
        approach: (3,) unit, the direction of the touches (S6 at first contact).
        offsets: the touches' offsets from ``origin`` (:func:`probe_offsets`).
        points: the measured tips of the touches so far (surface points), the first
            contact's first.
        line: the touches on the line of travel (the first contact, behind, ahead, the
            centre again): the path's first points for its curvature.
        index: the offset being touched.
        mode: "lift", "shift" or "descend".
        cycles: cycles spent probing.
    """

    origin: np.ndarray
    approach: np.ndarray
    offsets: tuple
    points: tuple = ()
    line: tuple = ()
    index: int = 0
    mode: str = "lift"
    cycles: int = 0


@dataclass(frozen=True, eq=False)
class ProbeStep:
    """One probing cycle's outcome: the new :class:`Probe`, the next commanded tool point
    (None when done or stopped) and a stop reason (empty if none); ``done`` once every
    offset was touched."""

    probe: Probe
    tool_point: np.ndarray | None
    reason: str = ""
    done: bool = False


def probe_offsets(travel_dir, approach, span: float) -> tuple:
    """The touches' offsets from the first contact (mm, perpendicular to ``approach``):
    ``span`` across the travel, back along it, across the other way, ahead, then the centre
    again: symmetric about the centre, so that the fitted slope is the central difference.

    >>> [(np.round(o, 6) + 0.0).tolist() for o in probe_offsets([0, 1, 0], [0, 0, -1], 3.0)][:2]
    [[3.0, 0.0, 0.0], [0.0, -3.0, 0.0]]
    """
    d = np.asarray(approach, dtype=float)
    d = d / np.linalg.norm(d)
    t = np.asarray(travel_dir, dtype=float)
    t = t - float(t @ d) * d
    t = t / np.linalg.norm(t)
    b = cross3(d, t)
    r = float(span)
    return (r * b, -r * t, -r * b, r * t, np.zeros(3))


def probe_normal(points, normal_guess, approach) -> tuple[np.ndarray, dict]:
    """The surface normal (out of the material) from the touches, and what the fit found: the
    plane fitted to the touches' heights against ``approach``
    (:func:`~kinestat.control.contact_estimate.fit_plane`, facing against it);
    ``normal_guess`` (the first contact force's direction) instead where the touches are
    nearly collinear, lie more than ``ProbeTuning.fit_rms_mm`` from a plane (an edge or a step), or
    the plane is more than ``ProbeTuning.max_cone_deg`` from the guess.

    >>> pts = [[0, 0, 0], [3, 0, 0.3], [0, 3, 0], [-3, 0, -0.3], [0, -3, 0]]
    >>> n, fit = probe_normal(pts, [0.0, 0.0, 1.0], [0.0, 0.0, -1.0])
    >>> (np.round(n, 6) + 0.0).tolist(), fit["used"]
    ([-0.099504, 0.0, 0.995037], True)
    """
    P = np.asarray(points, dtype=float)
    guess = np.asarray(normal_guess, dtype=float)
    n, rms, spread = fit_plane(P, approach)
    fit = {"points": int(len(P)), "fit_rms": float(rms), "normal": n.copy(), "used": True}
    half = 0.5 * float(np.max(np.linalg.norm(P - P.mean(axis=0), axis=1)))
    if (spread < 0.25 * half or rms > PROBE_TUNING.fit_rms_mm
            or float(n @ guess) < math.cos(math.radians(PROBE_TUNING.max_cone_deg))):
        fit["used"] = False
        return guess.copy(), fit
    return n, fit


def start_probe(tip, tool_point, approach, travel_dir, span: float) -> Probe:
    """The probe after the first contact at the measured ``tip`` with the commanded
    ``tool_point`` and S6 ``approach``."""
    d = np.asarray(approach, dtype=float)
    d = d / np.linalg.norm(d)
    tip = np.asarray(tip, dtype=float).copy()
    return Probe(origin=np.asarray(tool_point, dtype=float).copy(), approach=d,
                 offsets=probe_offsets(travel_dir, d, span), points=(tip,), line=(tip,))


def probe_step(probe: Probe, tool_point, contact: bool, tip, approach_step: float) -> ProbeStep:
    """One probing cycle (module docstring): from the commanded ``tool_point``, whether the
    tool is in ``contact`` and the measured ``tip``, the next tool point."""
    tp = np.asarray(tool_point, dtype=float)
    d, step = probe.approach, float(approach_step)
    wide = max(step, PROBE_TUNING.step_mm)
    pr = replace(probe, cycles=probe.cycles + 1)
    if pr.cycles > PROBE_TUNING.max_cycles:
        return ProbeStep(pr, None, "probing the surface did not finish in "
                         f"{PROBE_TUNING.max_cycles} cycles ({len(pr.points)} touches)")
    tip = np.asarray(tip, dtype=float).copy()
    mode = pr.mode
    if mode == "descend" and contact:
        on_line = abs(float(pr.offsets[pr.index] @ pr.offsets[0])) < 1e-9  # not across
        pr = replace(pr, points=pr.points + (tip,), index=pr.index + 1,
                     line=pr.line + (tip,) if on_line else pr.line)
        if pr.index == len(pr.offsets):
            return ProbeStep(replace(pr, mode=""), None, done=True)
        pr, mode = replace(pr, mode="lift"), "lift"
    if mode == "shift" and contact:  # the surface rose into the tool: a touch too
        pr, mode = replace(pr, points=pr.points + (tip,), mode="lift"), "lift"
    if mode == "lift":
        if not contact:  # clear of the surface: one probe step more, then across
            pr = replace(pr, mode="shift")
        return ProbeStep(pr, tp - (step if contact else wide) * d)
    depth = float((tp - pr.origin) @ d)
    if mode == "shift":
        rem = pr.origin + pr.offsets[pr.index] + depth * d - tp
        dist = np.linalg.norm(rem)
        if dist > 1e-9:
            if dist <= wide:
                pr = replace(pr, mode="descend")
            return ProbeStep(pr, tp + rem * min(1.0, wide / dist))
        pr = replace(pr, mode="descend")
    if depth > PROBE_TUNING.descent_mm:
        return ProbeStep(pr, None, "probing: no surface within "
                         f"{PROBE_TUNING.descent_mm:g} mm below the first contact at offset "
                         f"{np.round(pr.offsets[pr.index], 3).tolist()} mm (an edge of the "
                         "workpiece?); use a smaller --probe-span or --probe-span 0")
    return ProbeStep(pr, tp + step * d)
