"""The contact estimator of the follow task: normal, friction coefficient, curvature, slip.

Measurement model (:mod:`.tuning`): each cycle gives the measured tool tip ``p`` (a point of
the surface while in contact; noise ``σ_tip`` per coordinate) and the force the tool applies
to the workpiece ``F`` (noise ``σ_F`` per component).

* **Slip.** The tip slides when it advanced along the travel by more than ``confidence``
  standard deviations of an advance (``√2 σ_tip``, at least the tool's step resolution) in
  the last cycle or over the window of the last ``creep_window`` cycles: a significance test on
  the measured tips, not a tuned threshold.
* **Normal and friction while sliding** (a significant advance within one cycle: a creep,
  which a soft contact shows under a load inside the cone, is no evidence of the edge).
  Three measurements, each with its variance, fused by scalar Kalman updates: the normal is
  perpendicular to the tip path's chord carried to the current tip by the curvature
  (:func:`chord_constraint`: geometry only); μ is the force's tangential over its normal part
  (:func:`friction_on_normal`: a sliding tip's force is on the cone's edge; μ's variance never
  falls below the normal's share, common to every sample); the normal is ``atan μ̂`` from the
  force, away from its tangential part (:func:`cone_measurement`). Isotropic Coulomb friction
  would also put the normal as the force's part across the chord (:func:`estimate_normal`),
  but a plant's friction need not lie along the measured slip (MuJoCo's soft contact, measured
  at rest after each move, leaves it 18–45° off), so the chord gives only geometry. Friction
  opposes the slip, though: it counts only once its part along the slip (the drag) is
  significant too; a tangential force across the slip is a normal estimated off about the
  travel (the surface's turn about it, which the tip path does not show), and until friction
  counts the cone measurement takes the normal along the force.
* **While stuck** the force may lie anywhere in the cone and says nothing more: the normal is
  the prediction (the probe's plane fit or the last slide, turned by the curvature under the
  tip's advance), with its variance grown; the force lies inside the cone, so its ratio of
  tangential to normal part, less ``confidence`` standard deviations of the ratio, is a lower
  bound of μ (:func:`friction_lower_bound`; a slip mistaken for one, the tip's jitter, is
  corrected so rather than by turning the normal, which the geometry gave).
* **The workpiece's compliance.** A compliant workpiece gives under the tip by ``c F_n`` along
  the normal, so the tip path is the surface only at a steady normal force: a change of force
  tilts the chord as a turn of the surface would. While the force is raised with the tip
  stuck (the settle), the tip's height along the normal against the normal force gives ``c``
  when its slope is significant (:func:`contact_compliance`), and each travel cycle's tip is
  carried back to the surface by ``c F_n`` before the estimator uses it
  (:func:`surface_point`).
* **Curvature** from a circle fitted to the recent tips in the plane of the normal and the
  travel (:func:`~kinestat.control.contact_estimate.path_curvature`, with its significance
  test), with the probe's touches on the line of travel while the path is short.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from kinestat.control.contact_estimate import cone_normal, path_curvature, turn_by_curvature
from kinestat.control.follow.tuning import FollowTuning, advance_limit

__all__ = ["ContactEstimate", "estimate_normal", "advance_limit", "slip_test",
           "chord_constraint", "cone_measurement", "friction_on_normal", "friction_lower_bound",
           "observe_travel", "curvature_span", "contact_compliance", "surface_point",
           "settle_sample", "start_travel", "developed_step"]



@dataclass(frozen=True, eq=False)
class ContactEstimate:
    """The contact as estimated (fixed frame; immutable).

    Attributes:
        normal: (3,) unit normal, out of the material.
        normal_var: rad², variance of the normal's direction (about any tangent axis).
        mu: friction coefficient estimate (0 before a slide measured it).
        mu_var: its variance (inf before a slide).
        curvature: 1/mm, the normal curvature along the travel (positive convex).
        sliding: the last cycle's slip test.
        tips: the measured tips of the last ``creep_window`` travel cycles, oldest first.
        path: measured tips along the travel, each a significant advance from the one
            before (a stuck tip adds none), oldest first: the chords and the curvature.
        line: the probe's touches on the line of travel (the curvature's first points).
        samples: slides that measured the normal and μ.
        drag: the sliding tip's tangential force along its slip over its normal force (the
            friction's dissipative part), fused as μ: friction opposes the slip, so a
            tangential force across the slip (a normal estimated off about the travel) is
            no evidence of friction.
        compliance: mm/N, the workpiece's give along the normal under the normal force
            (:func:`contact_compliance`; 0 for a rigid workpiece).
    """

    normal: np.ndarray
    normal_var: float
    mu: float = 0.0
    mu_var: float = math.inf
    curvature: float = 0.0
    sliding: bool = False
    tips: tuple = ()
    path: tuple = ()
    line: tuple = ()
    samples: int = 0
    drag: float = 0.0
    compliance: float = 0.0

    def friction_known(self, tun: FollowTuning) -> bool:
        """μ measured and significantly above zero, the force's part along the slip too."""
        lim = tun.confidence * math.sqrt(self.mu_var)
        return self.samples > 0 and self.mu > lim and self.drag > lim


def estimate_normal(force, path_dir=None) -> np.ndarray:
    """The contact normal (out of the material) from the tool's force on the workpiece and the
    slip's direction (a chord of the tip path): ``−(F − (F·ĉ)ĉ)`` normalised. Isotropic
    Coulomb friction lies along the slip, so the force's part across the chord is the normal
    force (no μ needed); without a chord, the force's own direction.

    >>> estimate_normal([0.3, 0.0, -1.0], [1.0, 0.0, 0.0]).tolist()
    [-0.0, -0.0, 1.0]
    """
    F = np.asarray(force, dtype=float)
    if path_dir is not None:
        c = np.asarray(path_dir, dtype=float)
        c = c / np.linalg.norm(c)
        F = F - (F @ c) * c
    return -F / np.linalg.norm(F)


def contact_compliance(normal_forces, heights, height_sigma: float = 0.0,
                       confidence: float = 3.0) -> float:
    """mm/N: the workpiece's compliance along the normal from a stuck tip's normal forces
    (N) and heights along the normal (mm, each measured with standard deviation
    ``height_sigma``) while the force changes: the least-squares slope of the height against
    the force, negated (the tip sinks as the force rises). 0 unless it exceeds ``confidence``
    standard errors of the slope (a rigid workpiece's slope is noise), from fewer than three
    samples, or from a force that did not change.

    >>> contact_compliance([1.0, 2.0, 3.0, 4.0], [0.0, -0.25, -0.5, -0.75])   # 4 N/mm wood
    0.25
    >>> contact_compliance([1.0, 2.0, 3.0, 4.0], [0.0, -0.01, 0.0, -0.01], 0.01)  # noise
    0.0
    """
    f = np.asarray(normal_forces, dtype=float)
    h = np.asarray(heights, dtype=float)
    if f.size < 3:
        return 0.0
    df = f - f.mean()
    sxx = float(df @ df)
    if sxx <= 1e-12:
        return 0.0
    c = -float(df @ (h - h.mean())) / sxx
    return c if c > confidence * height_sigma / math.sqrt(sxx) else 0.0


def surface_point(est: ContactEstimate, tip: np.ndarray, F: np.ndarray) -> np.ndarray:
    """The surface point above a measured ``tip`` pressed into a compliant workpiece by the
    force ``F`` on it: ``tip + c F_n n̂`` (``c`` the estimate's compliance, ``F_n = −F·n̂``).

    >>> est = ContactEstimate(normal=np.array([0.0, 0.0, 1.0]), normal_var=0.0, compliance=0.25)
    >>> surface_point(est, np.zeros(3), np.array([0.0, 0.0, -4.0])).tolist()
    [0.0, 0.0, 1.0]
    """
    n = est.normal
    return tip + est.compliance * max(-float(F @ n), 0.0) * n


def developed_step(developed: tuple[float, float], normal: np.ndarray, d: np.ndarray,
                   t: np.ndarray) -> tuple[float, float]:
    """The tips' displacement on the surface developed into a plane (mm, along the travel
    tangent ``t`` and across it, ``normal × t``) after the tip's displacement ``d``, from
    ``developed``: on a plane or a cylinder, whose development keeps lengths, each cycle's
    chord stands for its short arc.

    >>> developed_step((0.0, 0.0), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.5, 0.0]),
    ...                np.array([1.0, 0.0, 0.0]))
    (1.0, 0.5)
    """
    across = np.cross(normal, t)
    a, c = developed
    return a + float(d @ t), c + float(d @ across)


def settle_sample(est: ContactEstimate, tip: np.ndarray, F: np.ndarray) -> tuple[float, float]:
    """A settle cycle's (normal force N, tip height along the normal mm) for
    :func:`contact_compliance`."""
    return -float(F @ est.normal), float(tip @ est.normal)


def start_travel(tun: FollowTuning, est: ContactEstimate, samples: tuple, tip: np.ndarray,
                 F: np.ndarray) -> tuple[ContactEstimate, np.ndarray]:
    """A travel cycle's estimate and surface point above the measured ``tip``; on the first
    (the settle's ``samples`` given) the workpiece's compliance from them, and the settle's
    last tip carried to the surface as the path's start."""
    if samples:
        c = contact_compliance(*zip(*samples, strict=True), tun.path_sigma, tun.confidence)
        est = replace(est, compliance=c)
        tips = tuple(surface_point(est, p, F) for p in est.tips)
        est = replace(est, tips=tips, path=tips[-1:])
    return est, surface_point(est, tip, F)


def slip_test(tun: FollowTuning, tips: tuple, tip: np.ndarray, t: np.ndarray) -> bool:
    """Whether the tip slides along ``t``: its advance over the last cycle exceeds
    :func:`advance_limit`, or it crept: advanced in each of the last ``creep_window`` − 1 cycles
    and by more than that limit over them (a stuck tip's jitter rarely does both)."""
    if not tips:
        return False
    lim = advance_limit(tun)
    x = [float((p - tip) @ t) for p in tips[-(tun.creep_window - 1):]] + [0.0]
    if x[-1] - x[-2] > lim:
        return True
    return (len(x) == tun.creep_window and x[-1] - x[0] > lim
            and all(b > a for a, b in zip(x[:-1], x[1:], strict=True)))


def _chord(tips: tuple, tip: np.ndarray, length: float) -> np.ndarray | None:
    """The chord from the latest earlier tip at least ``length`` mm back to ``tip``."""
    for old in reversed(tips):
        c = tip - old
        if float(np.linalg.norm(c)) >= length:
            return c
    return None


def chord_constraint(tun: FollowTuning, est: ContactEstimate, chord: np.ndarray
                     ) -> tuple[np.ndarray, float]:
    """The normal made perpendicular to the tip path (pure geometry, whatever the friction
    does): the ``chord`` carried to the current tip by the curvature (the tangent turns by
    κ|c|/2 from the chord's middle), and the predicted normal's part across it; variance from
    the chord's direction noise ``√2 σ_tip/|c|`` and the curvature fit's standard error
    (``curvature_tol / confidence``) over half the chord."""
    L = float(np.linalg.norm(chord))
    n = est.normal
    s = turn_by_curvature(n, chord / L, est.curvature * L / 2.0)[1]
    s /= np.linalg.norm(s)
    m = n - float(n @ s) * s
    var = 2.0 * (tun.tip_sigma / L) ** 2 + (tun.curvature_tol / tun.confidence * L / 2.0) ** 2
    return m / np.linalg.norm(m), var


def friction_on_normal(tun: FollowTuning, F: np.ndarray, n: np.ndarray, var_n: float
                       ) -> tuple[float, float]:
    """A sliding cycle's friction measurement against the normal estimate ``n`` (variance
    ``var_n``): a sliding tip's force is on the cone's edge, so μ is its tangential part over
    its normal part; with its variance (the force's noise and the normal's error, which tilts
    the ratio by ``(1 + μ²)`` per radian)."""
    fn = -float(F @ n)
    mu = float(np.linalg.norm(F + fn * n)) / fn
    var = (tun.force_sigma / fn) ** 2 * (1.0 + mu * mu) + (1.0 + mu * mu) ** 2 * var_n
    return mu, var


def friction_lower_bound(tun: FollowTuning, F: np.ndarray, n: np.ndarray, var_n: float
                         ) -> float:
    """A stuck cycle's lower bound of μ: the force lies inside the cone, so its tangential
    over its normal part (:func:`friction_on_normal`'s ratio) is at most μ; taken
    ``confidence`` standard deviations below the ratio, since the ratio is measured (the
    largest of many noisy ratios would climb past μ on its noise alone). 0 when the force
    does not press on the workpiece.

    >>> tun = FollowTuning(tip_sigma=0.01, path_sigma=0.01, force_sigma=0.01, confidence=3.0,
    ...     chord=1.0, direction_tol=0.01, step_resolution=0.001, tangential_stiffness=0.05,
    ...     axial_stiffness=1.0, turn_gain=0.5, max_friction=1.0, curvature_tol=1e-3)
    >>> F = np.array([1.0, 0.0, -4.0])                 # ratio 0.25 against the normal +z
    >>> round(friction_lower_bound(tun, F, np.array([0.0, 0.0, 1.0]), 0.0), 4)
    0.2423
    """
    if -float(F @ n) <= 0.0:
        return 0.0
    ratio, var = friction_on_normal(tun, F, n, var_n)
    return ratio - tun.confidence * math.sqrt(var)


def cone_measurement(tun: FollowTuning, est: ContactEstimate, F: np.ndarray
                     ) -> tuple[np.ndarray, float]:
    """A sliding cycle's normal from the force on the cone's edge: ``atan μ̂`` from the force
    on the tool, away from its tangential part (the friction's direction, measured: it need
    not be the travel's) (:func:`~kinestat.control.contact_estimate.cone_normal`), with its
    variance: the force's direction noise and μ̂'s error (``1/(1 + μ²)`` rad per unit)."""
    u = -F / np.linalg.norm(F)
    n = est.normal
    g = F - float(F @ n) * n  # the tangential force on the workpiece: along the slip
    if float(np.linalg.norm(g)) < 1e-12:
        return n, math.inf
    mu = est.mu if est.friction_known(tun) else 0.0  # no friction measured: along the force
    var = ((tun.force_sigma / float(np.linalg.norm(F))) ** 2
           + est.mu_var / (1.0 + mu * mu) ** 2)
    return cone_normal(u, g, mu), var


def _fuse_normal(n: np.ndarray, var: float, m: np.ndarray, var_m: float
                 ) -> tuple[np.ndarray, float]:
    g = var / (var + var_m)
    out = n + g * (m - n)
    return out / np.linalg.norm(out), (1.0 - g) * var


def curvature_span(tun: FollowTuning) -> float:
    """mm: the span of the path whose sagitta ``κ s²/8`` at ``curvature_tol`` is
    ``confidence path_sigma`` (at least the chord): the curvature is fitted over it."""
    return max(math.sqrt(8.0 * tun.confidence * tun.path_sigma / tun.curvature_tol), tun.chord)


def _curvature(tun: FollowTuning, est: ContactEstimate, path: tuple, tip: np.ndarray,
               n: np.ndarray, t: np.ndarray) -> float:
    """The path's curvature over the span that resolves ``curvature_tol``; with the probe's
    touches while the path is shorter. A larger curvature is resolved over less: the fit is
    taken once its points span half that span or the chord, and its sagitta exceeds twice
    its residual and ``confidence`` standard deviations of the robot's share of the path's
    noise (which a few points need not show)."""
    span = curvature_span(tun)
    x = (np.asarray(path) - tip) @ t if path else np.zeros(1)
    pts = path if float(np.ptp(np.append(x, 0.0))) >= span else est.line + path
    if len(pts) < 3:
        return est.curvature
    robot = math.sqrt(max(tun.path_sigma ** 2 - tun.tip_sigma ** 2, 0.0))
    return path_curvature(np.asarray(pts), tip, n, t, min(0.5 * span, tun.chord),
                          noise=tun.confidence * robot)


def observe_travel(tun: FollowTuning, est: ContactEstimate, tip: np.ndarray, F: np.ndarray,
                   t: np.ndarray) -> ContactEstimate:
    """One travel cycle's update of ``est`` from the measured ``tip`` and force ``F`` with
    the travel tangent ``t`` (module docstring)."""
    tips = est.tips
    sliding = slip_test(tun, tips, tip, t)
    adv = float((tip - tips[-1]) @ t) if tips else 0.0
    # prediction: the normal turns with the surface under the tip's advance
    n, _ = turn_by_curvature(est.normal, t, est.curvature * adv)
    var = est.normal_var + (tun.curvature_tol * adv) ** 2
    est = replace(est, normal=n / np.linalg.norm(n), normal_var=var, sliding=sliding)
    new_tips = (tips + (tip.copy(),))[-tun.creep_window:]
    path = est.path
    if not path or float(np.linalg.norm(tip - path[-1])) > advance_limit(tun):
        span = 2.0 * curvature_span(tun)  # the chord's and the curvature's reach
        path = tuple(p for p in path if float(np.linalg.norm(tip - p)) <= span) + (tip.copy(),)
    # a creep (a soft contact's micro-slip under a load inside the cone) slides but says
    # nothing of the edge: only a significant slip within one cycle is measured
    if sliding and tips and float((tip - tips[-1]) @ t) > advance_limit(tun):
        c = _chord(est.path, tip, tun.chord)
        if c is not None and float(c @ t) > 0.5 * float(np.linalg.norm(c)):
            m, var_m = chord_constraint(tun, est, c)
            n, var = _fuse_normal(est.normal, est.normal_var, m, var_m)
            est = replace(est, normal=n, normal_var=var)
        mu_m, var_mu = friction_on_normal(tun, F, est.normal, est.normal_var)
        # μ and the drag share their variance: each measured against the same force and normal
        first = not est.samples
        drag, _ = _fuse(est.drag, est.mu_var, _drag(F, est.normal, tip - tips[-1]), var_mu, first)
        mu, mvar = _fuse(est.mu, est.mu_var, mu_m, var_mu, first)
        # every sample is measured against the same normal: its error is common to them
        floor = (1.0 + mu * mu) ** 2 * est.normal_var
        est = replace(est, mu=min(max(mu, 0.0), tun.max_friction), mu_var=max(mvar, floor),
                      samples=est.samples + 1, drag=drag)
        if est.samples > 1:  # the force on the cone's edge: the normal atan μ̂ from it
            m, var_m = cone_measurement(tun, est, F)
            n, var = _fuse_normal(est.normal, est.normal_var, m, var_m)
            est = replace(est, normal=n, normal_var=var)
    elif est.samples:  # a stuck tip's force is inside the cone: its ratio bounds μ below
        bound = friction_lower_bound(tun, F, est.normal, est.normal_var)
        if bound > est.mu:
            est = replace(est, mu=min(bound, tun.max_friction))
    tt = t - float(t @ est.normal) * est.normal
    kappa = _curvature(tun, est, path[:-1], tip, est.normal, tt / np.linalg.norm(tt))
    return replace(est, tips=new_tips, path=path, curvature=kappa)


def _drag(F: np.ndarray, n: np.ndarray, slip: np.ndarray) -> float:
    """The tangential force on the workpiece along the tip's ``slip`` over the normal force."""
    fn = -float(F @ n)
    s = slip - float(slip @ n) * n
    return float((F + fn * n) @ s) / (fn * float(np.linalg.norm(s)))


def _fuse(x: float, var: float, m: float, var_m: float, first: bool) -> tuple[float, float]:
    """A scalar Kalman update of ``x`` (variance ``var``) by the measurement ``m`` (``var_m``);
    the measurement itself when it is the ``first``."""
    if first:
        return m, var_m
    g = var / (var + var_m)
    return x + g * (m - x), (1.0 - g) * var
