"""Plücker coordinates of lines, ``[S; S0]`` with ``S0 = r1 x S`` (Vibhute 2011, Appendix A).

A line is an array ``(..., 6)``: unit direction ``S`` then moment ``S0`` about the origin
(ray coordinates, ``{S; S0L}`` in the seeds). The coordinates are homogeneous; functions that take
lines accept any nonzero scale and normalise them. Every function broadcasts over leading
dimensions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError
from kinestat.spatial.transforms import as_array
from kinestat.spatial.validate import as_pose, as_unit_vector, freeze_fields

__all__ = [
    "LINE_KINDS",
    "SKEW",
    "PARALLEL",
    "INTERSECTING",
    "COINCIDENT",
    "CommonNormal",
    "LinePair",
    "line_from_points",
    "line_from_point_direction",
    "normalize_line",
    "is_line",
    "point_on_line",
    "transform_line",
    "mutual_moment",
    "line_distance",
    "common_normal",
    "classify_lines",
]

#: Names of the relations returned by :func:`classify_lines`, indexed by the integer codes.
LINE_KINDS: tuple[str, ...] = ("skew", "parallel", "intersecting", "coincident")
SKEW, PARALLEL, INTERSECTING, COINCIDENT = range(4)



def _where(mask: np.ndarray) -> str:
    """`` at batch index (i, j)`` for the first True entry of a batched mask, else ``""``."""
    if mask.ndim == 0:
        return ""
    return f" at batch index {tuple(int(i) for i in np.argwhere(mask)[0])}"


def _dot(a, b) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def line_from_points(p1, p2) -> np.ndarray:
    """Line through ``p1`` and ``p2`` (``(..., 3)`` each): ``S = (r2 - r1)/|r2 - r1|``,
    ``S0 = r1 x S`` (Vibhute eqs. A-2, A-7).

    >>> line_from_points([0.0, 1.0, 0.0], [1.0, 1.0, 0.0])  # [S; p x S]
    array([ 1.,  0.,  0.,  0.,  0., -1.])
    """
    p1 = as_array(p1, shape_tail=(3,), name="p1")
    p2 = as_array(p2, shape_tail=(3,), name="p2")
    s = p2 - p1
    n = np.linalg.norm(s, axis=-1)
    scale = np.maximum(np.maximum(np.linalg.norm(p1, axis=-1), np.linalg.norm(p2, axis=-1)), 1.0)
    bad = n <= 1e-12 * scale
    if np.any(bad):
        raise InputError(f"p1 and p2 coincide{_where(bad)}: a line needs two distinct points")
    S = s / n[..., None]
    return np.concatenate(np.broadcast_arrays(S, np.cross(p1, S)), axis=-1)


def line_from_point_direction(p, s) -> np.ndarray:
    """Line through point ``p`` with direction ``s`` (any nonzero length): ``[S; p x S]``.

    >>> line_from_point_direction([0.0, 1.0, 0.0], [2.0, 0.0, 0.0])
    array([ 1.,  0.,  0.,  0.,  0., -1.])
    """
    p = as_array(p, shape_tail=(3,), name="point")
    S = as_unit_vector(s, "direction", normalize=True)
    return np.concatenate(np.broadcast_arrays(S, np.cross(p, S)), axis=-1)


def normalize_line(line, *, tol: float = 1e-6, name: str = "line") -> np.ndarray:
    """Scale homogeneous line coordinates so that ``|S| = 1``.

    Raises :class:`InputError` if ``S = 0`` (a line at infinity) or the Plücker condition
    ``S . S0 = 0`` (Vibhute eq. A-8) fails by more than ``tol`` relative to ``|S| |S0|``; the
    message names the argument ``name``.

    >>> normalize_line([2.0, 0.0, 0.0, 0.0, 0.0, -2.0])
    array([ 1.,  0.,  0.,  0.,  0., -1.])
    """
    L = as_array(line, shape_tail=(6,), name=name)
    S, S0 = L[..., :3], L[..., 3:]
    n = np.linalg.norm(S, axis=-1)
    bad = n == 0.0
    if np.any(bad):
        raise InputError(
            f"{name} has zero direction S{_where(bad)}: Plücker coordinates [S; S0] need S != 0"
        )
    off = np.abs(_dot(S, S0)) > tol * n * np.maximum(np.linalg.norm(S0, axis=-1), 1.0)
    if np.any(off):
        raise InputError(
            f"{name} is not a line{_where(off)}: S . S0 must be 0 (Plücker condition); build "
            "lines with line_from_points or line_from_point_direction"
        )
    return L / n[..., None]


def is_line(line, tol: float = 1e-9) -> np.ndarray:
    """True where ``line`` satisfies the Plücker condition ``S . S0 = 0`` with ``S != 0``.

    >>> bool(is_line([1.0, 0.0, 0.0, 0.0, 0.0, -1.0])), bool(is_line([1.0, 0, 0, 1.0, 0, 0]))
    (True, False)
    """
    L = as_array(line, shape_tail=(6,), name="line", finite=False)  # NaN: not a line
    S, S0 = L[..., :3], L[..., 3:]
    n = np.linalg.norm(S, axis=-1)
    return (n > 0) & (np.abs(_dot(S, S0)) <= tol * n * np.maximum(np.linalg.norm(S0, axis=-1), 1.0))


def point_on_line(line) -> np.ndarray:
    """Foot of the perpendicular from the origin to the line: ``S x S0 / (S . S)``.

    >>> point_on_line([1.0, 0.0, 0.0, 0.0, 0.0, -1.0]) + 0.0
    array([0., 1., 0.])
    """
    L = normalize_line(line)
    return np.cross(L[..., :3], L[..., 3:])


def transform_line(T, line) -> np.ndarray:
    """Express lines given in frame B in frame A, with ``T`` the pose of B in A:
    ``S' = R S``, ``S0' = R S0 + p x R S``.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> transform_line(trans([0.0, 0.0, 5.0]), [1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    array([1., 0., 0., 0., 5., 0.])
    """
    T = as_pose(T, "T")
    L = normalize_line(line)
    R, p = T[..., :3, :3], T[..., :3, 3]
    S = np.einsum("...ij,...j->...i", R, L[..., :3])
    S0 = np.einsum("...ij,...j->...i", R, L[..., 3:]) + np.cross(p, S)
    return np.concatenate([S, S0], axis=-1)


def mutual_moment(l1, l2) -> np.ndarray:
    """Mutual moment (reciprocal product) ``S1 . S02 + S2 . S01`` of two lines, normalised.

    Equals ``(r1 - r2) . (S1 x S2)`` for points ``r1``, ``r2`` on the lines, i.e. ``-a sin(alpha)``
    with ``a`` the common-normal length and ``alpha`` the twist angle from S1 to S2 about it. Zero
    exactly when the lines are coplanar (intersect or are parallel).

    >>> x_axis = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    >>> y_at_z1 = line_from_point_direction([0.0, 0.0, 1.0], [0.0, 1.0, 0.0])
    >>> float(mutual_moment(x_axis, y_at_z1))  # -distance x sin(angle)
    -1.0
    """
    a = normalize_line(l1, name="l1")
    b = normalize_line(l2, name="l2")
    return _dot(a[..., :3], b[..., 3:]) + _dot(b[..., :3], a[..., 3:])


@dataclass(frozen=True)
class CommonNormal:
    """The common normal of two lines.

    ``foot1`` on line 1 and ``foot2`` on line 2 are its feet; ``direction`` is the unit vector
    from ``foot1`` to ``foot2`` (``S1 x S2`` normalised when the lines meet; for coincident lines,
    where any perpendicular will do, a fixed perpendicular to ``S1``); ``distance`` its length.
    For parallel lines the common normal is not unique: the one through the foot of the
    perpendicular from the origin to line 1 is returned.

    >>> y_at_z1 = line_from_point_direction([0.0, 0.0, 1.0], [0.0, 1.0, 0.0])
    >>> n = common_normal([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], y_at_z1)
    >>> n.foot1, n.foot2, float(n.distance)
    (array([0., 0., 0.]), array([0., 0., 1.]), 1.0)
    """

    foot1: np.ndarray
    foot2: np.ndarray
    direction: np.ndarray
    distance: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, ("foot1", "foot2", "direction", "distance"))


def _any_perpendicular(S: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to unit ``S``, fixed by the smallest component of ``S``."""
    k = np.argmin(np.abs(S), axis=-1)
    e = np.zeros_like(S)
    np.put_along_axis(e, k[..., None], 1.0, axis=-1)
    v = np.cross(S, e)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _normal(a: np.ndarray, b: np.ndarray, angle_tol: float, tol: float):
    """Common normal of unit lines ``a``, ``b``; also returns the parallel mask."""
    a, b = np.broadcast_arrays(a, b)
    S1, S2 = a[..., :3], b[..., :3]
    p1 = np.cross(S1, a[..., 3:])
    p2 = np.cross(S2, b[..., 3:])
    w = p2 - p1
    n = np.cross(S1, S2)
    nn = _dot(n, n)
    parallel = np.sqrt(nn) <= angle_tol
    safe = np.where(parallel, 1.0, nn)
    t1 = _dot(np.cross(w, S2), n) / safe
    t2 = _dot(np.cross(w, S1), n) / safe
    foot1 = np.where(parallel[..., None], p1, p1 + t1[..., None] * S1)
    # parallel: project p1 onto line 2
    t2p = _dot(p1 - p2, S2)
    foot2 = np.where(parallel[..., None], p2 + t2p[..., None] * S2, p2 + t2[..., None] * S2)
    gap = foot2 - foot1
    dist = np.linalg.norm(gap, axis=-1)
    meet = dist <= tol
    n_unit = n / np.where(parallel, 1.0, np.sqrt(nn))[..., None]
    # non-parallel: +-(S1 x S2)/|S1 x S2| (accurate even for short normals), pointing from
    # foot1 to foot2 unless the lines meet; parallel: along the gap, or any perpendicular
    n_unit = np.where((~meet & (_dot(gap, n_unit) < 0))[..., None], -n_unit, n_unit)
    direction = np.where(
        parallel[..., None],
        np.where(meet[..., None], _any_perpendicular(S1),
                 gap / np.where(meet, 1.0, dist)[..., None]),
        n_unit,
    )
    return foot1, foot2, direction, dist, parallel


def common_normal(l1, l2, *, tol: float = 1e-9, angle_tol: float = 1e-9) -> CommonNormal:
    """Common normal (feet, direction, length) of two lines ``(..., 6)``.

    Lines whose directions differ by less than ``angle_tol`` (``|S1 x S2|``) are treated as
    parallel; feet closer than ``tol`` (length unit of the lines) as meeting.

    >>> y_at_z1 = line_from_point_direction([0.0, 0.0, 1.0], [0.0, 1.0, 0.0])
    >>> n = common_normal([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], y_at_z1)
    >>> n.direction, float(n.distance)
    (array([0., 0., 1.]), 1.0)
    """
    foot1, foot2, direction, dist, _ = _normal(
        normalize_line(l1, name="l1"), normalize_line(l2, name="l2"), angle_tol, tol
    )
    return CommonNormal(foot1, foot2, direction, dist)


def line_distance(l1, l2, *, angle_tol: float = 1e-9) -> np.ndarray:
    """Shortest distance between two lines ``(..., 6)`` (0 where they meet).

    >>> y_at_z2 = line_from_point_direction([0.0, 0.0, 2.0], [0.0, 1.0, 0.0])
    >>> float(line_distance([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], y_at_z2))
    2.0
    """
    return _normal(normalize_line(l1, name="l1"), normalize_line(l2, name="l2"), angle_tol,
                   0.0)[3]


@dataclass(frozen=True)
class LinePair:
    """How two lines relate: ``kind`` (codes into :data:`LINE_KINDS`), the shortest
    ``distance``, the ``angle`` between their directions in [0, pi], and the feet of the common
    normal ``foot1`` (on line 1) and ``foot2`` (on line 2). For intersecting lines both feet are
    the intersection point; for coincident lines both are the foot of the perpendicular from the
    origin.

    >>> p = classify_lines([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    >>> LINE_KINDS[int(p.kind)], float(p.distance), round(float(p.angle), 12)
    ('intersecting', 0.0, 1.570796326795)
    """

    kind: np.ndarray
    distance: np.ndarray
    angle: np.ndarray
    foot1: np.ndarray
    foot2: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, ("kind", "distance", "angle", "foot1", "foot2"))

    @property
    def kind_name(self):
        """``"skew"``, ``"parallel"``, ``"intersecting"`` or ``"coincident"`` (an array of
        those strings for a batch)."""
        names = np.array(LINE_KINDS)[self.kind]
        return str(names) if names.ndim == 0 else names

    @property
    def point(self) -> np.ndarray:
        """Midpoint of the common normal: the intersection point when the lines meet."""
        return 0.5 * (self.foot1 + self.foot2)


def classify_lines(l1, l2, tol: float = 1e-9, *, angle_tol: float = 1e-9) -> LinePair:
    """Classify two lines as skew, parallel, intersecting or coincident.

    ``tol`` is the distance (in the lines' length unit) below which they are taken to meet and
    ``angle_tol`` the ``|S1 x S2|`` below which they are parallel.

    >>> x_at_y1 = line_from_point_direction([0.0, 1.0, 0.0], [1.0, 0.0, 0.0])
    >>> LINE_KINDS[int(classify_lines([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], x_at_y1).kind)]
    'parallel'
    """
    a, b = normalize_line(l1, name="l1"), normalize_line(l2, name="l2")
    foot1, foot2, _, dist, parallel = _normal(a, b, angle_tol, tol)
    meet = dist <= tol
    kind = np.where(parallel, np.where(meet, COINCIDENT, PARALLEL),
                    np.where(meet, INTERSECTING, SKEW))
    a, b = np.broadcast_arrays(a, b)
    angle = np.arctan2(np.linalg.norm(np.cross(a[..., :3], b[..., :3]), axis=-1),
                       _dot(a[..., :3], b[..., :3]))
    mid = 0.5 * (foot1 + foot2)
    foot1 = np.where(meet[..., None], mid, foot1)
    foot2 = np.where(meet[..., None], mid, foot2)
    return LinePair(kind.astype(np.int64), dist, angle, foot1, foot2)
