"""The follow task's one tuning object: every number the estimator and the law use.

Each parameter has a physical meaning and a unit, and its default is derived from the
platform (spring rates, geometry, the tool), the leg sensors (count resolution, noise) and the
robot (encoder resolution at the tool) by :func:`derive_tuning` — never from a workpiece.

The measurement model: a leg length is read to one count (``r`` mm) plus optional Gaussian
noise ``σ_n``, so each leg's error has standard deviation ``σ_l = sqrt(r²/12 + σ_n²)``
(uniform quantisation), independent across legs. Through the platform's kinematics it moves
the measured top, hence the measured tool tip (``σ_tip``), and through the springs (``k σ_l``
per leg tension) the point-contact force fit (``σ_F``): both are propagated here at the
platform's home pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinestat.control.model import ControlModel
from kinestat.errors import InputError
from kinestat.parallel.legs import leg_lengths, line_jacobian_trusted
from kinestat.parallel.stiffness import stiffness, tip_compliance
from kinestat.spatial.se3 import twist_exp
from kinestat.spatial.transforms import apply_one, skew

__all__ = ["FollowTuning", "derive_tuning"]


@dataclass(frozen=True)
class FollowTuning:
    """The follow task's tuning (immutable; :func:`derive_tuning` gives the defaults).

    Attributes:
        tip_sigma: mm, standard deviation of one measured tip coordinate (leg counts and
            noise through the platform's kinematics, times the tool's lever).
        force_sigma: N, standard deviation of one component of the measured contact force
            (leg counts and noise through the springs and the point-contact fit).
        confidence: the number of standard deviations a measured change must exceed to
            count (a slip, a friction coefficient above zero); 3 (a 0.3 % false alarm).
        chord: mm, shortest tip chord taken as the slip direction: its direction error
            ``√2 σ_tip / chord`` is at most ``direction_tol``.
        direction_tol: rad, the error allowed in a direction the estimator measures (a
            chord's, the normal's): ``force_sigma`` over the target force, the force's own
            direction noise.
        step_resolution: mm, the tool's displacement for one robot encoder count (the
            largest over the axes at the tool's reach): the smallest motion commanded, and
            the remaining travel at which the task is done (three counts).
        tangential_stiffness: N/mm, the tool tip's stiffness across the tool axis (the
            platform's soft direction at the tip).
        axial_stiffness: N/mm, the tool tip's stiffness along the tool axis.
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
            ``κ s²/8`` at this curvature is ``confidence σ_tip``, and the normal's
            prediction is uncertain by this much per mm of travel.
    """

    tip_sigma: float
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

    def __post_init__(self) -> None:
        for name, v in vars(self).items():
            if not (math.isfinite(v) and v > 0.0):
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


def _tip_stiffness(model: ControlModel) -> tuple[float, float]:
    """(across, along) the tool axis: the tip's stiffness at home (N/mm)."""
    plat = model.platform
    X0 = np.asarray(plat.home_pose, dtype=float)
    K = stiffness(plat, X0, twist_order="axis")
    C = tip_compliance(plat, X0, apply_one(X0, model.tool_tip_top), stiffness_axis=K)
    s6_base = np.linalg.inv(np.asarray(model.mount, dtype=float))[:3, :3] @ [0.0, 0.0, 1.0]
    a = s6_base / np.linalg.norm(s6_base)
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


def derive_tuning(model: ControlModel, force: float, tool_point, travel_step: float,
                  noise: float = 0.0) -> FollowTuning:
    """The default tuning for ``model`` at the target force ``force`` (N), the tool near
    ``tool_point`` (mm, fixed frame), travel steps up to ``travel_step`` (mm), with leg
    sensor ``noise`` (mm, standard deviation; 0: counts only). See :class:`FollowTuning`."""
    z = 3.0
    leg = _leg_sigma(model, noise)
    tip, fs = _sigmas(model, leg)
    kt, ka = _tip_stiffness(model)
    dir_tol = max(fs / force, 1e-4)
    return FollowTuning(
        tip_sigma=tip, force_sigma=fs, confidence=z,
        chord=max(math.sqrt(2.0) * tip / dir_tol, z * tip),
        direction_tol=dir_tol, step_resolution=_count_at_tool(model, tool_point),
        tangential_stiffness=kt, axial_stiffness=ka, turn_gain=0.5,
        max_friction=1.0, curvature_tol=dir_tol / travel_step, creep_window=4)
