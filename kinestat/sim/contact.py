"""The simulated cell's mechanics: PUMA 762 + compliant platform + tool + planar workpiece.

The cell of Vibhute 2011 ch. 4-5: the special 6-6 platform's base is bolted to the robot's
flange (frame 6), a tool tip is fixed to its top, and the tip presses on a workpiece. For each
flange pose this module solves the **contact equilibrium** of the top platform and returns the
true leg lengths and the true contact force; :class:`kinestat.sim.sensor.Sensor` turns leg
lengths into encoder counts as the platform's encoders would.

Over 600 lines on purpose: the stick/slip solve (:func:`_stick_or_slip`) keeps the sticking
solve and its slide residual as closures shared by the slide's three searches (secant and
Newton here; the damped Newton and the snap in :mod:`kinestat.sim._slide`).

Frames and conventions (all lengths in mm, forces in N):

* ``flange_pose`` is ``F_6T``, frame 6 in the fixed frame
  (:func:`kinestat.robots.puma762.forward.forward`).
* ``Cell.mount`` is ``6_BT``, the platform's base frame (O0 at the origin, P0 on +x) in frame 6.
  The default, :func:`centred_mount`, puts the base triangle's centroid on frame 6's z axis
  (S6), the base plane in frame 6's x-y plane and the base x axis along a67 — so the top's
  axis (the top triangle's centroid normal) is S6 when the platform is unloaded. (The thesis's
  eq_wrench.m makes the base frame coincide with frame 6 instead: ``mount = I``.)
* ``Cell.tool_tip`` is the tip in the top frame. By default it is the point that sits at the
  thesis's unloaded tool point ``P_tool_6 = (0, 0, 235)`` mm (App. D.1) when the platform is at
  home; with the centred mount that point is on the top's axis, 175 mm above the top plane.
* The workpiece is the half-space behind a plane through ``point`` with unit ``normal``
  pointing OUT of the material, towards the tool. The gap of the tip is ``n·(tip − point)``.
* A compliant workpiece (``Workpiece.stiffness`` k, N/mm; None: rigid) gives way under the
  tip along its normal: the tip sits ``f_n / k`` behind the surface, ``n·(tip − point) =
  −f_n / k``, and a sticking tip stays on the normal through its anchor (the surface is
  compliant along its normal only; tangentially the anchor holds or Coulomb slides it).
* Forces: ``contact_force`` is what the workpiece exerts on the tool; ``tool_force`` (its
  negative) is what the tool exerts on the workpiece — the sense of the thesis's ``W_eq``
  and of ``F_req``.

Equilibrium (all in base coordinates, unknown top pose X):

* out of contact (the unloaded tip is not behind the plane): the top rests at home;
* frictionless contact: ``w(X) = λ [n; p × n]`` and ``n·(p(X) − c) = −λ/k`` with ``λ ≥ 0``
  (``1/k = 0`` when rigid), where
  ``w`` is the external wrench the springs balance (:func:`kinestat.parallel.statics.spring_wrench`)
  and ``p`` the tip. 7 equations in (X, λ), solved by Newton with the platform stiffness
  ``K = ∂w/∂D`` (:func:`kinestat.parallel.stiffness.stiffness`) plus the contact's geometric
  term;
* Coulomb friction ``μ``: the tip sticks at its first contact point ``a`` (``w(X) =
  [f; p × f]``, ``p(X) = a − (f·n/k) n``, 9 equations) while ``|f_t| ≤ μ f_n``; beyond that it
  slides quasi-statically to the anchor ``a'`` where ``|f_t| = μ f_n`` with the friction
  opposing the slip ``a' − a`` (maximum dissipation), found by Newton over the 2-D slip.

Each solution is checked: wrench residual ≤ ``tol`` (1e-9 N and N·mm by default), tip on the
plane (at ``−f_n/k`` from it when compliant), ``f_n ≥ 0`` (unilateral), and every leg
deflection within the legs' stroke.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial.transform import Rotation

from kinestat.errors import InputError, ModelError, UnreachableError
from kinestat.hardware.leg_calibration import LegCalibration
from kinestat.hardware.leg_law import calibrated_platform, tension_slopes, tensions_at_lengths
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import Platform
from kinestat.parallel.statics import spring_wrench
from kinestat.parallel.stiffness import stiffness
from kinestat.robots.puma762.axes import THESIS_TOOL_POINT_6
from kinestat.sim._slide import damped_slide, fd_jacobian, snap_slide
from kinestat.spatial.transforms import apply, apply_vector, as_array, inv, make_pose, skew
from kinestat.spatial.validate import frozen

__all__ = [
    "DEFAULT_TOOL_POINT_6",
    "DEFAULT_STROKE",
    "Workpiece",
    "Cell",
    "Equilibrium",
    "centred_mount",
    "make_cell",
    "equilibrium",
    "unloaded_tip",
]

DEFAULT_TOOL_POINT_6 = THESIS_TOOL_POINT_6
"""The unloaded tool tip in frame 6, mm: the thesis's ``P_tool_6`` (Vibhute App. D.1,
:data:`kinestat.robots.puma762.axes.THESIS_TOOL_POINT_6`)."""

DEFAULT_STROKE = 8.0
"""Largest leg deflection |l − l0| the simulated legs can take (mm) before bottoming out.

The design range is 5 mm (Vibhute Table 3-1); the controller's safety envelope stops there.
The simulated hardware tolerates a little more so that the envelope, not the simulator, is
what stops an excessive command."""


SLIDE_TOL = 1e-3
"""Largest force residual (N) accepted for a sliding contact's equilibrium. One count of a leg
sensor is about 0.03 N (0.0254 mm at about 1.1 N/mm), so 1e-3 N is invisible in the counts; a
solve that stops short of its 1e-10 N target near the stick-slip boundary (residuals of 2e-5 and
2e-4 N were seen) is accepted instead of failing the cell, and the friction force may then
exceed the cone by that residual."""
SLIDE_CONVERGED = 1e-10
"""The sliding contact's Newton target (N)."""
_SLIDE_STARTS = (1.0, 8.0, 64.0)
"""Starts of the sliding contact's one Newton (:func:`_solve_slide`), as multiples of the
stiffness-based guess of the slip ``s0`` (at least 1e-3 mm): s0, then 8·s0 and 64·s0 before
the secant search takes over. Around a first touch (hundredths of a newton) the tangential
stiffness along the slip can be negative near the anchor: the slip first runs on, then rests
further out (0.024 mm for an excess of 1e-4 N over the cone, R = 333 mm cylinder, follow
study seed 13). From s0 the Newton turns back; from 8·s0 it reaches the rest the secant
search finds (to 1e-10 N) in 0.05 s instead of 0.3 s."""


def _unit(v, name: str) -> np.ndarray:
    a = as_array(v, shape_tail=(3,), name=name)
    if a.shape != (3,):
        raise InputError(f"{name} must be 3 numbers, got shape {a.shape}")
    n = float(np.linalg.norm(a))
    if n < 1e-12:
        raise InputError(f"{name} must be a nonzero vector, got {a.tolist()}")
    return a / n


def check_stiffness(stiffness) -> float | None:
    """A workpiece's normal stiffness (N/mm) as a float, None (rigid) kept; anything but a
    finite positive number is refused."""
    if stiffness is None:
        return None
    try:
        k = float(stiffness)
    except (TypeError, ValueError):
        k = math.nan
    if not (math.isfinite(k) and k > 0.0):
        raise InputError(f"workpiece stiffness must be a finite number of N/mm > 0 (or none "
                         f"for a rigid workpiece), got {stiffness!r}")
    return k


@dataclass(frozen=True, eq=False)
class Workpiece:
    """A planar workpiece: a plane through ``point`` with unit ``normal`` pointing out of
    the material (towards the tool), fixed frame; Coulomb ``friction`` coefficient μ ≥ 0
    (0: frictionless); normal ``stiffness`` k in N/mm (None: rigid), the tip then sinks
    ``f_n / k`` into it."""

    point: np.ndarray
    normal: np.ndarray
    friction: float = 0.0
    stiffness: float | None = None

    def __post_init__(self) -> None:
        p = as_array(self.point, shape_tail=(3,), name="workpiece point")
        if p.shape != (3,):
            raise InputError(f"workpiece point must be 3 numbers, got shape {p.shape}")
        object.__setattr__(self, "point", frozen(p, float))
        object.__setattr__(self, "normal", frozen(_unit(self.normal, "workpiece normal"), float))
        mu = float(self.friction)
        if not (math.isfinite(mu) and mu >= 0.0):
            raise InputError(f"friction coefficient must be a finite number >= 0, got "
                             f"{self.friction!r}")
        object.__setattr__(self, "friction", mu)
        object.__setattr__(self, "stiffness", check_stiffness(self.stiffness))

    @property
    def compliance(self) -> float:
        """``1 / stiffness`` (mm/N), 0 for a rigid workpiece."""
        return 0.0 if self.stiffness is None else 1.0 / self.stiffness

    def gap(self, points) -> np.ndarray:
        """Signed distance of points (..., 3) from the plane; negative means behind it."""
        return np.einsum("...i,i->...", np.asarray(points, dtype=float) - self.point,
                         self.normal)


@dataclass(frozen=True, eq=False)
class Cell:
    """The simulated cell's geometry (immutable).

    Attributes:
        platform: the compliant platform.
        mount: (4, 4) the platform's base frame in frame 6.
        tool_tip: (3,) the tool tip in the top frame.
        workpiece: the planar workpiece.
        stroke: largest leg deflection the legs take (mm), see :data:`DEFAULT_STROKE`.
        leg_law: a non-linear true leg law (a calibration whose maps compose to the tension as
            a function of length); None: the platform's linear springs. See :func:`make_cell`.
    """

    platform: Platform
    mount: np.ndarray
    tool_tip: np.ndarray
    workpiece: Workpiece
    stroke: float = DEFAULT_STROKE
    leg_law: LegCalibration | None = None

    def __post_init__(self) -> None:
        M = as_array(self.mount, shape_tail=(4, 4), name="mount")
        if M.shape != (4, 4):
            raise ModelError(f"mount must be one 4x4 transform, got shape {M.shape}")
        R = M[:3, :3]
        if (np.max(np.abs(R @ R.T - np.eye(3))) > 1e-9 or abs(np.linalg.det(R) - 1.0) > 1e-9
                or np.any(M[3] != [0.0, 0.0, 0.0, 1.0])):
            raise ModelError("mount must be a rigid transform (orthonormal rotation, last row "
                             "0 0 0 1)")
        object.__setattr__(self, "mount", frozen(M, float))
        tip = as_array(self.tool_tip, shape_tail=(3,), name="tool tip")
        if tip.shape != (3,):
            raise ModelError(f"tool tip must be 3 numbers, got shape {tip.shape}")
        object.__setattr__(self, "tool_tip", frozen(tip, float))
        s = float(self.stroke)
        if not (math.isfinite(s) and s > 0):
            raise ModelError(f"leg stroke must be a positive number of mm, got {self.stroke!r}")
        object.__setattr__(self, "stroke", s)

    @property
    def tool_point_6(self) -> np.ndarray:
        """The unloaded tool tip in frame 6 (the thesis's ``P_tool_6``)."""
        return apply(self.mount @ self.platform.home_pose, self.tool_tip)


def _base_corner_centroid(platform: Platform) -> np.ndarray:
    layout = platform.layout
    if layout is not None:
        corners = platform.base_points[list(layout.order[:3])]
        return corners.mean(axis=0)
    return platform.base_points.mean(axis=0)


def centred_mount(platform: Platform, *, offset: float = 0.0, turn: float = 0.0) -> np.ndarray:
    """``6_BT`` with the base triangle's centroid on frame 6's z axis (S6).

    The base plane is frame 6's x-y plane shifted by ``offset`` mm along S6; the base x axis is
    a67 (frame 6's x axis) turned by ``turn`` radians about S6. For the special 6-6 prototype
    the top's unloaded axis is then S6 itself.
    """
    for v, nm in ((offset, "offset"), (turn, "turn")):
        if not math.isfinite(float(v)):
            raise InputError(f"mount {nm} must be finite, got {v!r}")
    c = _base_corner_centroid(platform)
    R = Rotation.from_rotvec([0.0, 0.0, float(turn)]).as_matrix()
    # 6_B T maps base coordinates to frame 6: the centroid c goes to (0, 0, offset).
    return make_pose(R, np.array([0.0, 0.0, float(offset)]) - R @ c)


def make_cell(
    platform: Platform,
    *,
    plane_point,
    plane_normal,
    friction: float = 0.0,
    stiffness: float | None = None,
    mount=None,
    tool_point_6=DEFAULT_TOOL_POINT_6,
    tool_tip=None,
    stroke: float = DEFAULT_STROKE,
    legs: LegCalibration | None = None,
) -> Cell:
    """Assemble a :class:`Cell`.

    ``mount`` defaults to :func:`centred_mount`. The tool tip is ``tool_tip`` (top frame) if
    given, else the point of the top that sits at ``tool_point_6`` (frame 6) when the platform
    is unloaded — by default the thesis's (0, 0, 235) mm.

    ``legs``: the legs' TRUE law, a calibration (counts → length, counts → tension); the
    platform's springs are replaced by it (free lengths where it reads no force, unloaded home
    pose there: :func:`kinestat.hardware.leg_law.calibrated_platform`), and a non-linear law
    is kept as :attr:`Cell.leg_law` so that the equilibrium uses it exactly.
    """
    if legs is not None:
        platform = calibrated_platform(platform, legs)
        nonlinear = legs.force_coeffs.shape[1] > 2 or legs.length_coeffs.shape[1] > 2
    M = centred_mount(platform) if mount is None else as_array(mount, shape_tail=(4, 4),
                                                                  name="mount")
    if tool_tip is None:
        p6 = as_array(tool_point_6, shape_tail=(3,), name="tool_point_6")
        tip = apply(inv(M @ platform.home_pose), p6)
    else:
        tip = tool_tip
    return Cell(platform=platform, mount=M, tool_tip=tip,
                workpiece=Workpiece(plane_point, plane_normal, friction, stiffness),
                stroke=stroke,
                leg_law=legs if legs is not None and nonlinear else None)


def _springs(cell: Cell, X: np.ndarray) -> Platform:
    """The platform whose linear springs agree with the true legs at pose ``X`` in force and
    slope (the platform itself when the legs are linear): its ``spring_wrench`` and
    ``stiffness`` are then exact for a non-linear :attr:`Cell.leg_law`."""
    plat = cell.platform
    if cell.leg_law is None:
        return plat
    L = leg_lengths(plat, X)
    f = tensions_at_lengths(cell.leg_law, L, plat.leg_names)
    k = tension_slopes(cell.leg_law, L, plat.leg_names)
    if np.any(~np.isfinite(k)) or np.any(k <= 0):
        raise UnreachableError(f"simulated cell: the true leg law has a non-positive slope "
                               f"({np.round(k, 4).tolist()} N/mm) at leg lengths "
                               f"{np.round(L, 3).tolist()}")
    return replace(plat, stiffness=k, free_lengths=L - f / k)


@dataclass(frozen=True, eq=False)
class Equilibrium:
    """The solved state of the cell at one flange pose.

    Attributes:
        flange_pose: (4, 4) ``F_6T``.
        top_pose: (4, 4) the top frame in the base frame.
        leg_lengths: (6,) true leg lengths (mm), the platform's leg order.
        in_contact: the tip touches the workpiece.
        sticking: with friction, the tip is stuck at ``anchor``; False when frictionless or
            sliding.
        contact_force: (3,) force of the workpiece on the tool, fixed frame (N).
        tool_force: (3,) force of the tool on the workpiece (= −contact_force), fixed frame.
        tip: (3,) the tool tip, fixed frame.
        anchor: (3,) | None the friction anchor (fixed frame) to pass to the next solve.
        residual: largest wrench residual of the equilibrium (N, N·mm).
        iterations: Newton iterations used (summed over the slip search).
    """

    flange_pose: np.ndarray
    top_pose: np.ndarray
    leg_lengths: np.ndarray
    in_contact: bool
    sticking: bool
    contact_force: np.ndarray
    tool_force: np.ndarray
    tip: np.ndarray
    anchor: np.ndarray | None
    residual: float
    iterations: int
    normal_force: float = 0.0
    extra: dict = field(default_factory=dict, repr=False)

    @property
    def base_pose(self) -> np.ndarray:
        """The platform's base frame in the fixed frame."""
        return self.extra["base_pose"]


def _displace(X: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Move a pose by the small twist ``d = [δφ; δx_O]`` (base frame): Rot(δφ)·X + δx_O."""
    R = Rotation.from_rotvec(d[:3]).as_matrix()
    out = np.empty((4, 4))
    out[:3, :3] = R @ X[:3, :3]
    out[:3, 3] = R @ X[:3, 3] + d[3:]
    out[3] = (0.0, 0.0, 0.0, 1.0)
    return out


def _check_flange(flange_pose) -> np.ndarray:
    T = as_array(flange_pose, shape_tail=(4, 4), name="flange pose")
    if T.shape != (4, 4):
        raise InputError(f"flange pose must be one 4x4 transform, got shape {T.shape}")
    R = T[:3, :3]
    if np.max(np.abs(R @ R.T - np.eye(3))) > 1e-6 or abs(np.linalg.det(R) - 1.0) > 1e-6:
        raise InputError("flange pose must be a rigid transform (orthonormal rotation)")
    return T


def unloaded_tip(cell: Cell, flange_pose) -> np.ndarray:
    """Where the tip would be with the platform unloaded (fixed frame)."""
    T = _check_flange(flange_pose)
    return apply(T @ cell.mount @ cell.platform.home_pose, cell.tool_tip)


def _frictionless_system(cell: Cell, n: np.ndarray, c: np.ndarray, X: np.ndarray, lam: float):
    """The frictionless contact's residual ``r (7,)`` and Newton matrix ``A (7, 7)`` at (X, λ)
    (base coordinates): ``r = [w(X) − λ [n; p×n]; n·(p − c) + λ/k]``."""
    cmp = cell.workpiece.compliance
    p = apply(X, cell.tool_tip)
    wc = np.concatenate([n, np.cross(p, n)])
    sp = _springs(cell, X)
    r = np.concatenate([spring_wrench(sp, X) - lam * wc, [n @ (p - c) + cmp * lam]])
    G = np.zeros((6, 6))
    G[3:, :3] = skew(n) @ skew(p)
    G[3:, 3:] = -skew(n)
    A = np.zeros((7, 7))
    A[:6, :6] = stiffness(sp, X, twist_order="axis") - lam * G
    A[:6, 6] = -wc
    A[6, :3] = np.cross(p, n)
    A[6, 3:6] = n
    A[6, 6] = cmp
    return r, A


def _solve_frictionless(cell: Cell, n: np.ndarray, c: np.ndarray, X0: np.ndarray,
                        tol: float, max_iter: int, damped: bool = False):
    """Newton on (X, λ): w(X) − λ [n; p×n] = 0, n·(p − c) + λ/k = 0 (base coordinates).

    ``damped``: each step is halved until the residual (moments over the platform's scale)
    falls — the second try when the plain Newton from the unloaded pose overshoots into a
    cycle (seen 2.8 mm into a 560 N/mm plane tilted 2.75°)."""
    plat = cell.platform
    X, lam = X0.copy(), 0.0
    it = 0
    weight = np.array([1.0, 1.0, 1.0, 1.0 / plat.scale, 1.0 / plat.scale, 1.0 / plat.scale, 1.0])
    r, A = _frictionless_system(cell, n, c, X, lam)
    while it < max_iter:
        it += 1
        d = _limit_step(np.linalg.solve(A, -r), plat.scale)
        t = 1.0
        for _ in range(20 if damped else 1):
            Xt, lt = _displace(X, t * d[:6]), lam + t * d[6]
            rt, At = _frictionless_system(cell, n, c, Xt, lt)
            if not damped or np.linalg.norm(weight * rt) < np.linalg.norm(weight * r):
                break
            t *= 0.5
        X, lam, r, A = Xt, lt, rt, At
        if np.max(np.abs(t * d[:6])) < 1e-13 * max(1.0, plat.scale):
            break
    return X, lam, float(np.max(np.abs(r[:6]))), abs(float(r[6])), it


def _stick_system(cell: Cell, X: np.ndarray, f: np.ndarray, n: np.ndarray):
    """The sticking contact's wrench residual and Newton matrix at (X, f) (base coordinates):
    ``(r (6,), q (3,), A (9, 9))`` with ``r = w(X) − [f; p×f]``, rows 0-5 of ``A`` its
    derivative in ``[δφ; δx_O; δf]`` and rows 6-8 that of the surface point under the tip,
    ``q = p(X) + (f·n/k) n`` (the tip itself on a rigid workpiece), which the anchor holds."""
    cmp = cell.workpiece.compliance
    p = apply(X, cell.tool_tip)
    sp = _springs(cell, X)
    r = spring_wrench(sp, X) - np.concatenate([f, np.cross(p, f)])
    A = np.zeros((9, 9))
    A[:6, :6] = stiffness(sp, X, twist_order="axis")
    A[3:6, :3] -= skew(f) @ skew(p)
    A[3:6, 3:6] += skew(f)
    A[:3, 6:] = -np.eye(3)
    A[3:6, 6:] = -skew(p)
    A[6:, :3] = -skew(p)
    A[6:, 3:6] = np.eye(3)
    if cmp:
        A[6:, 6:] = cmp * np.outer(n, n)
        return r, p + cmp * float(f @ n) * n, A
    return r, p, A


def _solve_stick(cell: Cell, a: np.ndarray, n: np.ndarray, X0: np.ndarray, tol: float,
                 max_iter: int):
    """Newton on (X, f): w(X) − [f; p×f] = 0, p(X) + (f·n/k) n − a = 0 (base coordinates)."""
    plat = cell.platform
    X, f = X0.copy(), np.zeros(3)
    it = 0
    while it < max_iter:
        it += 1
        r, q, A = _stick_system(cell, X, f, n)
        d = np.linalg.solve(A, -np.concatenate([r, q - a]))
        d[:6] = _limit_step(d[:6], plat.scale)
        X = _displace(X, d[:6])
        f = f + d[6:]
        if np.max(np.abs(d[:6])) < 1e-13 * max(1.0, plat.scale):
            break
    p = apply(X, cell.tool_tip)
    res = float(np.max(np.abs(spring_wrench(_springs(cell, X), X)
                              - np.concatenate([f, np.cross(p, f)]))))
    q = p + cell.workpiece.compliance * float(f @ n) * n
    return X, f, res, float(np.max(np.abs(q - a))), it


def _solve_slide(cell: Cell, a: np.ndarray, E: np.ndarray, n: np.ndarray, X0: np.ndarray,
                 f0: np.ndarray, rho0: float, phi0: float, tol: float, max_iter: int = 40):
    """The sliding contact in one Newton, on (X, f, ρ, φ) (base coordinates): the stick
    equations at the slid anchor ``a + ρ (cos φ e1 + sin φ e2)`` (``E = [e1 e2]``, the plane's
    tangent basis, 3×2) and Coulomb's law on the slip, ``f·e_i + μ (f·n) (cos φ, sin φ)_i = 0``:
    friction at the cone's edge, against the slip. The slip is kept ahead of the anchor
    (ρ > 0). Returns ``(X, f, ρ, φ, wrench residual, iterations)`` once every equation holds
    (wrench and tip to ``tol``, friction to :data:`SLIDE_CONVERGED`), else None: the caller's
    secant and 2-D Newton (one stick solve per trial anchor) take over. None early when four
    steps running would shrink the slip past half: the tangential stiffness along the slip is
    negative there (a heavily loaded top) and the rest lies millimetres on, e.g. 9.9 mm for a
    plane tilted 2° pressed 3 mm deep with μ = 0.03, beyond this Newton's reach."""
    plat = cell.platform
    mu = cell.workpiece.friction
    X, f, rho, phi = X0.copy(), np.asarray(f0, dtype=float).copy(), float(rho0), float(phi0)
    B = np.zeros((11, 11))
    clamped = 0
    for it in range(1, max_iter + 1):
        r, p, A = _stick_system(cell, X, f, n)
        u, v = np.array([math.cos(phi), math.sin(phi)]), np.array([-math.sin(phi), math.cos(phi)])
        c = E @ u
        fn = float(f @ n)
        g = E.T @ f + mu * fn * u
        res = (float(np.max(np.abs(r))), float(np.max(np.abs(p - a - rho * c))),
               float(np.max(np.abs(g))))
        if res[0] <= tol and res[1] <= tol and res[2] <= SLIDE_CONVERGED:
            return X, f, rho, phi, res[0], it
        B[:9, :9] = A
        B[6:9, 9], B[6:9, 10] = -c, -rho * (E @ v)
        B[9:, 6:9] = E.T + mu * np.outer(u, n)
        B[9:, 10] = mu * fn * v
        try:
            d = np.linalg.solve(B, -np.concatenate([r, p - a - rho * c, g]))
        except np.linalg.LinAlgError:
            return None
        if not np.all(np.isfinite(d)):
            return None
        if d[9] < -0.5 * rho:  # the slip would shrink past half, or turn back:
            clamped += 1  # a negative tangential stiffness along it, the rest far off
            if clamped > 3:
                return None
        else:
            clamped = 0
        k = max(1.0, -d[9] / (0.5 * rho), abs(d[10]) / 0.5)  # ρ at least halves; φ ≤ 0.5 rad
        d = _limit_step(d / k, plat.scale)
        X = _displace(X, d[:6])
        f, rho, phi = f + d[6:9], rho + d[9], phi + d[10]
    return None


def _limit_step(d: np.ndarray, scale: float) -> np.ndarray:
    """Damp a Newton step to at most 0.1 rad and 0.2·scale of translation."""
    k = max(1.0, float(np.linalg.norm(d[:3])) / 0.1, float(np.linalg.norm(d[3:6])) / (0.2 * scale))
    out = d.copy()
    out[:6] = d[:6] / k
    if d.shape[0] > 6:
        out[6:] = d[6:] / k
    return out


def equilibrium(
    cell: Cell,
    flange_pose,
    *,
    anchor=None,
    approach_from=None,
    tol: float = 1e-9,
    max_iter: int = 30,
    top_pose_guess=None,
) -> Equilibrium:
    """Solve the contact equilibrium of the top platform at ``flange_pose`` (``F_6T``).

    ``anchor`` is the friction anchor returned by the previous solve (None: not in sticking
    contact before). ``approach_from`` is the previous unloaded tip position (fixed frame):
    when the tip first touches, the anchor is where the segment from it to the current
    unloaded tip crosses the plane (else the projection of the unloaded tip onto the plane).

    ``top_pose_guess`` (the previous solution's ``top_pose``, base frame) is a second start
    for the frictionless Newton when the one from the unloaded pose fails: continuation
    along the robot's motion. Far from the unloaded pose (e.g. 16 mm into the workpiece along
    the thesis's direction, where the force flattens as the top turns) Newton from the
    unloaded pose misses equilibria that exist.

    Raises:
        UnreachableError: no equilibrium (Newton failed), or one that needs a leg deflection
            beyond :attr:`Cell.stroke` — the platform would bottom out.
    """
    T = _check_flange(flange_pose)
    plat = cell.platform
    wp = cell.workpiece
    TB = T @ cell.mount
    TBinv = inv(TB)
    home = plat.home_pose
    tip0 = apply(TB @ home, cell.tool_tip)
    g0 = float(wp.gap(tip0))
    extra = {"base_pose": TB}
    if g0 >= 0.0:
        return Equilibrium(flange_pose=T, top_pose=home.copy(), leg_lengths=leg_lengths(plat, home),
                           in_contact=False, sticking=False, contact_force=np.zeros(3),
                           tool_force=np.zeros(3), tip=tip0, anchor=None, residual=0.0,
                           iterations=0, normal_force=0.0, extra=extra)
    nB = apply_vector(TBinv, wp.normal)
    cB = apply(TBinv, wp.point)
    mu = wp.friction
    iters = 0
    if mu > 0.0:
        if anchor is None:
            if approach_from is not None:
                prev = as_array(approach_from, shape_tail=(3,), name="approach_from")
                gp = float(wp.gap(prev))
                s = gp / (gp - g0) if gp > 0.0 else 1.0
                a = prev + s * (tip0 - prev)
            else:
                a = tip0
            a = a - float(wp.gap(a)) * wp.normal  # exactly on the plane
        else:
            a = as_array(anchor, shape_tail=(3,), name="anchor")
            a = a - float(wp.gap(a)) * wp.normal
        sol = _stick_or_slip(cell, TB, TBinv, nB, a, home, tol, max_iter, top_pose_guess)
        if sol is not None:
            X, f_B, a_new, sticking, res, iters = sol
            fF = apply_vector(TB, f_B)
            return _finish(cell, T, X, fF, a_new, sticking, res, iters, extra)
        # the sticking solution would pull: contact released, fall back to frictionless
    X, lam, res, gap, it = _solve_frictionless(cell, nB, cB, home, tol, max_iter)
    iters += it
    if not (res <= tol and gap <= tol) and top_pose_guess is not None:
        guess = np.asarray(top_pose_guess, dtype=float)
        X, lam, res, gap, it = _solve_frictionless(cell, nB, cB, guess, tol, max_iter)
        iters += it
    if not (res <= tol and gap <= tol):
        X, lam, res, gap, it = _solve_frictionless(cell, nB, cB, home, tol, max_iter, True)
        iters += it
    if not (res <= tol and gap <= tol):
        raise UnreachableError(
            f"simulated cell: no frictionless contact equilibrium found (wrench residual "
            f"{res:.3g}, gap {gap:.3g} mm after {it} Newton steps); the tool is pushed too far "
            "into the workpiece")
    if lam < 0.0:
        raise UnreachableError(f"simulated cell: contact equilibrium needs a pulling contact "
                               f"force ({lam:.6g} N); not a valid unilateral contact")
    fF = lam * wp.normal
    a_new = (apply(TB, apply(X, cell.tool_tip)) + wp.compliance * lam * wp.normal
             if mu > 0.0 else None)
    return _finish(cell, T, X, fF, a_new, False, res, iters, extra)


def _finish(cell: Cell, T, X, contact_force_F, anchor, sticking, res, iters, extra
            ) -> Equilibrium:
    plat = cell.platform
    L = leg_lengths(plat, X)
    defl = L - plat.free_lengths
    worst = int(np.argmax(np.abs(defl)))
    if abs(defl[worst]) > cell.stroke:
        raise UnreachableError(
            f"simulated cell: leg {plat.leg_names[worst]} would deflect {defl[worst]:+.3f} mm, "
            f"beyond the legs' stroke of ±{cell.stroke:g} mm: the platform bottoms out (contact "
            f"force {np.linalg.norm(contact_force_F):.3f} N); the tool was pushed too far")
    TB = extra["base_pose"]
    tip = apply(TB @ X, cell.tool_tip)
    fn = float(contact_force_F @ cell.workpiece.normal)
    return Equilibrium(flange_pose=T, top_pose=X, leg_lengths=L, in_contact=True,
                       sticking=bool(sticking), contact_force=np.asarray(contact_force_F),
                       tool_force=-np.asarray(contact_force_F), tip=tip, anchor=anchor,
                       residual=float(res), iterations=int(iters), normal_force=fn, extra=extra)


def _slide_by_secant(resid, u: np.ndarray, s0: float, X: np.ndarray, stuck: tuple):
    """The sliding contact's search when the one Newton of :func:`_solve_slide` fails: a 1-D
    secant for the slip along ``u`` (against the stuck tangential force) from ``s0`` mm, a 2-D
    Newton from there, and the damped Newton if that wanders; each trial anchor is one stick
    solve, ``resid(d2, X)`` (see :func:`_stick_or_slip`). ``X`` and ``stuck = (f, f_F,
    residual, f_n)`` are the stuck solution's. Returns ``(r, d2, X, f, f_F, residual, f_n)``
    of the best slide found."""
    # 1-D secant along u for |f_t| = μ f_n, starting from the stiffness-based guess
    def g1(s, Xg):
        r, Xs, fs, fFs, rs, fns = resid(s * u, Xg)
        return float(r @ u), Xs

    s1 = s0
    Xb = X  # the damped Newton's start if the secant fails at once
    try:
        ga, Xa = g1(s0, X)
        s1 = s0 * 1.5
        gb, Xb = g1(s1, Xa)
        for _ in range(60):
            if abs(gb - ga) < 1e-300:
                break
            s2 = s1 - gb * (s1 - s0) / (gb - ga)
            s2 = max(s2, 1e-9)
            s0, ga, Xa = s1, gb, Xb
            s1 = s2
            gb, Xb = g1(s1, Xa)
            if abs(gb) < 1e-11 or abs(s1 - s0) < 1e-13:
                break
        d2 = s1 * u
        Xg = Xb
        # 2-D Newton with a finite-difference Jacobian
        for _ in range(30):
            r, Xs, fs, fFs, rs, fns = resid(d2, Xg)
            if np.max(np.abs(r)) <= 1e-10:
                break
            J = fd_jacobian(resid, d2, Xs, r)
            d2 = d2 - np.linalg.solve(J, r)
            Xg = Xs
        r, Xs, fs, fFs, rs, fns = resid(d2, Xg)
        wandered = not np.max(np.abs(r)) <= SLIDE_TOL
    except (UnreachableError, np.linalg.LinAlgError):
        # a step took the anchor metres away, where no sticking equilibrium exists (seen on
        # a cylinder with friction 0.3: an anchor 15 m off): the damped Newton instead
        wandered, r, d2 = True, np.full(2, np.inf), np.zeros(2)
        fs, fFs, rs, fns = stuck
        Xs = X
    if wandered:  # the plain Newton wandered off: damped instead
        try:
            d2b, Xgb = damped_slide(resid, s1 * u, Xb, SLIDE_CONVERGED)
            rb = resid(d2b, Xgb)
        except UnreachableError:  # not even the secant's point: the snap below
            rb = (np.full(2, np.inf),)
        if np.max(np.abs(rb[0])) < np.max(np.abs(r)):
            d2, Xg = d2b, Xgb
            r, Xs, fs, fFs, rs, fns = rb
    return r, d2, Xs, fs, fFs, rs, fns


def _stick_or_slip(cell: Cell, TB, TBinv, nB, a_F, home, tol, max_iter, guess=None):
    """Sticking at ``a_F`` if friction allows, else quasi-static slip; None if it would pull.
    The sticking solve starts from ``home``, then from ``guess`` (the previous solution's top
    pose: continuation) if that fails.

    Returns (X, f_B, anchor_F, sticking, residual, iterations)."""
    mu = cell.workpiece.friction
    nF = cell.workpiece.normal
    # tangent basis of the plane (fixed frame)
    e1 = np.cross(nF, [1.0, 0.0, 0.0])
    if np.linalg.norm(e1) < 0.5:
        e1 = np.cross(nF, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(nF, e1)
    iters = 0

    def stick(aF, X0):
        nonlocal iters
        X, f, res, perr, it = _solve_stick(cell, apply(TBinv, aF), nB, X0, tol, max_iter)
        iters += it
        if not (res <= tol and perr <= tol):
            raise UnreachableError(
                f"simulated cell: no sticking contact equilibrium found (wrench residual "
                f"{res:.3g}, tip error {perr:.3g} mm after {it} Newton steps)")
        fF = apply_vector(TB, f)
        return X, f, fF, res

    try:
        X, f, fF, res = stick(a_F, home)
    except UnreachableError:
        if guess is None:
            raise
        X, f, fF, res = stick(a_F, np.asarray(guess, dtype=float))
    fn = float(fF @ nF)
    if fn < 0.0:
        return None
    ft = fF - fn * nF
    if np.linalg.norm(ft) <= mu * fn * (1.0 + 1e-12):
        return X, f, a_F, True, res, iters

    # Slip: find d (in the plane) with f_t(a + d) = −μ f_n d/|d|, starting along −f_t.
    def resid(d2, Xg):
        aF = a_F + d2[0] * e1 + d2[1] * e2
        Xs, fs, fFs, rs = stick(aF, Xg)
        fns = float(fFs @ nF)
        fts = np.array([fFs @ e1, fFs @ e2])
        nd = float(np.hypot(*d2))
        return fts + mu * fns * d2 / nd, Xs, fs, fFs, rs, fns

    u = -np.array([ft @ e1, ft @ e2])
    u /= np.linalg.norm(u)
    s0 = (np.linalg.norm(ft) - mu * fn) / 2.0  # ~N per (N/mm): a first guess in mm
    s0 = max(min(s0, 5.0), 1e-3)
    E = np.column_stack([apply_vector(TBinv, e1), apply_vector(TBinv, e2)])
    sl = None
    for k in _SLIDE_STARTS:  # further out where the slip first runs on
        sl = _solve_slide(cell, apply(TBinv, a_F), E, nB, X, f, k * s0,
                          math.atan2(u[1], u[0]), tol)
        if sl is not None:
            break
    if sl is not None:  # one Newton on the whole slide
        Xs, fs, rho, phi, rs, it = sl
        iters += it
        d2 = rho * np.array([math.cos(phi), math.sin(phi)])
        fFs = apply_vector(TB, fs)
        fns = float(fFs @ nF)
        r = np.array([fFs @ e1, fFs @ e2]) + mu * fns * d2 / rho
    else:  # the slower search, one stick solve per trial anchor
        r, d2, Xs, fs, fFs, rs, fns = _slide_by_secant(resid, u, s0, X, (f, fF, res, fn))
    if fns < 0.0:
        return None
    ft_s = fFs - fns * nF
    # within the cone up to the accepted residual (|f_t| ≤ μ f_n + |r| when r is the residual)
    if not (np.max(np.abs(r)) <= SLIDE_TOL
            and np.linalg.norm(ft_s) <= mu * fns * (1.0 + 1e-6) + np.hypot(*r)):
        def tangential(d, Xq):  # (f_t in the plane's basis, f_n, X) at the anchor a_F + d
            Xq, _, fq, _ = stick(a_F + d[0] * e1 + d[1] * e2, Xq)
            return np.array([fq @ e1, fq @ e2]), float(fq @ nF), Xq

        snap = snap_slide(tangential, mu, X)
        if snap is not None:  # no root near the anchor: the tip snaps on and sticks again
            aF = a_F + snap[0][0] * e1 + snap[0][1] * e2
            Xs, fs, _, rs = stick(aF, snap[1])
            return Xs, fs, aF, True, rs, iters
        raise UnreachableError(
            f"simulated cell: the sliding contact did not settle (friction residual "
            f"{np.max(np.abs(r)):.3g} N)")
    aF = a_F + d2[0] * e1 + d2[1] * e2
    return Xs, fs, aF, False, rs, iters
