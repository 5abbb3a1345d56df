"""The screw axis of a finite displacement (Chasles; Nadkarni 1977, chapter III).

A body moved from pose ``T1`` to pose ``T2`` (both in the global frame) has undergone the
displacement ``D = T2 T1^-1``: a rotation ``theta`` about a line (the screw axis, unit direction
``u`` through the point ``rho_n``) combined with a translation ``d`` along it.

Conventions (those of Nadkarni's SCREWM, made total):

* ``u`` is a unit vector with ``u3 >= 0``; when ``|u3| <= 1e-12`` then ``u2 >= 0``; when also
  ``|u2| <= 1e-12`` then ``u1 > 0``. Flipping ``u`` flips ``theta`` and ``d`` with it.
* ``theta`` in (-pi, pi], right-handed about ``u``; a half turn is reported as ``+pi``.
* ``point`` is ``rho_n``, the foot of the perpendicular from the global origin to the axis
  (``point . u = 0``).
* ``pitch = d / theta``, ``inf`` for a pure translation.
* A pure translation (``|theta| <= angle_tol``) has ``u`` along the translation (eq. 3-29
  applied to the displacement of a body point), ``theta = 0``, ``point = 0`` (every parallel
  line is an axis; the one through the origin is returned) and ``is_translation`` set.
* No motion at all (identity, ``|q| <= length_tol``) gives ``u = (0, 0, 1)``, ``theta = 0``,
  ``d = 0``, ``point = 0``, ``is_translation`` set and ``pitch = inf``.

For a very small but nonzero rotation the axis is far away (``|rho_n| ~ |q| / theta``): that is
the geometry, not an artefact, and :func:`pose_from_screw` still reproduces the displacement to
rounding error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError
from kinestat.spatial.tolerances import ORTHO_TOL as _ORTHO_TOL
from kinestat.spatial.transforms import as_array, make_pose, skew
from kinestat.spatial.validate import as_pose, as_unit_vector, batch_index, freeze_fields

__all__ = [
    "ScrewDisplacement",
    "frame_from_points",
    "frame_from_triple",
    "relative_displacement",
    "screw_from_displacement",
    "screw_from_poses",
    "screw_from_points",
    "screws_between",
    "pose_from_screw",
    "interpolate_screw",
]

#: Poses are accepted when their rotation part is orthonormal to this tolerance.
ORTHO_TOL: float = _ORTHO_TOL
#: Rotation angles (rad) at or below this are treated as zero: a pure translation.
ANGLE_TOL: float = 1e-12
#: Components of ``u`` within this of zero count as zero for the sign convention.
_SIGN_TOL: float = 1e-12


def _dot(a, b) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


_where = batch_index



def frame_from_points(p1, p2, p3, *, tol: float = 1e-9) -> np.ndarray:
    """Body frame ``(..., 4, 4)`` located by three points (Nadkarni eqs. 3-1 to 3-3).

    Origin at ``p1``; ``z = (p2 - p1)/|p2 - p1|``; ``y = b/|b|`` with ``b = (p2 - p1) x (p3 - p1)``;
    ``x = y x z``, so ``p3`` lies in the z-x half plane on the side of positive x.

    Raises :class:`InputError` when two points coincide or the three are collinear (the sine of
    the angle at ``p1`` below ``tol``).

    >>> frame_from_points([1.0, 0.0, 0.0], [1.0, 0.0, 2.0], [3.0, 0.0, 0.0])
    array([[1., 0., 0., 1.],
           [0., 1., 0., 0.],
           [0., 0., 1., 0.],
           [0., 0., 0., 1.]])
    """
    p1 = as_array(p1, shape_tail=(3,), name="point 1")
    p2 = as_array(p2, shape_tail=(3,), name="point 2")
    p3 = as_array(p3, shape_tail=(3,), name="point 3")
    p1, p2, p3 = np.broadcast_arrays(p1, p2, p3)
    a, c = p2 - p1, p3 - p1
    na, nc = np.linalg.norm(a, axis=-1), np.linalg.norm(c, axis=-1)
    norms = [np.linalg.norm(p, axis=-1) for p in (p1, p2, p3)]
    scale = np.maximum(np.maximum(norms[0], norms[1]), np.maximum(norms[2], 1.0))
    for bad, which in (
        (na <= tol * scale, "points 1 and 2 coincide"),
        (nc <= tol * scale, "points 1 and 3 coincide"),
        (np.linalg.norm(p3 - p2, axis=-1) <= tol * scale, "points 2 and 3 coincide"),
    ):
        if np.any(bad):
            raise InputError(
                f"{which}{_where(bad)}: a body frame needs three distinct, non-collinear points "
                "(origin, a point on +z, a point in the z-x half plane with x > 0)"
            )
    b = np.cross(a, c)
    nb = np.linalg.norm(b, axis=-1)
    bad = nb <= tol * na * nc
    if np.any(bad):
        raise InputError(
            f"points 1, 2 and 3 are collinear{_where(bad)}: the third point must lie off the line "
            "through the first two (it fixes the x axis)"
        )
    z = a / na[..., None]
    y = b / nb[..., None]
    x = np.cross(y, z)
    return make_pose(np.stack([x, y, z], axis=-1), p1)


def frame_from_triple(points, *, tol: float = 1e-9) -> np.ndarray:
    """:func:`frame_from_points` for points ``(..., 3, 3)`` given as rows ``p1, p2, p3``.

    >>> frame_from_triple([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    array([[1., 0., 0., 0.],
           [0., 1., 0., 0.],
           [0., 0., 1., 0.],
           [0., 0., 0., 1.]])
    """
    P = as_array(points, shape_tail=(3, 3), name="points")
    return frame_from_points(P[..., 0, :], P[..., 1, :], P[..., 2, :], tol=tol)


def _check_pose(T, name: str, tol: float) -> np.ndarray:
    return as_pose(T, name, tol=tol, last_row_tol=tol)


def relative_displacement(T1, T2, *, tol: float = ORTHO_TOL) -> np.ndarray:
    """``D = T2 T1^-1`` ``(..., 4, 4)``, i.e. ``Q = Q2 Q1^T``, ``q = q2 - Q q1``
    (Nadkarni eqs. 3-12, 3-13); ``X2 = Q X1 + q`` for every body point.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> relative_displacement(trans([1.0, 0.0, 0.0]), trans([1.0, 2.0, 0.0]))[:3, 3]
    array([0., 2., 0.])
    """
    T1 = _check_pose(T1, "pose 1", tol)
    T2 = _check_pose(T2, "pose 2", tol)
    Q = T2[..., :3, :3] @ np.swapaxes(T1[..., :3, :3], -1, -2)
    q = T2[..., :3, 3] - np.einsum("...ij,...j->...i", Q, T1[..., :3, 3])
    return make_pose(Q, q)


@dataclass(frozen=True)
class ScrewDisplacement:
    """Screw parameters of finite displacements (batched; all arrays read-only).

    ``axis`` ``(..., 3)`` unit ``u``; ``point`` ``(..., 3)`` the foot ``rho_n`` of the
    perpendicular from the origin to the axis; ``theta`` ``(...)`` rotation in (-pi, pi];
    ``d`` ``(...)`` translation along ``u``; ``is_translation`` ``(...)`` no rotation.
    See the module docstring for the conventions.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> D = screw_from_poses(np.eye(4), trans([0.0, 0.0, 2.0]) @ rot_z(np.pi / 2))
    >>> D.axis, round(float(D.theta), 12), float(D.d), bool(D.is_translation)
    (array([0., 0., 1.]), 1.570796326795, 2.0, False)
    """

    axis: np.ndarray
    point: np.ndarray
    theta: np.ndarray
    d: np.ndarray
    is_translation: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, ("axis", "point", "theta", "d", "is_translation"))

    @property
    def shape(self) -> tuple[int, ...]:
        """Batch shape."""
        return self.theta.shape

    def __getitem__(self, index) -> ScrewDisplacement:
        return ScrewDisplacement(
            self.axis[index], self.point[index], self.theta[index], self.d[index],
            self.is_translation[index],
        )

    @property
    def angle_deg(self) -> np.ndarray:
        """``theta`` in degrees, in (-180, 180]."""
        return np.degrees(self.theta)

    @property
    def pitch(self) -> np.ndarray:
        """``h = d / theta``; ``inf`` for a pure translation (and for no motion)."""
        t = np.where(self.is_translation, 1.0, self.theta)
        return np.where(self.is_translation, np.inf, self.d / t)

    @property
    def line(self) -> np.ndarray:
        """The screw axis as a Plücker line ``[u; point x u]`` ``(..., 6)``."""
        return np.concatenate([self.axis, np.cross(self.point, self.axis)], axis=-1)

    @property
    def twist(self) -> np.ndarray:
        """Twist ``[theta u; theta (point x u) + d u]`` ``(..., 6)`` whose matrix exponential
        (:func:`kinestat.spatial.screws.twist_matrix`) is the displacement ``D``."""
        t = self.theta[..., None]
        return np.concatenate(
            [t * self.axis, t * np.cross(self.point, self.axis) + self.d[..., None] * self.axis],
            axis=-1,
        )

    def pose(self) -> np.ndarray:
        """The displacement ``D`` ``(..., 4, 4)`` (:func:`pose_from_screw`)."""
        return pose_from_screw(self.axis, self.point, self.theta, self.d)


def _sign_flip(u: np.ndarray) -> np.ndarray:
    """True where ``u`` breaks the convention u3 >= 0 (then u2 >= 0, then u1 > 0)."""
    u1, u2, u3 = u[..., 0], u[..., 1], u[..., 2]
    z3 = np.abs(u3) <= _SIGN_TOL
    z2 = np.abs(u2) <= _SIGN_TOL
    return (u3 < -_SIGN_TOL) | (z3 & (u2 < -_SIGN_TOL)) | (z3 & z2 & (u1 < 0))


def _foot(u: np.ndarray, theta: np.ndarray, q_perp: np.ndarray) -> np.ndarray:
    """Point ``rho_n`` on the axis with ``(I - Q) rho_n = q_perp``, ``rho_n . u = 0``:
    ``rho_n = (q_perp + cot(theta/2) u x q_perp) / 2`` (closed-form solution of Nadkarni's
    system 3-41, exact at theta = pi and well conditioned down to tiny theta)."""
    half = 0.5 * theta
    cot = np.cos(half) / np.sin(half)
    return 0.5 * (q_perp + cot[..., None] * np.cross(u, q_perp))


def screw_from_displacement(
    D, *, angle_tol: float = ANGLE_TOL, length_tol: float = 1e-12, tol: float = ORTHO_TOL,
) -> ScrewDisplacement:
    """Screw parameters of rigid displacements ``D`` ``(..., 4, 4)`` (``X2 = Q X1 + q``).

    Direction and angle come from the rotation vector of ``Q`` (SciPy, robust at 0 and pi;
    equivalent to eqs. 3-24 to 3-28 and 3-50 to 3-54), ``d = u . q`` and ``rho_n`` from the
    closed-form solution of eq. 3-41. Rotations of at most ``angle_tol`` (rad) count as none (a
    pure translation; ``angle_tol=0`` makes :func:`pose_from_screw` an exact inverse for every
    input); a pure translation of at most ``length_tol`` (model units) counts as no motion.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> D = trans([1.0, 0.0, 0.0]) @ rot_z(np.pi / 2) @ trans([-1.0, 0.0, 0.0])
    >>> s = screw_from_displacement(D)
    >>> s.point, round(float(s.theta), 12)  # a quarter turn about the vertical through x = 1
    (array([1., 0., 0.]), 1.570796326795)
    """
    from scipy.spatial.transform import Rotation  # lazy: start-up (scipy.spatial ~0.5 s)
    D = _check_pose(D, "displacement", tol)
    Q, q = D[..., :3, :3], D[..., :3, 3]
    shape = D.shape[:-2]
    rv = Rotation.from_matrix(Q.reshape(-1, 3, 3)).as_rotvec().reshape(shape + (3,))
    theta = np.minimum(np.linalg.norm(rv, axis=-1), np.pi)  # |rotvec| may exceed pi by an ulp
    rot = theta > angle_tol
    nq = np.linalg.norm(q, axis=-1)
    moves = nq > length_tol
    ez = np.broadcast_to(np.array([0.0, 0.0, 1.0]), shape + (3,))
    u_trans = np.where(moves[..., None], q / np.where(moves, nq, 1.0)[..., None], ez)
    u = np.where(rot[..., None], rv / np.where(rot, theta, 1.0)[..., None], u_trans)
    theta = np.where(rot, theta, 0.0)
    flip = _sign_flip(u)
    u = np.where(flip[..., None], -u, u)
    theta = np.where(flip & (theta < np.pi), -theta, theta) + 0.0  # no -0.0
    d = np.where(rot | moves, _dot(u, q), 0.0)
    q_perp = q - d[..., None] * u
    point = np.where(rot[..., None], _foot(u, np.where(rot, theta, 1.0), q_perp), 0.0)
    return ScrewDisplacement(u, point, theta, d, ~rot)


def screw_from_poses(T1, T2, **kw) -> ScrewDisplacement:
    """Screw axis of the displacement taking a body from pose ``T1`` to ``T2`` (``(..., 4, 4)``,
    global frame): Nadkarni ch. III (SCREWM). Keywords as :func:`screw_from_displacement`.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> s = screw_from_poses(np.eye(4), trans([0.0, 0.0, 3.0]))
    >>> bool(s.is_translation), s.axis, float(s.d)
    (True, array([0., 0., 1.]), 3.0)
    """
    tol = kw.get("tol", ORTHO_TOL)
    return screw_from_displacement(relative_displacement(T1, T2, tol=tol), **kw)


def screw_from_points(points1, points2, *, tol: float = 1e-9, **kw) -> ScrewDisplacement:
    """Screw axis between two body positions each located by three points ``(..., 3, 3)``
    (rows ``p1, p2, p3`` as in :func:`frame_from_points`; Nadkarni's SET TWO cards).

    >>> P1 = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
    >>> P2 = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
    >>> s = screw_from_points(P1, P2)
    >>> s.axis, round(float(np.degrees(s.theta)), 9)
    (array([0., 0., 1.]), 90.0)
    """
    T1 = frame_from_triple(points1, tol=tol)
    T2 = frame_from_triple(points2, tol=tol)
    return screw_from_poses(T1, T2, **kw)


def screws_between(poses, **kw) -> ScrewDisplacement:
    """Screws between consecutive poses ``(..., N, 4, 4)`` -> batch ``(..., N-1)``
    (Nadkarni's DISP with MS = 1). For point triples use ``frame_from_triple`` first.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> s = screws_between(np.stack([np.eye(4), trans([1.0, 0.0, 0.0]), trans([1.0, 1.0, 0.0])]))
    >>> s.d
    array([1., 1.])
    """
    P = as_array(poses, shape_tail=(4, 4), name="poses")
    if P.ndim < 3 or P.shape[-3] < 2:
        raise InputError(f"screws_between needs at least two poses (..., N, 4, 4), got {P.shape}")
    return screw_from_poses(P[..., :-1, :, :], P[..., 1:, :, :], **kw)


def pose_from_screw(axis, point, theta, d) -> np.ndarray:
    """Displacement ``D`` ``(..., 4, 4)`` of a screw motion: rotation ``theta`` (rad) about the
    line through ``point`` along ``axis`` (normalised) and translation ``d`` along it, so that
    ``T2 = D @ T1``. ``Q = I + sin(theta) [u]x + 2 sin^2(theta/2) [u]x^2`` (Rodrigues) and
    ``q = (I - Q) point + d u``, the latter as ``2 sin^2(theta/2) c - sin(theta) u x c`` with
    ``c`` the part of ``point`` normal to ``u`` (accurate even for far-away axes).

    >>> D = pose_from_screw([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], np.pi, 0.0)  # half turn about x = 1
    >>> np.round(D[:3, 3], 12) + 0.0
    array([2., 0., 0.])
    """
    u = as_unit_vector(axis, "axis", normalize=True)
    c = as_array(point, shape_tail=(3,), name="point")
    theta = as_array(theta, name="theta")
    d = as_array(d, name="d")
    s, h2 = np.sin(theta), 2.0 * np.sin(0.5 * theta) ** 2
    K = skew(u)
    Q = np.eye(3) + s[..., None, None] * K + h2[..., None, None] * (K @ K)
    c = c - _dot(c, u)[..., None] * u
    q = h2[..., None] * c - s[..., None] * np.cross(u, c) + d[..., None] * u
    return make_pose(Q, q)


def interpolate_screw(T1, T2, s, **kw) -> np.ndarray:
    """Pose(s) at fraction ``s`` of the screw motion from ``T1`` to ``T2`` (``s = 0`` gives
    ``T1``, ``s = 1`` gives ``T2``): rotation ``s theta`` and translation ``s d`` about/along the
    fixed screw axis (Nadkarni's screw path, analysis type II). ``s`` broadcasts against the
    batch shape of the poses; values outside [0, 1] extrapolate.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> interpolate_screw(np.eye(4), trans([2.0, 0.0, 0.0]), 0.25)[:3, 3]
    array([0.5, 0. , 0. ])
    """
    sc = screw_from_poses(T1, T2, **kw)
    s = as_array(s, name="s")
    D = pose_from_screw(sc.axis, sc.point, s * sc.theta, s * sc.d)
    return D @ np.asarray(T1, dtype=float)
