"""Hand paths of Nadkarni's four analysis types and the twist B of each step (ch. IV).

A path is pure geometry: the ideal hand pose at every fraction ``s ∈ [0, 1]`` of the motion
(:meth:`pose_at`) plus the rule the thesis uses to build the small hand displacement B of a
step (:meth:`step_twist`, the right-hand side of eq. 4-11). The runner (:mod:`.run`) chooses
the step count k and calls them with ``s = j/k``.

=========  ============  =====================================================================
type       DISP (MS)     path and step twist
=========  ============  =====================================================================
II         DISPM (0)     screw path: fixed screw axis through ρn, ``B = [δθU; hδθU − δθU×ρn]``
                         constant for all k steps (eqs. 4-18, 4-19; Pieper's iterative
                         velocity method) — :func:`screw_path`
III        SPLITM (4)    the three hand points move on straight lines split in k equal parts;
                         each step screws the hand from where it is to the next split position
                         (eq. 4-20) — :func:`line_path`
IV         GUIDM (5)     operator command R, d, θ (global frame or hand frame, R = Q'R'):
                         ``U = R/|R|``, ``δθ = θ/k``, ``h = d/θ``, ``ρn = ρo`` the hand origin
                         at the start of the command (eqs. 4-21, 4-22) — :func:`command_path`
I          GENM (6)      rotation δθ about a fixed direction u_ω through the *current* hand
                         origin O_H plus δr along u_v: ``B = [δθu_ω; δr u_v − δθu_ω×ρo]``
                         (eq. 4-11a); Ex. 4 (eq. 4-17): u_ω = screw axis U of the whole
                         displacement, u_v = R/|R| (R = O_H1→O_H2) — :func:`general_path`,
                         Ex. 1–3 — :func:`general_motion`
=========  ============  =====================================================================

DISP with MS = 6 plans from the actual hand at every step (ρo = the current O_H), as the thesis
notes ("DISP uses the actual position of the manipulator hand defined by the seventh joint ...
for any intermediate stage"); :class:`GeneralPath` does the same.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from kinestat.errors import InputError
from kinestat.spatial.displacement import (
    frame_from_triple,
    screw_from_poses,
)
from kinestat.spatial.se3 import pose_error, twist_exp
from kinestat.spatial.transforms import as_array, make_pose
from kinestat.spatial.validate import as_number, as_pose

__all__ = [
    "Path",
    "StageSpec",
    "resolve_stage",
    "twist_exp",
    "twist_between",
    "pose_error",
    "ScrewPath",
    "LinePath",
    "GeneralPath",
    "screw_path",
    "line_path",
    "general_path",
    "general_motion",
    "command_path",
    "auto_steps",
    "path_extent",
]


@runtime_checkable
class Path(Protocol):
    """A hand path of analysis types I–IV: the ideal pose at every fraction ``s`` and the
    step twist B of eq. 4-11 from the actual hand pose."""

    kind: str

    @property
    def end(self) -> np.ndarray:
        """The ideal end pose ``(4, 4)``."""
        ...

    def pose_at(self, s) -> np.ndarray:
        """Ideal hand poses ``(..., 4, 4)`` at fractions ``s`` ``(...)``."""
        ...

    def step_twist(self, s0: float, s1: float, hand) -> np.ndarray:
        """B ``(6,)`` of the step from ``s0`` to ``s1`` with the hand at ``hand``."""
        ...

    def step_target(self, s0: float, s1: float, hand) -> np.ndarray:
        """The pose ``(4, 4)`` the step is meant to reach (for eq. 5-5's chord)."""
        ...

    def replan(self, hand, s_now: float) -> Path:
        """The rest of the path from ``hand`` (after a perturbation at ``s_now``)."""
        ...


#: A stage of a run: a path, or a function of the hand pose at the stage start returning one.
StageSpec = Path | Callable[[np.ndarray], Path]


def resolve_stage(spec: StageSpec, hand: np.ndarray) -> Path:
    """The path of a stage starting with the hand at ``hand`` ``(4, 4)``."""
    if isinstance(spec, Path):
        return spec
    if not callable(spec):
        raise InputError(f"a stage must be a path or a function hand pose -> path, got "
                         f"{type(spec).__name__}")
    return spec(hand)


def _pose(T, name: str) -> np.ndarray:
    return as_pose(T, name, single=True)


def twist_between(T1, T2) -> np.ndarray:
    """Twist ``ξ`` ``(..., 6)`` with ``twist_exp(ξ) @ T1 = T2``: the screw displacement of
    Nadkarni ch. III as ``[θU; hθU − θU×ρn]`` (eq. 4-19a with k = 1)."""
    return screw_from_poses(T1, T2).twist


def _rot(axis, angle) -> np.ndarray:
    from scipy.spatial.transform import Rotation  # lazy: start-up (scipy.spatial ~0.5 s)
    rv = np.asarray(axis, dtype=float) * np.asarray(angle, dtype=float)[..., None]
    flat = rv.reshape(-1, 3)
    return Rotation.from_rotvec(flat).as_matrix().reshape(rv.shape[:-1] + (3, 3))


def _s(s) -> np.ndarray:
    s = np.asarray(s, dtype=float)
    if not np.all(np.isfinite(s)):
        raise InputError("path fraction s must be finite")
    return s


class _PathEnd:
    """``end``: the ideal pose at ``s = 1``, for paths that define ``pose_at``."""

    @property
    def end(self) -> np.ndarray:
        return self.pose_at(1.0)


@dataclass(frozen=True, eq=False)
class ScrewPath(_PathEnd):
    """Screw path (analysis type II; type IV commands): ``pose_at(s) = exp(s ξ) · start``.

    ``twist`` ξ ``(6,)`` is the whole screw displacement ``[θU; hθU − θU×ρn]``; the step twist
    is the constant ``(s1 − s0) ξ`` whatever the hand's actual pose (eq. 4-19: ρn "constant
    throughout the analysis"). With ``from_actual`` a step is instead the screw from the hand's
    actual pose to the path's pose at ``s1`` (DISP, App. I: "the actual position of the
    manipulator hand ... for any intermediate stage"), so first-order errors do not add up.
    """

    start: np.ndarray
    twist: np.ndarray
    kind: str = "screw"
    from_actual: bool = False

    def pose_at(self, s) -> np.ndarray:
        s = _s(s)
        return twist_exp(s[..., None] * self.twist) @ self.start

    def step_twist(self, s0: float, s1: float, hand) -> np.ndarray:
        if self.from_actual:
            return twist_between(np.asarray(hand, dtype=float), self.pose_at(s1))
        return (s1 - s0) * self.twist

    def step_target(self, s0: float, s1: float, hand) -> np.ndarray:
        if self.from_actual:
            return self.pose_at(s1)
        return twist_exp((s1 - s0) * self.twist) @ np.asarray(hand, dtype=float)

    def replan(self, hand, s_now: float) -> ScrewPath:
        """A screw path from ``hand`` to this path's end (after a perturbation)."""
        hand = _pose(hand, "hand pose")
        return ScrewPath(hand, twist_between(hand, self.end), self.kind, self.from_actual)


@dataclass(frozen=True, eq=False)
class LinePath(_PathEnd):
    """Type III: the three hand points move on straight lines (Nadkarni eq. 4-20, SPLITM).

    ``points0``/``points1`` ``(3, 3)`` are the origin, a point on +z and a point on the +x side
    at the start and the end; ``pose_at(s)`` is the frame (eqs. 3-1 to 3-3) of the points
    ``points0 + s (points1 − points0)``. A step screws the hand from its actual pose to the next
    split position, so the hand origin stays on the straight line.
    """

    points0: np.ndarray
    points1: np.ndarray
    kind: str = "line"

    @property
    def start(self) -> np.ndarray:
        return self.pose_at(0.0)

    def points_at(self, s) -> np.ndarray:
        s = _s(s)[..., None, None]
        return self.points0 + s * (self.points1 - self.points0)

    def pose_at(self, s) -> np.ndarray:
        return frame_from_triple(self.points_at(s))

    def step_twist(self, s0: float, s1: float, hand) -> np.ndarray:
        return twist_between(np.asarray(hand, dtype=float), self.pose_at(s1))

    def step_target(self, s0: float, s1: float, hand) -> np.ndarray:
        return self.pose_at(s1)

    def replan(self, hand, s_now: float) -> LinePath:
        """The rest of the same lines, from the split position at ``s_now``."""
        return LinePath(self.points_at(s_now), self.points1, self.kind)


@dataclass(frozen=True, eq=False)
class GeneralPath(_PathEnd):
    """Type I: rotation θ about the fixed direction ``u_w`` through the moving hand origin and
    translation r of the origin along ``u_v`` (eqs. 4-9 to 4-17).

    ``pose_at(s) = [Rot(u_w, sθ) R0 , o0 + s r u_v]``. The step twist is eq. 4-11a's
    ``[δθ u_w; δr u_v − δθ u_w × ρo]`` with ρo the *current* hand origin.

    ``replan_each_step`` (Example 4, DISP's GENM, MS = 6): every step re-plans eqs. 4-16 and
    4-17 from the *actual* hand to the end pose — u_v from the actual hand origin to the
    target origin, u_w the axis of the remaining rotation — and takes 1/(steps left) of the
    remaining length and angle, so first-order errors do not accumulate.
    """

    start: np.ndarray
    u_w: np.ndarray
    theta: float
    u_v: np.ndarray
    r: float
    kind: str = "general"
    replan_each_step: bool = False

    def pose_at(self, s) -> np.ndarray:
        s = _s(s)
        R = _rot(self.u_w, s * self.theta) @ self.start[:3, :3]
        p = self.start[:3, 3] + (s * self.r)[..., None] * self.u_v
        return make_pose(R, p)

    def _step_parts(self, s0: float, s1: float, hand) -> tuple[np.ndarray, np.ndarray]:
        """(rotation vector δθ u_w, displacement δr u_v of the hand origin) of the step."""
        hand = np.asarray(hand, dtype=float)
        if not self.replan_each_step:
            ds = s1 - s0
            return ds * self.theta * self.u_w, ds * self.r * self.u_v
        left = 1.0 - s0
        frac = (s1 - s0) / left if left > 1e-15 else 1.0  # 1 / (steps left)
        end = self.end
        sc = screw_from_poses(hand, end)
        th = 0.0 if bool(sc.is_translation) else float(sc.theta)
        return frac * th * np.asarray(sc.axis, dtype=float), frac * (end[:3, 3] - hand[:3, 3])

    def step_twist(self, s0: float, s1: float, hand) -> np.ndarray:
        """Eq. 4-11a: ``[δθ u_w; δr u_v − δθ u_w × ρo]`` with ρo the actual hand origin."""
        w, dr = self._step_parts(s0, s1, hand)
        o = np.asarray(hand, dtype=float)[:3, 3]
        return np.concatenate([w, dr - np.cross(w, o)])

    def step_target(self, s0: float, s1: float, hand) -> np.ndarray:
        w, dr = self._step_parts(s0, s1, hand)
        hand = np.asarray(hand, dtype=float)
        th = float(np.linalg.norm(w))
        R = _rot(w / th, th) @ hand[:3, :3] if th > 0 else hand[:3, :3]
        return make_pose(R, hand[:3, 3] + dr)

    def replan(self, hand, s_now: float) -> GeneralPath:
        """Example 4 from ``hand`` to this path's end (after a perturbation)."""
        return general_path(hand, self.end)


def screw_path(start, target, *, from_actual: bool = False) -> ScrewPath:
    """Type II (eqs. 4-18, 4-19): the screw displacement from ``start`` to ``target``
    (``from_actual``: each step aims from the actual hand at the next path pose, as DISP).

    >>> from kinestat.spatial.transforms import trans
    >>> p = screw_path(np.eye(4), trans([0.0, 0.0, 4.0]))
    >>> p.step_twist(0.0, 0.25, np.eye(4)).tolist()      # constant B = ξ/k (eq. 4-19)
    [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    """
    start = _pose(start, "start pose")
    target = _pose(target, "target pose")
    return ScrewPath(start, twist_between(start, target), from_actual=from_actual)


def line_path(points0, points1) -> LinePath:
    """Type III (eq. 4-20): straight lines of the three hand points ``(3, 3)`` each (rows:
    origin, point on +z, point on the +x side). Every split position must fix a frame.

    >>> P0 = np.array([[0.0, 0, 0], [0, 0, 1], [1, 0, 0]])
    >>> line_path(P0, P0 + [2.0, 0, 0]).pose_at(0.5)[:3, 3].tolist()
    [1.0, 0.0, 0.0]
    """
    P0 = as_array(points0, shape_tail=(3, 3), name="start points")
    P1 = as_array(points1, shape_tail=(3, 3), name="target points")
    if P0.shape != (3, 3) or P1.shape != (3, 3):
        raise InputError("line_path takes two sets of three points, shape (3, 3) each")
    path = LinePath(P0, P1)
    frame_from_triple(path.points_at(np.linspace(0.0, 1.0, 65)))  # raises on degeneracy
    return path


def general_motion(start, axis, angle: float, direction, distance: float) -> GeneralPath:
    """Type I, Examples 1–3: rotate by ``angle`` (rad) about ``axis`` through the hand origin
    while the origin moves ``distance`` along ``direction`` (both in the global frame)."""
    start = _pose(start, "start pose")
    a = as_array(axis, shape_tail=(3,), name="rotation axis")
    v = as_array(direction, shape_tail=(3,), name="direction")
    angle = float(angle)
    distance = float(distance)
    na, nv = float(np.linalg.norm(a)), float(np.linalg.norm(v))
    if angle != 0.0 and na == 0.0:
        raise InputError("a rotation needs a nonzero axis direction")
    if distance != 0.0 and nv == 0.0:
        raise InputError("a translation needs a nonzero direction")
    u_w = a / na if na > 0 else np.zeros(3)
    u_v = v / nv if nv > 0 else np.zeros(3)
    return GeneralPath(start, u_w, angle, u_v, distance)


def general_path(start, target) -> GeneralPath:
    """Type I, Example 4 (eqs. 4-16, 4-17): ``u_ω = U`` the screw axis of start → target,
    θ its angle, ``u_v = R/|R|`` with R from the start origin to the target origin; re-planned
    from the actual hand at every step as DISP's GENM does (``replan_each_step``).

    >>> from kinestat.spatial.transforms import trans
    >>> p = general_path(np.eye(4), trans([3.0, 0.0, 0.0]))
    >>> (p.step_twist(0.5, 0.75, trans([1.0, 1.0, 0.0])).round(3) + 0.0).tolist()
    [0.0, 0.0, 0.0, 1.0, -0.5, 0.0]
    """
    start = _pose(start, "start pose")
    target = _pose(target, "target pose")
    sc = screw_from_poses(start, target)
    R = target[:3, 3] - start[:3, 3]
    nR = float(np.linalg.norm(R))
    u_v = R / nR if nR > 0 else np.zeros(3)
    th = 0.0 if bool(sc.is_translation) else float(sc.theta)
    return GeneralPath(start, np.asarray(sc.axis, dtype=float), th, u_v, nR,
                       replan_each_step=True)


def command_path(start, direction, distance: float, angle: float,
                 frame: str = "global") -> ScrewPath:
    """Type IV (eqs. 4-21, 4-22): an operator command from the hand pose ``start``.

    ``direction`` R (global frame, or the hand frame when ``frame="hand"``: R = Q'R'),
    ``distance`` d along it and ``angle`` θ (rad) about the line through the hand origin
    parallel to R: ``U = R/|R|``, ``h = d/θ``, ``ρn = ρo``; θ = 0 is a pure translation.

    >>> from kinestat.spatial.transforms import trans
    >>> c = command_path(trans([15.0, -25.0, 12.0]), [0, 0, 1], 4.0, 0.0)
    >>> c.end[:3, 3].tolist()                              # Illustration 6, command 1's d
    [15.0, -25.0, 16.0]
    """
    start = _pose(start, "start pose")
    R = as_array(direction, shape_tail=(3,), name="command direction")
    if frame not in ("global", "hand"):
        raise InputError(f"command frame must be 'global' or 'hand', got {frame!r}")
    nR = float(np.linalg.norm(R))
    if nR == 0.0:
        raise InputError("command direction R is the zero vector: give the direction of motion")
    distance = as_number(distance, "command distance")
    angle = as_number(angle, "command angle")
    if frame == "hand":
        R = start[:3, :3] @ R
    U = R / nR
    rho_o = start[:3, 3]
    twist = np.concatenate([angle * U, angle * np.cross(rho_o, U) + distance * U])
    return ScrewPath(start, twist, "command")


def path_extent(path, samples: int = 256) -> tuple[float, float]:
    """``(rotation in rad, length)`` travelled by the hand frame / origin along the ideal path,
    summed over ``samples`` equal parts (exact for screw and general paths in the limit)."""
    with np.errstate(over="ignore", invalid="ignore"):  # huge motions: inf, checked by callers
        P = path.pose_at(np.linspace(0.0, 1.0, samples + 1))
        dp, ang = pose_error(P[1:], P[:-1])
    return float(np.sum(ang)), float(np.sum(dp))


def auto_steps(path, length: float, *, max_step_deg: float = 1.0,
               max_step_fraction: float = 0.01, max_steps: int = 100_000) -> int:
    """DISP's IT = 0: choose the step count so that no step rotates the hand by more than
    ``max_step_deg`` nor moves its origin by more than ``max_step_fraction`` × L.

    With these defaults (1°, L/100) the neglected second-order terms of a step are of order
    ½ δθ² ℓ ≈ 1.5e-4 ℓ (ℓ a lever arm ~ L), see docs/guidance.md.

    >>> from kinestat.spatial.transforms import trans
    >>> auto_steps(screw_path(np.eye(4), trans([3.0, 0.0, 0.0])), length=10.0)
    30
    """
    rot, dist = path_extent(path)
    if not (math.isfinite(rot) and math.isfinite(dist) and math.isfinite(length)):
        raise InputError(
            f"the motion is not finite (rotation {rot:.4g} rad, distance {dist:.4g}): a "
            "distance, angle or target too large to guide")
    k = max(1, math.ceil(math.degrees(rot) / max_step_deg - 1e-9),
            math.ceil(dist / (max_step_fraction * length) - 1e-9))
    if k > max_steps:
        raise InputError(
            f"the motion needs {k} steps of at most {max_step_deg}° and "
            f"{max_step_fraction * length:.4g} length units; more than {max_steps}: give the "
            "step count explicitly or split the motion"
        )
    return k
