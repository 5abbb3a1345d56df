"""The follow task's request and state: :class:`FollowConfig` (checked before anything
moves), :class:`FollowState`, the default travel direction and the carry check."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinestat.control.controller import ControllerConfig, ControllerState
from kinestat.control.envelope import Envelope, check_motion
from kinestat.control.follow.estimator import ContactEstimate
from kinestat.control.follow.tuning import FollowTuning, derive_tuning, tip_load_pose
from kinestat.control.model import ControlModel
from kinestat.control.probe import PROBE_TUNING, Probe
from kinestat.errors import InputError
from kinestat.parallel.legs import leg_lengths

__all__ = ["FollowConfig", "FollowState", "carry_check", "default_travel_dir",
           "DEFAULT_TRAVEL_AXES"]

def _unit3(v, name: str) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) < 1e-12:
        raise InputError(f"{name} must be 3 finite numbers, not all zero, got "
                         f"{np.asarray(v).tolist()}")
    return a / np.linalg.norm(a)


DEFAULT_TRAVEL_AXES = ((0.0, 1.0, 0.0), (1.0, 0.0, 0.0))
"""The fixed-frame axes the default travel direction is made from, in order of preference."""


def default_travel_dir(approach) -> np.ndarray:
    """The follow task's travel direction when none is given: the fixed frame's +y made
    perpendicular to the approach direction ``approach`` (F_req), or +x when F_req is within
    30° of ±y. (3,) unit vector, at 90° from F_req: the tangent of a surface met head on.

    >>> default_travel_dir([0.9713, 0.0, -0.2375]).tolist()  # the thesis's F_req
    [0.0, 1.0, 0.0]
    >>> default_travel_dir([0.0, 1.0, 0.0]).tolist()  # F_req along y: +x
    [1.0, 0.0, 0.0]
    """
    d = _unit3(approach, "approach direction")
    for axis in DEFAULT_TRAVEL_AXES:
        a = np.asarray(axis)
        t = a - (a @ d) * d
        n = float(np.linalg.norm(t))
        if n >= 0.5:  # the axis is at least 30° from ±F_req
            return t / n
    raise AssertionError("unreachable: +x and +y cannot both be within 30° of one line")



def carry_check(model: ControlModel, envelope: Envelope, force, s6, a67,
                margin: float = 1.0) -> list[str]:
    """Violations of the envelope by the platform carrying ``force`` (N, fixed frame, the tool's
    force on the workpiece; checked at ``|force| + margin`` N, the force control's overshoot)
    at the tip with S6/a67 as given: an equilibrium must exist (the loaded platform stops
    carrying load beyond a limit, about 8 N along the thesis's direction with its calibrated
    legs), inside Table 3-1's motion ranges and the legs' deflection limit. Empty when it can
    be carried."""
    R6 = np.column_stack([a67, np.cross(s6, a67), s6])
    RB = R6 @ model.mount[:3, :3]
    plat = model.platform
    F = np.asarray(force, dtype=float)
    F = F * (1.0 + margin / float(np.linalg.norm(F)))
    top = tip_load_pose(plat, model.tool_tip_top, -(RB.T @ F))
    if top is None:
        return [f"the platform finds no equilibrium carrying {np.linalg.norm(F):.3g} N at the "
                "tool tip (its load limit along this direction)"]
    out = check_motion(envelope, model, top, f"at {np.linalg.norm(F):.3g} N the")
    defl = leg_lengths(plat, top) - plat.free_lengths
    k = int(np.argmax(np.abs(defl)))
    if abs(defl[k]) > envelope.max_deflection:
        out.append(f"at {np.linalg.norm(F):.3g} N leg {plat.leg_names[k]} would deflect "
                   f"{defl[k]:+.3f} mm, beyond ±{envelope.max_deflection:g} mm")
    return out



@dataclass(frozen=True, eq=False)
class FollowConfig:
    """Settings of one follow run (immutable; bad requests raise InputError here, before any
    motion).

    Attributes:
        base: the press task's settings (model, F_req, start pose, approach step, contact
            threshold, estimator, vernier, envelope, max_iterations).
        travel: distance to travel along the surface (mm).
        travel_dir: (3,) initial direction of travel (fixed frame), projected onto the
            tangent plane as the surface is discovered.
        travel_step: largest travel per cycle (mm).
        max_correction: largest tip motion of the compliance twist per cycle (mm).
        max_turn_deg: largest turn of S6 per cycle (degrees).
        gain: fraction of the normal-force error corrected per cycle (0 < gain ≤ 1).
        settle_tol: normal-force error (N) below which travel starts.
        tilt_deg: S6 tilted from −n̂ towards the travel direction (degrees, 0: along −n̂).
        auto_tilt: lean S6 onto the friction cone (:mod:`.phases`): a point contact on the
            long tool is very soft across the tool's axis (the top turns about the tip), so
            friction carried across the axis turns the top beyond Table 3-1's range; along
            the axis the platform carries it. While a stuck tip holds the travel the tool
            leans towards the travel, S6 a bounded step ahead of the force, until the tip
            slides; then it leans ``atan μ̂`` plus a margin of the estimate's uncertainty.
            True: from the first travel cycle; False: never (a sticking tip then drags the
            top round until the envelope stops the run, with a hint); None (default): it
            switches itself on when the tip does not follow two travel steps in a row,
            unless a tilt is commanded (``tilt_deg``) or slides measured no friction.
        max_contact_lost: cycles without contact during travel before a safe stop.
        min_angle_deg: smallest angle between the travel direction and the approach direction
            or the measured normal.
        probe_span: before the force is raised, the surface's normal is measured by touching
            it at this distance (mm) either side of the first contact, across and along the
            travel, and fitting a plane to the touches (:mod:`kinestat.control.probe`); 0:
            the first contact force's direction is taken instead (with friction it can lie
            anywhere in the friction cone, and a normal off by θ costs about |F_t| θ of
            normal force).
        tuning: the estimator's and the law's parameters (:class:`FollowTuning`); None
            (default): derived from the platform, the sensor and the robot
            (:func:`derive_tuning`).
    """

    base: ControllerConfig
    travel: float
    travel_dir: np.ndarray
    travel_step: float = 1.0
    max_correction: float = 0.3
    max_turn_deg: float = 1.0
    gain: float = 0.8
    settle_tol: float = 0.2
    tilt_deg: float = 0.0
    auto_tilt: bool | None = None
    max_contact_lost: int = 3
    min_angle_deg: float = 10.0
    probe_span: float = PROBE_TUNING.span_mm
    tuning: FollowTuning | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.travel) and 0.0 < self.travel <= 1000.0):
            raise InputError(f"travel (--travel) must be in (0, 1000] mm, got {self.travel!r}")
        t = _unit3(self.travel_dir, "travel direction")
        object.__setattr__(self, "travel_dir", t)
        if not (math.isfinite(self.travel_step) and self.travel_step > 0):
            raise InputError(f"travel_step (--travel-step) must be a positive number of mm, "
                             f"got {self.travel_step!r}")
        for name in ("max_correction", "max_turn_deg", "settle_tol"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"{name} must be a positive number, got {v!r}")
        if not 0.0 < self.gain <= 1.0:
            raise InputError(f"gain must be in (0, 1], got {self.gain!r}")
        if not (math.isfinite(self.probe_span) and 0.0 <= self.probe_span <= 20.0):
            raise InputError(f"probe_span (--probe-span) must be in [0, 20] mm (0: no "
                             f"probing), got {self.probe_span!r}")
        if self.auto_tilt not in (None, True, False):
            raise InputError(f"auto_tilt must be True, False or None (automatic), got "
                             f"{self.auto_tilt!r}")
        if not (math.isfinite(self.tilt_deg) and abs(self.tilt_deg) < 45.0):
            raise InputError(f"tilt_deg (--tilt-deg) must be within ±45°, got {self.tilt_deg!r}")
        d = self.base.start_s6
        ang = math.degrees(math.acos(min(1.0, abs(float(t @ d)))))
        if ang < self.min_angle_deg:
            raise InputError(f"travel direction {np.round(t, 4).tolist()} is {ang:.2f}° from the "
                             f"approach direction (F_req): it must make at least "
                             f"{self.min_angle_deg:g}° with it to travel along the surface")
        bad = carry_check(self.base.model, self.base.envelope, self.base.force, d,
                          self.base.start_a67)
        if bad:
            raise InputError(f"the requested force {self.base.force_target:g} N cannot be carried "
                             "by the platform inside the safety envelope: " + "; ".join(bad))
        if self.tuning is None:
            object.__setattr__(self, "tuning", derive_tuning(
                self.base.model, self.base.force_target, self.base.start_tool_point,
                self.travel_step, s6=self.base.start_s6, a67=self.base.start_a67))




@dataclass(frozen=True, eq=False)
class FollowState(ControllerState):
    """The follow task's state: the press state plus the phase, the contact estimate and the
    travel.

    Attributes:
        phase: "approach", "probe", "settle", "travel" (then the run is done: "finish").
        estimate: the contact estimate (:mod:`.estimator`), None before contact.
        tangent: (3,) the travel direction on the tangent plane, None before travel.
        travel: distance travelled along the surface (mm): the length of ``developed``.
        developed: (2,) mm, the measured tips' displacement on the surface developed into a
            plane, along the travel tangent and across it (``n̂ × t̂``): a wander across the
            travel and back cancels, as a stuck tip's jitter does; a steady drift counts.
        contact_lost: consecutive travel cycles without contact.
        step: the travel commanded by the last move (mm).
        leaning: the friction lean is on (the tip stuck under the travel, or asked for).
        lean: rad, the lean of S6 from the normal towards the travel the law aims at.
        stuck: travel cycles in a row the tip did not follow.
        slides: travel cycles in a row the tip slid.
        probe: the surface probe's progress (:mod:`kinestat.control.probe`), None without.
        settle_samples: the settle's contact cycles as (normal force N, tip height along the
            normal mm): the workpiece's compliance at the start of travel.
    """

    phase: str = "approach"
    estimate: ContactEstimate | None = None
    tangent: np.ndarray | None = None
    travel: float = 0.0
    developed: tuple[float, float] = (0.0, 0.0)
    contact_lost: int = 0
    step: float = 0.0
    leaning: bool = False
    lean: float = 0.0
    stuck: int = 0
    slides: int = 0
    probe: Probe | None = None
    settle_samples: tuple = ()
