"""Curved workpieces for the simulated cell: a cylinder beside the plane of
:mod:`kinestat.sim.contact`.

The tool touches the workpiece at one point, so the contact only sees the surface's tangent
plane there. :func:`solve` therefore reuses the plane's contact equilibrium
(:func:`kinestat.sim.contact.equilibrium`, frictionless or Coulomb stick/slip) on the tangent
plane at the surface point nearest the tip, and repeats with the tangent plane at the new tip
until the tip lies on the surface (a fixed point: the tip on the tangent plane at its own
projection IS on the surface, and the contact force is along the true normal there). A
compliant cylinder (``stiffness`` k, N/mm) lets the tip sink ``f_n / k`` along that normal:
the same fixed point, the tip on the normal through its own projection. Each
repetition moves the contact point by about (deflection / radius) of the last change, so two
to four passes reach 1e-10 mm. A slide whose passes alternate between two tips, neither a rest
on its own tangent plane, is solved again from the farther one (:data:`_BRANCH_PASSES`).
A plane workpiece goes straight to the plane's equilibrium,
bit-identical to calling it directly.

Frames and senses are those of :mod:`kinestat.sim.contact` (mm, N, fixed frame; the normal
points out of the material, towards the tool).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from kinestat.errors import InputError, UnreachableError
from kinestat.sim.contact import (
    Cell,
    Equilibrium,
    Workpiece,
    check_stiffness,
    equilibrium,
    unloaded_tip,
)
from kinestat.spatial.transforms import as_array
from kinestat.spatial.validate import frozen

__all__ = ["Cylinder", "solve", "surface_normal", "cylinder_ahead", "approach_distance"]

_FIXED_POINT_TOL = 1e-10  # mm: the contact point has settled on the surface
_FIXED_POINT_ITER = 60
_FIXED_POINT_ACCEPT = 1e-3  # mm: the best pass is taken when the passes stall below this
_SLIDE_SETTLE = _FIXED_POINT_ACCEPT
"""A sliding contact point has settled on the cylinder once a pass moves it by at most this
(mm). The plane's sliding solve accepts a force residual up to
:data:`kinestat.sim.contact.SLIDE_TOL` (1e-3 N, ~0.02 mm of tip through the top's tangential
stiffness), so passes on a sliding contact cannot settle to ``_FIXED_POINT_TOL``: near the
stick-slip boundary they wander at 1e-5 to 3e-4 mm for all 60 passes, 5 s of solving, during
which the simulated encoder box (a thread sharing the solver's process) sent nothing and the
controller stopped on stale data (2026-12-02, ``kinestat control --task follow`` on the
R = 200 mm cylinder with friction 0.3, 1 run in 4). 1e-3 mm along a cylinder of radius R
turns the normal by 1e-3/R rad (5e-6 rad at 200 mm), invisible in a count (0.0254 mm)."""


def _vec3(v, name: str) -> np.ndarray:
    a = as_array(v, shape_tail=(3,), name=name)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise InputError(f"{name} must be 3 finite numbers, got {np.asarray(v).tolist()}")
    return a


@dataclass(frozen=True, eq=False)
class Cylinder:
    """A solid cylinder: axis through ``point`` along unit ``axis``, ``radius`` mm; the
    tool touches its outside (the normal points radially out). Coulomb ``friction`` μ ≥ 0;
    normal ``stiffness`` k in N/mm (None: rigid), the tip then sinks ``f_n / k`` into it.

    >>> c = Cylinder(point=[0, 0, 0], axis=[0, 0, 1], radius=200.0)
    >>> float(c.gap([250.0, 0.0, 5.0])), c.normal_at([250.0, 0.0, 5.0]).tolist()
    (50.0, [1.0, 0.0, 0.0])
    """

    point: np.ndarray
    axis: np.ndarray
    radius: float
    friction: float = 0.0
    stiffness: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", frozen(_vec3(self.point, "cylinder point"), float))
        a = _vec3(self.axis, "cylinder axis")
        n = float(np.linalg.norm(a))
        if n < 1e-12:
            raise InputError("cylinder axis must be a nonzero vector")
        object.__setattr__(self, "axis", frozen(a / n, float))
        r = float(self.radius)
        if not (math.isfinite(r) and r > 0):
            raise InputError(f"cylinder radius must be a positive number of mm, got "
                             f"{self.radius!r}")
        object.__setattr__(self, "radius", r)
        mu = float(self.friction)
        if not (math.isfinite(mu) and mu >= 0.0):
            raise InputError(f"friction coefficient must be a finite number >= 0, got "
                             f"{self.friction!r}")
        object.__setattr__(self, "friction", mu)
        object.__setattr__(self, "stiffness", check_stiffness(self.stiffness))

    def _radial(self, points) -> np.ndarray:
        d = np.asarray(points, dtype=float) - self.point
        return d - np.einsum("...i,i->...", d, self.axis)[..., None] * self.axis

    def gap(self, points) -> np.ndarray:
        """Signed distance of points (..., 3) from the surface; negative inside the material."""
        return np.linalg.norm(self._radial(points), axis=-1) - self.radius

    def normal_at(self, point) -> np.ndarray:
        """The outward unit normal of the surface nearest ``point`` (3,)."""
        r = self._radial(point)
        n = float(np.linalg.norm(r))
        if n < 1e-9:
            raise UnreachableError("simulated cell: the tool tip is on the cylinder's axis; "
                                   "the contact normal is undefined")
        return r / n

    def project(self, point) -> np.ndarray:
        """The surface point nearest ``point``."""
        p = np.asarray(point, dtype=float)
        return p - float(self.gap(p)) * self.normal_at(p)

    def tangent_plane(self, point) -> Workpiece:
        """The tangent plane (a plane :class:`~kinestat.sim.contact.Workpiece` with the same
        friction and stiffness) at the surface point nearest ``point``."""
        return Workpiece(self.project(point), self.normal_at(point), self.friction,
                         self.stiffness)


def cylinder_ahead(start_point, direction, distance: float, radius: float, axis) -> Cylinder:
    """The cylinder whose surface is ``distance`` mm ahead of ``start_point`` along
    ``direction`` (placed like the default plane): its axis is ``radius`` further on, along the
    part of ``direction`` perpendicular to ``axis``."""
    d = _vec3(direction, "direction")
    a = _vec3(axis, "cylinder axis")
    for v, name in ((d, "direction"), (a, "cylinder axis")):
        if not np.linalg.norm(v) > 0.0:
            raise InputError(f"{name} must be a nonzero vector, got {v.tolist()}")
    d = d / np.linalg.norm(d)
    a = a / np.linalg.norm(a)
    u = d - (d @ a) * a
    if np.linalg.norm(u) < 1e-6:
        raise InputError("the cylinder's axis is along the force direction: the tool would "
                         "meet its end, not its curved surface")
    u /= np.linalg.norm(u)
    c0 = np.asarray(start_point, dtype=float) + distance * d
    return Cylinder(point=c0 + float(radius) * u, axis=a, radius=radius)

def approach_distance(workpiece, start_point, direction) -> float:
    """How far (mm) a point moving from ``start_point`` along ``direction`` goes before it
    meets the surface of a plane or cylinder ``workpiece``: 0 when it starts on or inside the
    material, ``inf`` when the line never meets the surface ahead.

    >>> c = Cylinder(point=[0, 0, 0], axis=[0, 0, 1], radius=200.0)
    >>> approach_distance(c, [-250.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    50.0
    >>> approach_distance(c, [-250.0, 0.0, 0.0], [0.0, 0.0, 1.0])   # along the axis
    inf
    >>> approach_distance(Workpiece([0, 0, 0], [0, 0, 1]), [0, 0, 5.0], [0, 0.6, -0.8])
    6.25
    """
    p = _vec3(start_point, "start point")
    d = _vec3(direction, "direction")
    nd = float(np.linalg.norm(d))
    if not nd > 0.0:
        raise InputError(f"direction must be a nonzero vector, got {d.tolist()}")
    d = d / nd
    gap = float(workpiece.gap(p))
    if gap <= 0.0:
        return 0.0
    if isinstance(workpiece, Workpiece):
        rate = float(d @ workpiece.normal)
        return gap / -rate if rate < 0.0 else math.inf
    r0 = workpiece._radial(p)
    u = d - float(d @ workpiece.axis) * workpiece.axis
    a = float(u @ u)
    b = float(r0 @ u)
    c = float(r0 @ r0) - workpiece.radius ** 2
    disc = b * b - a * c
    if a < 1e-18 or disc < 0.0 or b >= 0.0:  # parallel to the axis, missing, or moving away
        return math.inf
    return (-b - math.sqrt(disc)) / a


_BRANCH_PASSES = 10
"""Passes after which a slide that has not settled, and whose last four passes did not halve
its least move, restarts from the farthest tip it reached.
A slide can have two rests on neighbouring tangent planes and none on its own: the slip search
on the plane at tip A stops at B (no rest before it), and on the plane at B it stops at A, a
rest that plane's 0.2° tilt makes and the surface at A does not have; the passes then alternate
between A and B for good (seed 29 of the follow study, R = 205 mm, friction 0.3: 0.18 and
0.86 mm from the anchor, 2026-12-02). The slip went past A, where the surface holds no rest, so
the tip is solved again from B: it sticks there or slides on, and the passes settle."""


def surface_normal(workpiece, point) -> np.ndarray:
    """The outward normal of a plane or cylinder workpiece at (the surface point nearest)
    ``point``."""
    if isinstance(workpiece, Workpiece):
        return np.asarray(workpiece.normal, dtype=float).copy()
    return workpiece.normal_at(point)


def solve(cell: Cell, flange_pose, *, anchor=None, approach_from=None,
          top_pose_guess=None) -> Equilibrium:
    """Contact equilibrium of ``cell`` at ``flange_pose`` for a plane or a cylinder workpiece.

    A plane: :func:`kinestat.sim.contact.equilibrium` itself. A cylinder: the plane's
    equilibrium on the tangent plane at the contact point, repeated until the tip lies on the
    cylinder (module docstring). ``anchor``/``approach_from``/``top_pose_guess`` (the previous
    solution, for continuation along the robot's motion) as for the plane.
    """
    wp = cell.workpiece
    if isinstance(wp, Workpiece):
        return equilibrium(cell, flange_pose, anchor=anchor, approach_from=approach_from,
                           top_pose_guess=top_pose_guess)
    q = unloaded_tip(cell, flange_pose) if anchor is None else np.asarray(anchor, dtype=float)
    hist: list[float] = []
    prev = None
    best = None
    slides: list[Equilibrium] = []
    for k in range(_FIXED_POINT_ITER):
        if (k == _BRANCH_PASSES and anchor is not None and slides
                and min(hist[-4:]) > 0.5 * min(hist[:-4])):
            # no fixed point on this slide: restart it from its farthest tip (docstring above)
            far = max(slides, key=lambda e: float(np.linalg.norm(e.tip - anchor)))
            anchor = q = wp.project(far.tip)
            prev = None
        plane = wp.tangent_plane(q)
        eq = equilibrium(replace(cell, workpiece=plane), flange_pose, anchor=anchor,
                         approach_from=approach_from, top_pose_guess=top_pose_guess)
        if not eq.in_contact:
            return eq
        hist.append(float(np.linalg.norm(wp.project(eq.tip) - plane.point)))
        if eq.anchor is not None:
            eq = replace(eq, anchor=wp.project(eq.anchor))
        sliding = plane.friction > 0.0 and not eq.sticking
        if sliding:
            slides.append(eq)
        if hist[-1] <= (_SLIDE_SETTLE if sliding else _FIXED_POINT_TOL):
            return eq
        if best is None or hist[-1] < best[0]:
            best = (hist[-1], eq)
        d = eq.tip - q
        if prev is None:  # a plain pass, then an Aitken-extrapolated one (linear contraction)
            q, prev = eq.tip, d
        else:
            r = min(max(float(d @ prev) / max(float(prev @ prev), 1e-300), -0.9), 0.95)
            q, prev = q + d / (1.0 - r), None
    if best is not None and best[0] <= _FIXED_POINT_ACCEPT:
        # the passes stall where the sliding solve's accepted residual (contact.SLIDE_TOL)
        # leaves the tip: ~1e-4 mm on one R = 282 mm cylinder with friction 0.3, far below a
        # robot count or the sensor's resolution; the closest pass is the equilibrium
        return best[1]
    raise UnreachableError(f"simulated cell: the contact point on the cylinder did not settle "
                           f"after {_FIXED_POINT_ITER} tangent-plane passes {hist}")
