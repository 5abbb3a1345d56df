"""The press's move in contact (:func:`kinestat.control.controller.decide`): the align turn of
S6 onto the measured force about the tool point, damped where a turn overshot and capped per
cycle, the shed across S6 where a stuck tip carries the turns, and the step along the axis.

Pure functions; rotation vectors in radians, fixed frame. ``config`` and ``state`` are the
press's :class:`~kinestat.control.controller.ControllerConfig` and
:class:`~kinestat.control.controller.ControllerState`; targets are returned as
``(tool_point, s6, a67)``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from kinestat.control.arm import frame_from_tool
from kinestat.control.predict import sliding_push, tip_stiffness
from kinestat.control.tuning import TUNING, Tuning
from kinestat.spatial.transforms import cross3

__all__ = [
    "align_progress", "align_stalled", "align_stall_reason", "turn_vector", "rotate_onto",
    "align_gain", "turn_was_carried", "contact_move", "turned_force", "stuck", "shed",
]


def turn_vector(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation vector (3,) (radians) of the smallest rotation taking unit ``a`` onto
    unit ``b`` (zero when they are parallel)."""
    axis = cross3(a, b)
    s = np.linalg.norm(axis)
    if s < 1e-15:
        return np.zeros(3)
    return axis * (math.atan2(s, float(a @ b)) / s)


def align_gain(gain: float, last_turn, misalignment, tuning: Tuning = TUNING) -> float:
    """The fraction of the misalignment ``misalignment`` (rotation vector from S6 onto the
    measured force, radians) that the next align turn makes, after the turn ``last_turn``
    (rotation vector, or None when the last move was not an align turn) made with ``gain``.

    On a plane a turn of S6 about the tool point onto the force lands on it: the normal does
    not move. On a frictionless curved surface of curvature κ the turn δ also slides the free
    tip across the surface by about B δ (the platform's soft mode), where the normal differs by
    κ B δ; the whole turn then lands κ B e past the normal, and for κ B ≥ 1 the turns alternate
    for good (a frictionless R = 200 mm cylinder at 4 N: ±2.35° a cycle; docs/control.md,
    "The press on curved and steep workpieces"). The turn that lands on the normal is e / (1 + κ B).
    Without measuring κ B: a turn overshot when the new misalignment points back along it by
    more than ``tuning.overshoot_ratio`` of the turn (κ B > ½ at the whole turn); the gain
    then halves (down to ``tuning.min_align_gain``), otherwise it grows back by a quarter (up
    to 1).

    >>> align_gain(1.0, [0.0, 0.0, 0.04], [0.0, 0.0, -0.04])   # overshot by the whole turn
    0.5
    >>> align_gain(0.5, [0.0, 0.0, 0.04], [0.0, 0.0, 0.01])    # short of it: grows back
    0.625
    >>> align_gain(1.0, None, [0.0, 0.0, 0.04])                 # no turn before
    1.0
    """
    if last_turn is None:
        return float(gain)
    t = np.asarray(last_turn, dtype=float)
    size = float(np.linalg.norm(t))
    if not size > 0.0:
        return float(gain)
    back = -float(np.asarray(misalignment, dtype=float) @ t) / size
    if back > tuning.overshoot_ratio * size:
        return max(0.5 * float(gain), tuning.min_align_gain)
    return min(1.25 * float(gain), 1.0)


def align_progress(ref_deg: float | None, stall: int, mis_deg: float,
                   tol_deg: float, tuning: Tuning = TUNING) -> tuple[float, int]:
    """The align turns' progress after a contact cycle measured ``mis_deg``: ``(ref, stall)``,
    the misalignment at the last progress and the cycles since. Progress is the first contact,
    a misalignment within ``tol_deg`` or one below ``tuning.align_progress`` of ``ref_deg``
    (:func:`align_stalled`).

    >>> align_progress(None, 0, 2.0, 0.5), align_progress(2.0, 0, 1.7, 0.5)
    ((2.0, 0), (2.0, 1))
    >>> align_progress(2.0, 5, 1.5, 0.5)
    (1.5, 0)
    """
    if ref_deg is None or mis_deg <= tol_deg or mis_deg < tuning.align_progress * ref_deg:
        return mis_deg, 0
    return ref_deg, stall + 1


def align_stalled(stall: int, gain: float, tuning: Tuning = TUNING) -> bool:
    """Whether the align turns cannot settle the force on S6: ``stall`` contact cycles (at
    least ``tuning.align_stall_cycles``) went by without the misalignment falling below
    ``tuning.align_progress`` of its value at the last progress, while the turns overshot so
    often that their gain is within a halving of its floor ``tuning.min_align_gain``. On a
    frictionless convex surface at a high force the tip's equilibrium where the force would
    lie along S6 can be unstable: the smallest turn snaps the tip from one side of it to the
    other (a frictionless R = 200 mm cylinder at 5.8 N: 1.18° off on one side at a 0.078°
    turn, 2.75° off on the other at 0.104°), and no turn aligns it. The controller applies it to the
    stiffness method only: the fixed step's jumps of several newtons (``--method fixed``)
    also keep the turns from settling, and that run stops on its own reasons.

    >>> align_stalled(12, 1 / 32), align_stalled(12, 0.5), align_stalled(3, 1 / 32)
    (True, False, False)
    """
    return stall >= tuning.align_stall_cycles and gain <= 2.0 * tuning.min_align_gain


def align_stall_reason(stall: int, ref_deg: float, mis_deg: float,
                       tuning: Tuning = TUNING) -> str:
    """The stop reason of :func:`align_stalled`: ``ref_deg`` the misalignment at the last
    progress, ``mis_deg`` the present one.

    >>> align_stall_reason(12, 2.31, 2.08)[:64]
    'the force does not settle on the tool axis: in 12 cycles in cont'
    """
    return (f"the force does not settle on the tool axis: in {stall} cycles in contact the "
            f"misalignment did not fall {100 * (1 - tuning.align_progress):.0f} % below "
            f"{ref_deg:.3g}° (now {mis_deg:.3g}°), and the align turns, cut to a few "
            "hundredths of it, still overshoot across S6. The contact is unstable where its "
            "force would lie along S6, and the tip snaps from one side to the other (seen on "
            "frictionless convex workpieces of small radius at a high force): a lower --force, "
            f"or an --align-tol-deg above {max(ref_deg, mis_deg):.2g}°")


def turn_was_carried(before, turn, after, tuning: Tuning = TUNING) -> bool:
    """Whether the align turn ``turn`` (rotation vector, radians), made from the misalignment
    ``before``, was carried by the force instead of closing the gap: the misalignment
    ``after`` it is less than ``tuning.stuck_ratio`` of the turn smaller along it.

    A tip that sticks on the workpiece holds the top: turning S6 about the tool point then
    turns the platform rigidly about the tip, its legs do not change, and the force turns with
    the tool (the default plane with μ = 0.3: 0.74° before a 0.74° turn, 0.72° after it). Only
    a change of the platform's deflection turns the force relative to the tool
    (:func:`shed`). On a plane or a frictionless surface a turn
    removes at least itself (``align_gain``).

    >>> turn_was_carried([0, 0, 0.0129], [0, 0, 0.0129], [0, 0, 0.0126])
    True
    >>> turn_was_carried([0, 0, 0.0129], [0, 0, 0.0129], [0, 0, 0.0002])
    False
    >>> turn_was_carried(None, [0, 0, 0.0129], [0, 0, 0.0126])
    False
    """
    if before is None or turn is None:
        return False
    t = np.asarray(turn, dtype=float)
    size = float(np.linalg.norm(t))
    if not size > 0.0:
        return False
    closed = float((np.asarray(before, dtype=float) - np.asarray(after, dtype=float)) @ t) / size
    return closed < tuning.stuck_ratio * size


def rotate_onto(v: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotate ``v`` by the smallest rotation taking unit ``a`` onto unit ``b``."""
    axis = cross3(a, b)
    s = np.linalg.norm(axis)
    c = float(a @ b)
    if s < 1e-15:
        return v.copy()
    k = axis / s
    ang = math.atan2(s, c)
    return (v * math.cos(ang) + cross3(k, v) * math.sin(ang)
            + k * (k @ v) * (1.0 - math.cos(ang)))


def contact_move(config, state, meas, F: np.ndarray, mis: float, err: float,
                 max_turn_deg: float | None = None):
    """The move of a cycle in contact: (action, target, step along the axis, turn in degrees,
    the state's align memory). Misaligned: turn S6 onto the force about the tool point (the
    torque about it vanishes) — a fraction of the turn where the last one overshot
    (:func:`~kinestat.control.align.align_gain`), at most ``max_turn_deg`` — or, where
    the turns are carried by a stuck tip, shed the force across S6 (:func:`shed`). Then the
    step along the axis when the force is out of tolerance. ``max_turn_deg`` None: the
    tuning's ``max_align_turn_deg``."""
    model, tgt, tuning = config.model, state.target, config.tuning
    if max_turn_deg is None:
        max_turn_deg = tuning.max_align_turn_deg
    Fmag = np.linalg.norm(F)
    step, rotation, far, k_push = 0.0, 0.0, False, None
    memo: dict = {}
    if mis > config.align_tol_deg:
        full = turn_vector(tgt.s6, F / Fmag)
        if stuck(config, state, full, mis):
            return shed(config, state, meas, F, mis, err)
        action = "align"
        gain = align_gain(state.align_gain,
                          state.align_turn if state.last_action == "align" else None, full,
                          tuning)
        frac = min(gain, math.radians(max_turn_deg) / max(np.linalg.norm(full),
                                                                 1e-300))
        if frac < 1.0:
            turn = frac * full
            R = Rotation.from_rotvec(turn).as_matrix()
            axis = R @ tgt.s6
            axis /= np.linalg.norm(axis)
            a67 = R @ tgt.a67
        else:
            turn, axis = full, F / Fmag
            a67 = rotate_onto(tgt.a67, tgt.s6, axis)
        a67 = a67 - (a67 @ axis) * axis
        a67 /= np.linalg.norm(a67)
        rotation = frac * mis  # frac <= 1: exactly mis for the whole turn
        far = rotation > tuning.push_turn_deg or mis * (1.0 - frac) > tuning.push_left_deg
        memo = {"align_gain": gain, "align_turn": turn, "align_from": full}
        if config.method != "fixed":
            turned = turned_force(config, state, meas, axis, a67)
            if turned is not None and config.force_target - turned[0] < err:
                err, k_push = config.force_target - turned[0], turned[1]
    else:
        action = "force"
        axis, a67 = tgt.s6, tgt.a67
    if abs(err) > config.force_tol:
        if config.method == "fixed":
            step = math.copysign(config.step, err)
        else:
            k = float(axis @ tip_stiffness(model, meas) @ axis)
            if k_push is not None and tuning.min_push_rate * k <= k_push <= k:
                k = k_push  # the turned tool's push, with the tip sliding (turned_force)
            step = float(min(max(err / k, -config.step), config.step))  # numpy.clip, in floats
        if far and step > 0.0:  # a large turn, or far off the force: turn before pushing
            step = 0.0
    return action, (tgt.tool_point + step * axis, axis, a67), step, rotation, memo


def turned_force(config, state, meas, s6, a67) -> tuple[float, float] | None:
    """``(f, k)``: |F| (N) predicted after turning the tool onto ``s6``, ``a67`` about the
    tool point, no step along the axis, with the tip sliding freely, and its rate ``k``
    (N/mm) for a push along the new ``s6``
    (:func:`~kinestat.control.predict.sliding_push`); None out of contact. A turn onto the
    force undoes the top's soft deflection across the tool and loads the stiff axis instead:
    on a frictionless cylinder met 41° off the tool axis at 5.8 N two 20° turns raised the
    force from 0.3 to 4.7 N (predicted 5.8 N), and the Newton step computed without the turn
    pushed the top past its range. The step along the axis is taken on the lower of this error
    and the measured one (the turn's rise is never pushed on top of; a stuck tip's turn rises
    more, and is shed instead, :func:`shed`), and where the turn's error is the lower, at the
    rate ``k`` (the default plane's first turn: predicted 2.10 N, true 2.07 N; the turn and
    push 3.95 N, true 3.90 N, before ``k`` was used)."""
    tgt = state.target
    # the rigid motion from the commanded tool frame to the turned one, applied to the flange
    # where it was measured: the turn R_new R_nowᵀ about the tool point
    o = np.zeros(3)
    R = (frame_from_tool(o, s6, a67, o)[:3, :3]
         @ frame_from_tool(o, tgt.s6, tgt.a67, o)[:3, :3].T)
    move = np.eye(4)
    move[:3, :3] = R
    move[:3, 3] = tgt.tool_point - R @ tgt.tool_point
    return sliding_push(config.model, meas, move @ meas.flange_pose, s6)


def stuck(config, state, full: np.ndarray, mis: float) -> bool:
    """Whether the tip holds the platform, so that turning S6 cannot align it: the last turn
    was carried by the force (:func:`~kinestat.control.align.turn_was_carried`), or the last
    shed did what a held tip does (the misalignment fell at least half as much as it
    aimed). The stiffness method only (the shed needs the tip's stiffness)."""
    if config.method != "stiffness":
        return False
    if state.last_action == "align":
        return turn_was_carried(state.align_from, state.align_turn, full, config.tuning)
    return state.last_action == "shed" and mis <= state.shed_expect_deg


def shed(config, state, meas, F: np.ndarray, mis: float, err: float):
    """Move the flange, S6 kept, so that a held tip's force lies along S6: ``δ = K_tip⁻¹ δF``
    with ``δF = −F⊥`` (the force across S6; plus the error along S6 when out of tolerance),
    ``K_tip`` the platform's point stiffness at the tip (:func:`tip_stiffness`: moving the
    flange by ``δ`` with the tip held changes the force by ``K_tip δ``), scaled to at most
    ``config.step``. The platform is soft across the tool at the tip (about 0.05 N/mm), so a
    0.7° misalignment at 4 N is a shed of about 1 mm."""
    tgt = state.target
    s6 = tgt.s6
    along = float(F @ s6)
    dF = -(F - along * s6)
    if abs(err) > config.force_tol:
        dF = dF + (config.force_target - along) * s6
    delta = np.linalg.solve(tip_stiffness(config.model, meas), dF)
    size = float(np.linalg.norm(delta))
    frac = min(1.0, config.step / size) if size > 0.0 else 1.0
    delta = frac * delta
    memo = {"shed_expect_deg": mis * (1.0 - 0.5 * frac)}
    return ("shed", (tgt.tool_point + delta, s6.copy(), tgt.a67.copy()), float(delta @ s6),
            0.0, memo)
