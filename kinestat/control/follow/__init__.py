"""Force + motion: slide the tool along an unknown workpiece holding the normal force.

One call per cycle, :func:`decide_follow` ``(config, state, meas)``, returns the next
:class:`~kinestat.control.controller.Command` and the new state — pure, no I/O, run by the
press task's loop (:func:`kinestat.control.loop.run` with ``decide_fn``) on the simulated
cells (built-in or MuJoCo) or real hardware. The design, one module each:

* :mod:`.tuning` — ONE frozen :class:`FollowTuning` (13 parameters, each with a unit and a
  meaning), derived by :func:`derive_tuning` from the platform (spring rates, geometry, the
  tool, the load it carries), the leg sensors (count resolution, noise) and the robot
  (counts through the arm's Jacobian); the measurement model: a leg read to one count,
  ``σ_l = sqrt(r²/12 + σ_n²)``, propagated to the measured tip (``σ_tip``) and the
  point-contact force (``σ_F``), and the robot's axes to one count (the tip path's
  ``path_sigma``, the floor of ``direction_tol``).
* :mod:`.estimator` — the contact estimate (normal with its variance, friction coefficient
  with its variance, path curvature, slip): a significance test on the measured tips for the
  slip; while sliding, the normal made perpendicular to the tip path's chord (geometry) and
  ``atan μ̂`` from the force (the force is on the cone's edge), and μ̂ the force's tangential
  over normal part, fused by scalar Kalman updates; while stuck, the prediction (turned by the
  curvature under the tip's advance), kept inside the cone of the measured force.
* :mod:`.law` — Griffis & Duffy's decomposition (:func:`kinestat.parallel.kinestatic.
  compose_twist`): a twist of freedom (travel along the tangent, turn about the tip onto the
  lean axis, the surface's turn ``κ Δs``) plus a twist of compliance changing the contact
  force (along the cone's edge while sliding; the whole force through the tip while stuck),
  and the sliding force's hold while the base turns.
* :mod:`.phases` — the state machine: approach (``a``/``b``), probe (``p``, the normal from
  touches around the first contact, :mod:`kinestat.control.probe`), settle (``d``), travel
  (``f``), finish (``e``). With friction the tip sticks under the first steps; the tool then
  leans towards the travel, S6 a bounded step ahead of the force (the breakaway), until the
  tip slides; it then leans on the measured cone's edge by a margin of the estimate's
  uncertainty, and the steps grow again from the size a stuck tip can take.
* :mod:`.config` — :class:`FollowConfig` (checked before anything moves; the carry check),
  :class:`FollowState`; :mod:`.summary` — the report's figures (:func:`follow_summary`).
"""

from kinestat.control.follow.config import (
    DEFAULT_TRAVEL_AXES,
    FollowConfig,
    FollowState,
    carry_check,
    default_travel_dir,
)
from kinestat.control.follow.estimator import ContactEstimate, estimate_normal
from kinestat.control.follow.phases import FOLLOW_STATES, decide_follow
from kinestat.control.follow.summary import follow_summary
from kinestat.control.follow.tuning import FollowTuning, derive_tuning

__all__ = [
    "FollowConfig",
    "FollowState",
    "FollowTuning",
    "ContactEstimate",
    "FOLLOW_STATES",
    "DEFAULT_TRAVEL_AXES",
    "decide_follow",
    "estimate_normal",
    "carry_check",
    "follow_summary",
    "default_travel_dir",
    "derive_tuning",
]
