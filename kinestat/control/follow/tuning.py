"""The follow task's one tuning object: every number the estimator and the law use.

Each parameter has a physical meaning and a unit, and its default is derived from the
platform (spring rates, geometry, the tool), the leg sensors (count resolution, noise) and the
robot (encoder resolution at the tool) by :func:`derive_tuning` — never from a workpiece.

The measurement model: a leg length is read to one count (``r`` mm) plus optional Gaussian
noise ``σ_n``, so each leg's error has standard deviation ``σ_l = sqrt(r²/12 + σ_n²)``
(uniform quantisation), independent across legs. Through the platform's kinematics it moves
the measured top, hence the measured tool tip (``σ_tip``), and through the springs (``k σ_l``
per leg tension) the point-contact force fit (``σ_F``): both are propagated here at the
platform's home pose. The robot's axes are read to one count too (``δ_i`` rad, error
``δ_i/√12``): through the arm's Jacobian at the start pose they move the measured base, hence
the tip path the curvature is fitted to (``path_sigma``), and turn it, hence
the direction of the measured force in the fixed frame (the floor of ``direction_tol``).
With a fine leg sensor the robot's counts are what is left of the measurement's noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from kinestat.control.model import ControlModel
from kinestat.errors import InputError, JointLimitError, UnreachableError
from kinestat.parallel.legs import leg_lengths, line_jacobian_trusted
from kinestat.parallel.statics import spring_wrench
from kinestat.parallel.stiffness import stiffness, tip_compliance
from kinestat.spatial.se3 import twist_exp
from kinestat.spatial.transforms import apply, apply_one, skew

__all__ = ["FollowTuning", "derive_tuning", "tip_load_pose", "loaded_stiffness",
           "tool_accel_limit", "advance_limit"]


@dataclass(frozen=True)
class FollowTuning:
    """The follow task's tuning (immutable; :func:`derive_tuning` gives the defaults).

    Attributes:
        tip_sigma: mm, standard deviation of one measured tip coordinate (leg counts and
            noise through the platform's kinematics, times the tool's lever).
        path_sigma: mm, the scatter of the tip path's points about a smooth path, which the
            curvature is fitted to: ``tip_sigma`` and the robot's axis counts through the
            arm's Jacobian (the robot places the path to one count at the tool; with a fine
            leg sensor this is what is left).
        force_sigma: N, standard deviation of one component of the measured contact force
            (leg counts and noise through the springs and the point-contact fit).
        confidence: the number of standard deviations a measured change must exceed to
            count (a slip, a friction coefficient above zero); 3 (a 0.3 % false alarm).
        chord: mm, shortest tip chord taken as the slip direction: its direction error
            ``√2 σ_tip / chord`` is at most ``direction_tol``.
        direction_tol: rad, the error allowed in a direction the estimator measures (a
            chord's, the normal's): the measured force's own direction noise, ``force_sigma``
            over the target force and the robot's axis counts turning the base.
        step_resolution: mm, the tool's displacement for one robot encoder count (the
            largest over the axes at the tool's reach): the smallest motion commanded, and
            the remaining travel at which the task is done (three counts).
        tangential_stiffness: N/mm, the tool tip's stiffness across the tool axis (the
            platform's soft direction at the tip) carrying the target force along the tool:
            the load on the long tool lowers it (:func:`loaded_stiffness`; on the thesis's
            cell 0.064 N/mm unloaded, 0.040 at 4 N).
        axial_stiffness: N/mm, the tool tip's stiffness along the tool axis, loaded alike.
        turn_gain: fraction of S6's misalignment turned per cycle while the tip slides
            freely: the turn swings the free tip across the surface, and turning onto a
            normal that moves with the swing converges for a loop gain below 2.
        max_friction: the largest friction coefficient the estimator accepts (a 45° cone:
            the probe's largest cone).
        creep_window: cycles over which a slow slide is told from a stuck tip's jitter: the
            tip advanced in each of the last ``creep_window − 1`` cycles (a jitter does so
            with probability ``2^−(creep_window−1)``) and significantly over them; 4.
        curvature_tol: 1/mm, the curvature that turns the normal by ``direction_tol`` over
            one travel step: the path's curvature is fitted over the span whose sagitta
            ``κ s²/8`` at this curvature is ``confidence path_sigma``, and the normal's
            prediction is uncertain by this much per mm of travel.
        tool_accel: mm/s², the largest acceleration of the top and the tool during a move in
            contact (:func:`tool_accel_limit`); ∞ for a massless top (the thesis's model).
    """

    tip_sigma: float
    path_sigma: float
    force_sigma: float
    confidence: float
    chord: float
    direction_tol: float
    step_resolution: float
    tangential_stiffness: float
    axial_stiffness: float
    turn_gain: float
    max_friction: float
    curvature_tol: float
    creep_window: int = 4
    tool_accel: float = math.inf

    def __post_init__(self) -> None:
        for name, v in vars(self).items():
            if not ((math.isfinite(v) or name == "tool_accel") and v > 0.0):
                raise InputError(f"follow tuning: {name} must be a positive number, got {v!r}")
        if self.creep_window < 2 or int(self.creep_window) != self.creep_window:
            raise InputError(f"follow tuning: creep_window must be an integer >= 2, got "
                             f"{self.creep_window!r}")
        if self.turn_gain > 1.0:
            raise InputError(f"follow tuning: turn_gain must be in (0, 1], got "
                             f"{self.turn_gain!r}")


def _leg_sigma(model: ControlModel, noise: float) -> float:
    """mm: one leg length's error, counts (uniform over a count) and noise."""
    per_count = float(np.mean(np.abs(np.asarray(model.calibration.length_coeffs)[:, 1])))
    return math.sqrt(per_count ** 2 / 12.0 + noise ** 2)


def _tip_jacobians(model: ControlModel) -> tuple[np.ndarray, np.ndarray]:
    """(∂tip/∂ξ (3, 6), ∂l/∂ξ (6, 6)) at home, ξ the top's small twist [ω; v] (base frame),
    by central differences."""
    plat = model.platform
    X0 = np.asarray(plat.home_pose, dtype=float)
    h = 1e-6
    Jt, Jl = np.zeros((3, 6)), np.zeros((6, 6))
    for i in range(6):
        e = np.zeros(6)
        e[i] = h
        Xp, Xm = twist_exp(e) @ X0, twist_exp(-e) @ X0
        Jt[:, i] = (apply_one(Xp, model.tool_tip_top) - apply_one(Xm, model.tool_tip_top)) / (2 * h)
        Jl[:, i] = (leg_lengths(plat, Xp) - leg_lengths(plat, Xm)) / (2 * h)
    return Jt, Jl


def _sigmas(model: ControlModel, leg_sigma: float) -> tuple[float, float]:
    """(σ_tip mm, σ_F N): the leg errors through the kinematics and the point-contact fit."""
    plat = model.platform
    Jt, Jl = _tip_jacobians(model)
    A = Jt @ np.linalg.inv(Jl)
    tip = leg_sigma * math.sqrt(float(np.max(np.linalg.eigvalsh(A @ A.T))))
    X0 = np.asarray(plat.home_pose, dtype=float)
    j = line_jacobian_trusted(plat, X0)
    p = apply_one(X0, model.tool_tip_top)
    M = np.linalg.solve(j, np.vstack([np.eye(3), skew(p)]))
    k = float(np.mean(np.abs(plat.stiffness)))
    cov = (k * leg_sigma) ** 2 * np.linalg.inv(M.T @ M)
    return tip, math.sqrt(float(np.max(np.linalg.eigvalsh(cov))))


def loaded_stiffness(platform, X: np.ndarray, tip_top: np.ndarray, f: np.ndarray
                     ) -> np.ndarray:
    """The platform's stiffness (6, 6, ray order ``[δx; δφ]``) at the top pose ``X`` carrying
    the force ``f`` (base frame) at the tool tip ``tip_top`` (top frame): the springs' ``K``
    less the load's own term, ``d[f; p × f]/d[δx; δφ]`` (the tip moves with the top)."""
    p = apply_one(X, tip_top)
    G = np.zeros((6, 6))
    G[3:, :3] = -skew(f)
    G[3:, 3:] = skew(f) @ skew(p)
    return stiffness(platform, X) - G


def tip_load_pose(platform, tip_top: np.ndarray, f_ext: np.ndarray, steps: int = 8,
                  max_iter: int = 30) -> np.ndarray | None:
    """The top pose (base frame) at which the springs carry the force ``f_ext`` (base frame)
    applied at the tool tip ``tip_top`` (top frame), the tip free to move (a frictionless
    contact): Newton on ``spring_wrench(X) = [f; p(X) × f]`` with :func:`loaded_stiffness`,
    the load raised in ``steps``; None where no equilibrium exists (the platform stops
    carrying load)."""
    X = platform.home_pose.copy()
    for k in range(1, steps + 1):
        f = f_ext * (k / steps)
        for _ in range(max_iter):
            p = apply(X, tip_top)
            r = np.concatenate([f, np.cross(p, f)]) - spring_wrench(platform, X)
            if float(np.linalg.norm(r)) <= 1e-8 * max(1.0, float(np.linalg.norm(f))):
                break
            try:
                d = np.linalg.solve(loaded_stiffness(platform, X, tip_top, f), r)
            except np.linalg.LinAlgError:
                return None
            d /= max(1.0, float(np.linalg.norm(d[3:])) / 0.05,
                     float(np.linalg.norm(d[:3])) / (0.05 * platform.scale))
            X = twist_exp(np.concatenate([d[3:], d[:3]])) @ X
        else:
            return None
    return X


def _tip_stiffness(model: ControlModel, force: float, s6, a67) -> tuple[float, float]:
    """(across, along) the tool axis: the tip's stiffness (N/mm) carrying ``force`` N along
    the tool (``s6``/``a67``: the start pose; None: along the mount's axis), at the loaded
    pose (:func:`tip_load_pose`; home where the platform cannot carry it)."""
    plat = model.platform
    a = np.linalg.inv(np.asarray(model.mount, dtype=float))[:3, :3] @ [0.0, 0.0, 1.0]
    if s6 is not None and a67 is not None:
        s6 = np.asarray(s6, dtype=float)
        R6 = np.column_stack([a67, np.cross(s6, a67), s6])
        a = (R6 @ np.asarray(model.mount, dtype=float)[:3, :3]).T @ s6
    a = a / np.linalg.norm(a)
    f = -force * a  # the workpiece's force on the tool, base frame
    X = tip_load_pose(plat, model.tool_tip_top, f)
    if X is None:
        X, f = np.asarray(plat.home_pose, dtype=float), np.zeros(3)
    K = loaded_stiffness(plat, X, model.tool_tip_top, f)[:, [3, 4, 5, 0, 1, 2]]
    C = tip_compliance(plat, X, apply_one(X, model.tool_tip_top), stiffness_axis=K)
    P = np.eye(3) - np.outer(a, a)
    across = float(np.max(np.linalg.eigvalsh(P @ C @ P)))
    return 1.0 / across, 1.0 / float(a @ C @ a)


def _count_at_tool(model: ControlModel, tool_point) -> float:
    """mm: the tool's largest displacement for one robot count: the arm axes' resolution
    times the tool point's distance from the base (axes 1-3), the wrist's times the tool's
    length (axes 4-6)."""
    deg = np.asarray(model.axis_deg_per_count, dtype=float)
    lever = np.where(np.arange(6) < 3, float(np.linalg.norm(tool_point)),
                     float(np.linalg.norm(model.tool_point_6)))
    return float(np.max(np.radians(deg) * lever))


def _robot_sigmas(model: ControlModel, tool_point, s6, a67) -> tuple[float, float]:
    """(σ mm, σ rad): each robot axis read to one count (uniform, ``δ_i/√12``) through the
    arm's Jacobian at the pose (``tool_point``, ``s6``, ``a67``): the tool tip's position
    and the end frame's orientation (largest over directions). Where the arm does not reach
    that pose (or no pose is given), the bound of :func:`_count_at_tool`'s levers."""
    arm, d = model.arm, np.radians(np.asarray(model.axis_deg_per_count, dtype=float))
    try:
        if s6 is None or a67 is None:
            raise UnreachableError("no start pose")
        axis = arm.solve_axis(tool_point, s6, a67, model.tool_point_6,
                              arm.q_from_axis(np.zeros(6)), model.limits_deg)
    except (UnreachableError, JointLimitError):
        lever = np.where(np.arange(6) < 3, float(np.linalg.norm(tool_point)),
                         float(np.linalg.norm(model.tool_point_6)))
        return (math.sqrt(float(np.sum((d * lever) ** 2)) / 12.0),
                math.sqrt(float(np.sum(d ** 2)) / 12.0))
    Cp, Cw = np.zeros((3, 3)), np.zeros((3, 3))
    for i in range(6):
        f = [arm.forward(arm.q_from_axis(axis + s * d[i] * np.eye(6)[i]), model.tool_point_6)
             for s in (1.0, -1.0)]
        dp = (np.asarray(f[0].tool_point) - np.asarray(f[1].tool_point)) / 2.0
        W = np.asarray(f[0].pose)[:3, :3] @ np.asarray(f[1].pose)[:3, :3].T  # two counts
        w = np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) / 4.0
        Cp += np.outer(dp, dp) / 12.0
        Cw += np.outer(w, w) / 12.0
    return (math.sqrt(float(np.max(np.linalg.eigvalsh(Cp)))),
            math.sqrt(float(np.max(np.linalg.eigvalsh(Cw)))))


def advance_limit(tun: FollowTuning) -> float:
    """mm: the smallest significant advance of the tip: ``confidence`` standard deviations
    of the difference of two measured tips (at least the tool's step resolution)."""
    return max(tun.confidence * math.sqrt(2.0) * tun.tip_sigma, tun.step_resolution)


def tool_accel_limit(mass: float, tangential_stiffness: float, resolution: float) -> float:
    """mm/s²: the largest acceleration ``a`` of a top + tool of ``mass`` kg during a move in
    contact. The law is quasi-static: it predicts where the platform comes to rest. While the
    top accelerates, its inertia ``m a`` loads the tip across the tool like a force, which the
    platform's soft tangential stiffness ``k_t`` (N/mm) turns into a run of ``m a / k_t`` mm;
    on a sliding contact, whose force is on the friction cone's edge, the tip runs that far
    beyond the rest state. Kept within ``resolution`` mm (the slip test's smallest advance):
    ``a = k_t resolution / m`` (N/kg = m/s², times 1000); ∞ for a massless top.

    >>> round(tool_accel_limit(0.35, 0.064, 0.13), 1)
    23.8
    """
    if mass <= 0.0:
        return math.inf
    return 1000.0 * tangential_stiffness * resolution / mass


def derive_tuning(model: ControlModel, force: float, tool_point, travel_step: float,
                  noise: float = 0.0, s6=None, a67=None) -> FollowTuning:
    """The default tuning for ``model`` at the target force ``force`` (N), the tool near
    ``tool_point`` (mm, fixed frame) with its axis ``s6`` and ``a67`` (the start pose: the
    robot's counts through the arm's Jacobian there; None: a bound from the arm's reach),
    travel steps up to ``travel_step`` (mm), with leg sensor ``noise`` (mm, standard
    deviation; 0: counts only). See :class:`FollowTuning`."""
    z = 3.0
    leg = _leg_sigma(model, noise)
    tip, fs = _sigmas(model, leg)
    tip_robot, turn = _robot_sigmas(model, tool_point, s6, a67)
    kt, ka = _tip_stiffness(model, force, s6, a67)
    dir_tol = math.hypot(fs / force, turn)
    tun = FollowTuning(
        tip_sigma=tip, path_sigma=math.hypot(tip, tip_robot), force_sigma=fs, confidence=z,
        chord=max(math.sqrt(2.0) * tip / dir_tol, z * tip),
        direction_tol=dir_tol, step_resolution=_count_at_tool(model, tool_point),
        tangential_stiffness=kt, axial_stiffness=ka, turn_gain=0.5,
        max_friction=1.0, curvature_tol=dir_tol / travel_step, creep_window=4)
    return replace(tun, tool_accel=tool_accel_limit(model.top_mass, kt, advance_limit(tun)))
