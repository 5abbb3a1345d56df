"""The compliant 6-6 platform model and the special 6-6 (Griffis–Duffy) builder.

A :class:`Platform` is immutable: six legs, leg ``i`` joining ``base_points[i]`` (base frame) to
``top_points[i]`` (top frame), with a linear spring of constant ``stiffness[i]`` and free length
``free_lengths[i]``, and the unloaded ``home_pose`` (top frame relative to the base frame).

The special 6-6 platform (Vibhute 2011, §2.1.1 and Figs. 2-2/2-3, after Griffis & Duffy) has
its six base points on a triangle O0 P0 Q0 and its six top points on a triangle R1 S1 T1:

* legs O, P, Q join the base corners O0, P0, Q0 to points O1, P1, Q1 on the top edges
  R1S1, S1T1, T1R1;
* legs R, S, T join points R0, S0, T0 on the base edges Q0O0, O0P0, P0Q0 to the top corners
  R1, S1, T1.

Frames (the thesis's code, Appendix B): the base frame has O0 at the origin and P0 on +x, the
base triangle in z = 0 with Q0 at y > 0; the top frame has R1 at the origin, S1 on +x and T1 at
y > 0. Poses are the top frame relative to the base frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from itertools import permutations

import numpy as np

from kinestat.errors import InputError, ModelError
from kinestat.parallel.singularity import check_design, reduction_products
from kinestat.spatial.transforms import apply, make_pose, rot_z
from kinestat.spatial.validate import as_number

__all__ = [
    "LEG_NAMES",
    "Platform",
    "SpecialDesign",
    "SpecialLayout",
    "special_6_6",
    "special_layout",
    "triangle_points",
]

#: The thesis's leg names, in the model's leg order (Appendix B, main.cpp).
LEG_NAMES: tuple[str, ...] = ("O", "P", "Q", "R", "S", "T")

# Roles of the special 6-6 layout, in canonical leg order O, P, Q, R, S, T.
# Base corners are the base points of legs O, P, Q; top corners the top points of R, S, T.
# Edge point of leg O (top) lies on R1 -> S1, etc.  (edge start corner, edge end corner).
_TOP_EDGE = {0: (3, 4), 1: (4, 5), 2: (5, 3)}  # O1 on R1S1, P1 on S1T1, Q1 on T1R1
_BASE_EDGE = {4: (0, 1), 5: (1, 2), 3: (2, 0)}  # S0 on O0P0, T0 on P0Q0, R0 on Q0O0



def _vec(value, n: int, name: str) -> np.ndarray:
    """A scalar or n numbers as a float array (n,), finite."""
    a = np.asarray(value, dtype=float)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise InputError(f"{name} must be a number or {n} numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} must be finite, got {a.tolist()}")
    return a


@dataclass(frozen=True)
class SpecialDesign:
    """Design parameters of a special 6-6 platform (what :func:`special_6_6` was given).

    Lengths in the model's unit, ``twist`` in radians. ``base_side`` is
    (|O0P0|, |P0Q0|, |Q0O0|), ``top_side`` (|R1S1|, |S1T1|, |T1R1|), ``base_offset``
    (|O0S0|, |P0T0|, |Q0R0|) and ``top_offset`` (|R1O1|, |S1P1|, |T1Q1|) — the thesis's
    ``o0s0, p0t0, q0r0, r1o1, s1p1, t1q1``.
    """

    base_side: tuple[float, float, float]
    top_side: tuple[float, float, float]
    base_offset: tuple[float, float, float]
    top_offset: tuple[float, float, float]
    height: float
    twist: float
    stiffness: tuple[float, ...]
    free_lengths: tuple[float, ...] | None = None


@dataclass(frozen=True)
class SpecialLayout:
    """How a platform's legs map onto the special 6-6 roles O, P, Q, R, S, T.

    ``order[r]`` is the model's leg index playing role ``r`` (0..5 = O..T). ``t[r]`` is the
    fraction along the edge of the edge point of role ``r``: for O, P, Q along the top edges
    R1→S1, S1→T1, T1→R1; for R, S, T along the base edges Q0→O0, O0→P0, P0→Q0.
    """

    order: tuple[int, ...]
    t: tuple[float, ...]

    @property
    def reduction_det(self) -> float:
        """Determinant of the special 6-6 → 3-3 reduction, Π(1 − t) − Π t (zero: singular)."""
        a, b = reduction_products(self.t)
        return a - b


@dataclass(frozen=True, eq=False)
class Platform:
    """An immutable 6-leg compliant platform (spring legs between two rigid bodies).

    Attributes:
        base_points: (6, 3) leg attachment points on the base, base frame.
        top_points: (6, 3) leg attachment points on the top, top frame.
        stiffness: (6,) spring constants (force unit per length unit).
        free_lengths: (6,) spring free lengths (leg lengths at which the leg force is zero).
        home_pose: (4, 4) the unloaded pose of the top frame relative to the base frame.
        leg_names: six leg names.
        name, length_unit, force_unit: labels; the numbers are in these units.
        design: the special 6-6 design parameters if built by :func:`special_6_6`.
    """

    base_points: np.ndarray
    top_points: np.ndarray
    stiffness: np.ndarray
    free_lengths: np.ndarray
    home_pose: np.ndarray
    leg_names: tuple[str, ...] = LEG_NAMES
    name: str = "platform"
    length_unit: str = "mm"
    force_unit: str = "N"
    design: SpecialDesign | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        checks = {
            "base_points": (6, 3),
            "top_points": (6, 3),
            "stiffness": (6,),
            "free_lengths": (6,),
            "home_pose": (4, 4),
        }
        for attr, shape in checks.items():
            try:
                a = np.array(getattr(self, attr), dtype=float)
            except (TypeError, ValueError) as exc:
                raise ModelError(f"platform {attr} must be numeric, shape {shape}") from exc
            if a.shape != shape:
                raise ModelError(f"platform {attr} must have shape {shape}, got {a.shape}")
            if not np.all(np.isfinite(a)):
                raise ModelError(f"platform {attr} contains NaN or infinity")
            a.flags.writeable = False
            object.__setattr__(self, attr, a)
        names = tuple(str(n) for n in self.leg_names)
        if len(names) != 6 or len(set(names)) != 6:
            raise ModelError(f"a platform needs six distinct leg names, got {names}")
        object.__setattr__(self, "leg_names", names)
        if np.any(self.stiffness <= 0):
            raise ModelError(f"spring constants must be positive, got {self.stiffness.tolist()}")
        if np.any(self.free_lengths <= 0):
            raise ModelError(f"free lengths must be positive, got {self.free_lengths.tolist()}")
        R = self.home_pose[:3, :3]
        if (np.max(np.abs(R @ R.T - np.eye(3))) > 1e-9 or abs(np.linalg.det(R) - 1) > 1e-9
                or np.any(self.home_pose[3] != [0, 0, 0, 1])):
            raise ModelError("home_pose must be a rigid transform (orthonormal rotation, "
                             "last row 0 0 0 1)")
        for which in ("base_points", "top_points"):
            p = getattr(self, which)
            d = np.linalg.norm(p[:, None] - p[None], axis=-1)
            # legs may share a joint point (a 3-3 platform), but not all of them
            if np.max(d) <= 0:
                raise ModelError(f"platform {which} all coincide")

    @cached_property
    def scale(self) -> float:
        """A characteristic length: the mean distance of the base points from their centroid."""
        c = self.base_points.mean(axis=0)
        return float(np.mean(np.linalg.norm(self.base_points - c, axis=1)))

    @cached_property
    def layout(self) -> SpecialLayout | None:
        """The special 6-6 layout of this platform, or None if it is not special."""
        return special_layout(self.base_points, self.top_points)

    def leg_index(self, name: str) -> int:
        """Index of the leg called ``name``."""
        try:
            return self.leg_names.index(name)
        except ValueError:
            raise InputError(f"no leg named {name!r}; legs are {list(self.leg_names)}") from None


def triangle_points(sides) -> np.ndarray:
    """Corners (3, 3) of a triangle from its sides (|AB|, |BC|, |CA|): A at 0, B on +x, C at y>0."""
    ab, bc, ca = (float(x) for x in _vec(sides, 3, "triangle sides"))
    if min(ab, bc, ca) <= 0:
        raise InputError(f"triangle sides must be positive, got {[ab, bc, ca]}")
    cx = (ab * ab + ca * ca - bc * bc) / (2 * ab)
    cy2 = ca * ca - cx * cx
    if cy2 <= 1e-12 * ab * ab:
        raise InputError(f"sides {[ab, bc, ca]} do not make a proper triangle "
                         "(triangle inequality fails or the triangle is flat)")
    return np.array([[0.0, 0.0, 0.0], [ab, 0.0, 0.0], [cx, math.sqrt(cy2), 0.0]])


def _edge_point(a: np.ndarray, b: np.ndarray, dist: float) -> np.ndarray:
    return a + dist * (b - a) / np.linalg.norm(b - a)


def special_6_6(
    base_side=120.0,
    top_side=60.0,
    base_offset=28.0,
    top_offset=14.0,
    height: float = 60.0,
    twist: float = -math.pi / 3,
    stiffness=2.627,
    free_lengths=None,
    *,
    name: str = "special-6-6",
    length_unit: str = "mm",
    force_unit: str = "N",
    leg_names: tuple[str, ...] = LEG_NAMES,
) -> Platform:
    """Build a special 6-6 (Griffis–Duffy) platform from its triangles and edge offsets.

    Vibhute 2011 §3.1.3 and Appendix B (main.cpp's ``plat_params``). ``base_side``/``top_side``
    are a side length (equilateral) or three sides; ``base_offset`` (|O0S0|, |P0T0|, |Q0R0|)
    and ``top_offset`` (|R1O1|, |S1P1|, |T1Q1|) place the edge points, each a number or three.

    The home pose is derived from the design (Vibhute §3.1.2, after Lee): top plane parallel to
    the base at ``height``, the top triangle's centroid above the base triangle's centroid, and
    the top frame turned by ``twist`` (radians) about the base z axis. With the defaults (the
    thesis prototype: b = 120, a = 60, twist = −60°) the top corners sit above the midpoints of
    the base edges. The free lengths are the leg lengths at home unless given.

    Raises:
        InputError: impossible dimensions (offsets outside their edge, bad triangles).
        ModelError: an architecturally singular layout (see :mod:`kinestat.parallel.singularity`).

    >>> p = special_6_6()                      # the 2011 prototype's design
    >>> p.leg_names, round(p.layout.t[0], 6)   # edge points 14 mm along 60 mm top sides
    (('O', 'P', 'Q', 'R', 'S', 'T'), 0.233333)
    """
    triangles = []
    for sides, what in ((base_side, "base_side"), (top_side, "top_side")):
        try:
            triangles.append(triangle_points(sides))
        except InputError as exc:
            raise InputError(f"{what}: {exc}") from exc
    base, top = triangles
    bside = np.array([np.linalg.norm(base[(i + 1) % 3] - base[i]) for i in range(3)])
    tside = np.array([np.linalg.norm(top[(i + 1) % 3] - top[i]) for i in range(3)])
    boff = _vec(base_offset, 3, "base_offset")
    toff = _vec(top_offset, 3, "top_offset")
    if np.any(boff < 0) or np.any(boff > bside):
        raise InputError(f"base offsets {boff.tolist()} must lie in [0, side] "
                         f"(sides {bside.tolist()})")
    if np.any(toff < 0) or np.any(toff > tside):
        raise InputError(f"top offsets {toff.tolist()} must lie in [0, side] "
                         f"(sides {tside.tolist()})")
    height, twist = as_number(height, "height"), as_number(twist, "twist")
    if height <= 0:
        raise InputError(f"home height must be positive, got {height}")
    k = _vec(stiffness, 6, "stiffness")
    O0, P0, Q0 = base
    R1, S1, T1 = top
    base_pts = np.array([
        O0, P0, Q0,
        _edge_point(Q0, O0, boff[2]),  # R0 on Q0O0
        _edge_point(O0, P0, boff[0]),  # S0 on O0P0
        _edge_point(P0, Q0, boff[1]),  # T0 on P0Q0
    ])
    top_pts = np.array([
        _edge_point(R1, S1, toff[0]),  # O1 on R1S1
        _edge_point(S1, T1, toff[1]),  # P1 on S1T1
        _edge_point(T1, R1, toff[2]),  # Q1 on T1R1
        R1, S1, T1,
    ])
    Rz = rot_z(float(twist))[:3, :3]
    p = base.mean(axis=0) + np.array([0.0, 0.0, float(height)]) - Rz @ top.mean(axis=0)
    home = make_pose(Rz, p)
    l_home = np.linalg.norm(apply(home, top_pts) - base_pts, axis=1)
    given_l0 = None
    if free_lengths is None:
        l0 = l_home
    else:
        l0 = _vec(free_lengths, 6, "free_lengths")
        given_l0 = tuple(float(x) for x in l0)
    design = SpecialDesign(
        base_side=tuple(float(x) for x in bside),
        top_side=tuple(float(x) for x in tside),
        base_offset=tuple(float(x) for x in boff),
        top_offset=tuple(float(x) for x in toff),
        height=float(height),
        twist=float(twist),
        stiffness=tuple(float(x) for x in k),
        free_lengths=given_l0,
    )
    plat = Platform(base_points=base_pts, top_points=top_pts, stiffness=k, free_lengths=l0,
                    home_pose=home, leg_names=leg_names, name=name, length_unit=length_unit,
                    force_unit=force_unit, design=design)
    check_design(plat)
    return plat


def _fraction_on_segment(x, a, b, tol: float) -> float | None:
    """t with x = a + t (b − a) if x lies on the line ab within ``tol``, else None."""
    d = b - a
    n2 = float(d @ d)
    if n2 <= tol * tol:
        return None
    t = float((x - a) @ d / n2)
    if np.linalg.norm(a + t * d - x) > tol:
        return None
    return t


def _match_roles(base: np.ndarray, top: np.ndarray, order, tol: float) -> tuple[float, ...] | None:
    b = base[list(order)]
    p = top[list(order)]
    t = [0.0] * 6
    for r, (i, j) in _TOP_EDGE.items():
        f = _fraction_on_segment(p[r], p[i], p[j], tol)
        if f is None:
            return None
        t[r] = f
    for r, (i, j) in _BASE_EDGE.items():
        f = _fraction_on_segment(b[r], b[i], b[j], tol)
        if f is None:
            return None
        t[r] = f
    # the corner triangles must be proper triangles
    for tri in (b[:3], p[3:]):
        if np.linalg.norm(np.cross(tri[1] - tri[0], tri[2] - tri[0])) <= tol * tol:
            return None
    return tuple(t)


def special_layout(base_points, top_points, tol: float | None = None) -> SpecialLayout | None:
    """Detect the special 6-6 structure of a leg layout (None if the platform is not special).

    Tries the canonical leg order O, P, Q, R, S, T first, then every relabelling of the legs.
    ``tol`` (default 1e-6 times the layout's size, so coordinates printed to 4 decimals still
    count) is the distance within which an edge point counts as lying on its edge. The closed
    form only seeds the forward kinematics — every mode is polished and verified on the real
    legs — so a nearly special layout still gets exact modes.
    """
    base = np.asarray(base_points, dtype=float)
    top = np.asarray(top_points, dtype=float)
    size = max(float(np.ptp(base, axis=0).max()), float(np.ptp(top, axis=0).max()), 1e-300)
    tol = 1e-6 * size if tol is None else tol
    canonical = tuple(range(6))
    for order in (canonical, *permutations(range(6))):
        t = _match_roles(base, top, order, tol)
        if t is not None:
            return SpecialLayout(order=tuple(int(i) for i in order), t=t)
    return None
