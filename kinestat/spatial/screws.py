"""Twists and wrenches as screws ``(..., 6)``.

A twist is ``[w; v_O]`` (angular velocity, then the velocity of the point of the body at the
origin: axis coordinates); a wrench is ``[f; m_O]`` (force, then moment about the origin: ray
coordinates, the seeds' ``f {S; S0L}``). Both are "direction part first, moment part second", so
the same algebra serves both:

* one 6x6 :func:`adjoint` changes the frame of twists *and* wrenches (``w' = R w``,
  ``v' = R v + p x R w``; ``f' = R f``, ``m' = R m + p x R f``);
* the power of a wrench on a twist is the :func:`reciprocal_product` ``w . m + v . f``, which that
  adjoint leaves unchanged (``Ad^T Pi Ad = Pi`` with ``Pi = [[0, I], [I, 0]]``).

Pitch ``h = a . b / a . a`` for a screw ``[a; b]``; the axis is the line ``{a/|a|; (b - h a)/|a|}``
(Vibhute Appendix A, Nadkarni eq. 4-5). A screw with ``a = 0`` (a pure translation, or a couple)
has infinite pitch and its axis direction is ``b/|b|``.
"""

from __future__ import annotations

import numpy as np

from kinestat.errors import InputError
from kinestat.spatial.plucker import normalize_line
from kinestat.spatial.transforms import as_array, skew
from kinestat.spatial.validate import as_pose

__all__ = [
    "twist",
    "wrench",
    "adjoint",
    "transform_twist",
    "transform_wrench",
    "reciprocal_product",
    "power",
    "pitch",
    "screw_magnitude",
    "screw_axis",
    "screw_from_axis",
    "twist_matrix",
]


def _dot(a, b) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def _where(mask: np.ndarray) -> str:
    if mask.ndim == 0:
        return ""
    return f" at batch index {tuple(int(i) for i in np.argwhere(mask)[0])}"


def twist(omega, v) -> np.ndarray:
    """Twist ``[w; v_O]`` ``(..., 6)`` from angular velocity and the origin point's velocity.

    >>> twist([0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    array([0., 0., 1., 1., 0., 0.])
    """
    w = as_array(omega, shape_tail=(3,), name="omega")
    v = as_array(v, shape_tail=(3,), name="v")
    return np.concatenate(np.broadcast_arrays(w, v), axis=-1)


def wrench(force, moment) -> np.ndarray:
    """Wrench ``[f; m_O]`` ``(..., 6)`` from a force and its moment about the origin.

    >>> wrench([0.0, 0.0, -10.0], [0.0, 0.0, 0.0])
    array([  0.,   0., -10.,   0.,   0.,   0.])
    """
    f = as_array(force, shape_tail=(3,), name="force")
    m = as_array(moment, shape_tail=(3,), name="moment")
    return np.concatenate(np.broadcast_arrays(f, m), axis=-1)


def adjoint(T) -> np.ndarray:
    """6x6 matrices ``[[R, 0], [[p]x R, R]]`` ``(..., 6, 6)`` of poses ``T`` (pose of B in A).

    Maps twists and wrenches written in B to the same twists and wrenches written in A.

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> adjoint(trans([1.0, 0.0, 0.0])).shape
    (6, 6)
    """
    T = as_pose(T, "T")
    R, p = T[..., :3, :3], T[..., :3, 3]
    out = np.zeros(T.shape[:-2] + (6, 6))
    out[..., :3, :3] = R
    out[..., 3:, 3:] = R
    out[..., 3:, :3] = skew(p) @ R
    return out


def transform_twist(T, V) -> np.ndarray:
    """Twist ``V`` written in frame B, rewritten in frame A (``T`` = pose of B in A).

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> spin = twist([0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    >>> transform_twist(trans([1.0, 0.0, 0.0]), spin)  # the spin about the line x = 1
    array([ 0.,  0.,  1.,  0., -1.,  0.])
    """
    V = as_array(V, shape_tail=(6,), name="twist")
    return np.einsum("...ij,...j->...i", adjoint(T), V)


def transform_wrench(T, W) -> np.ndarray:
    """Wrench ``W`` written in frame B, rewritten in frame A (``T`` = pose of B in A).

    >>> from kinestat.spatial.transforms import rot_z, trans
    >>> transform_wrench(trans([1.0, 0.0, 0.0]), wrench([0.0, 0.0, -10.0], [0.0, 0.0, 0.0]))
    array([  0.,   0., -10.,   0.,  10.,   0.])
    """
    W = as_array(W, shape_tail=(6,), name="wrench")
    return np.einsum("...ij,...j->...i", adjoint(T), W)


def reciprocal_product(s1, s2) -> np.ndarray:
    """Reciprocal product ``a1 . b2 + b1 . a2`` of screws ``[a1; b1]`` and ``[a2; b2]``.

    >>> spin, push = twist([0.0, 0, 1.0], [0.0, 0, 0]), wrench([0.0, 0, 1.0], [0.0, 0, 0])
    >>> float(reciprocal_product(spin, push))  # coaxial, both of zero pitch
    0.0
    """
    s1 = as_array(s1, shape_tail=(6,), name="screw 1")
    s2 = as_array(s2, shape_tail=(6,), name="screw 2")
    return _dot(s1[..., :3], s2[..., 3:]) + _dot(s1[..., 3:], s2[..., :3])


def power(V, W) -> np.ndarray:
    """Power ``w . m_O + v_O . f`` of wrench ``W`` on twist ``V`` (same frame); frame invariant.

    >>> V, W = twist([0.0, 0.0, 2.0], [1.0, 0.0, 0.0]), wrench([3.0, 0.0, 0.0], [0.0, 0.0, 0.5])
    >>> float(power(V, W))  # f·v_O + m_O·ω = 3 + 1
    4.0
    """
    return reciprocal_product(V, W)


def _split(s, tol: float, name: str):
    s = as_array(s, shape_tail=(6,), name=name)
    a, b = s[..., :3], s[..., 3:]
    na, nb = np.linalg.norm(a, axis=-1), np.linalg.norm(b, axis=-1)
    zero = (na == 0.0) & (nb == 0.0)
    if np.any(zero):
        raise InputError(f"{name} is zero{_where(zero)}: a zero screw has no pitch or axis")
    infinite = na <= tol * nb
    return a, b, na, nb, infinite


def pitch(s, *, tol: float = 1e-12) -> np.ndarray:
    """Pitch ``h = a . b / a . a`` of screws ``[a; b]``; ``inf`` where ``|a| <= tol |b|``.

    For a twist: translation per radian along the axis; for a wrench: couple per unit force.

    >>> float(pitch([0.0, 0.0, 1.0, 0.0, 0.0, 0.5]))
    0.5
    """
    a, b, na, _, infinite = _split(s, tol, "screw")
    return np.where(infinite, np.inf, _dot(a, b) / np.where(infinite, 1.0, na * na))


def screw_magnitude(s, *, tol: float = 1e-12) -> np.ndarray:
    """``|a|`` of screws ``[a; b]`` (angular speed, force), or ``|b|`` where the pitch is
    infinite (translation speed, couple).

    >>> float(screw_magnitude([0.0, 0.0, 2.0, 0.0, 0.0, 1.0]))
    2.0
    """
    _, _, na, nb, infinite = _split(s, tol, "screw")
    return np.where(infinite, nb, na)


def screw_axis(s, *, tol: float = 1e-12) -> np.ndarray:
    """Axis line ``[S; S0]`` ``(..., 6)`` of screws ``[a; b]``: ``S = a/|a|``,
    ``S0 = (b - h a)/|a|``. For infinite pitch, the line through the origin along ``b``
    (every parallel line is an axis then).

    >>> screw_axis([0.0, 0.0, 2.0, 2.0, 0.0, 1.0])
    array([0., 0., 1., 1., 0., 0.])
    """
    a, b, na, nb, infinite = _split(s, tol, "screw")
    sa = np.where(infinite, 1.0, na)[..., None]
    h = np.where(infinite, 0.0, _dot(a, b) / (sa[..., 0] ** 2))[..., None]
    S = np.where(infinite[..., None], b / np.where(infinite, nb, 1.0)[..., None], a / sa)
    S0 = np.where(infinite[..., None], 0.0, (b - h * a) / sa)
    return np.concatenate([S, S0], axis=-1)


def screw_from_axis(line, pitch, magnitude=1.0) -> np.ndarray:
    """Screw ``magnitude * [S; S0 + h S]`` on axis ``line`` with pitch ``h``; for ``h = inf``,
    ``magnitude * [0; S]``. A twist (``magnitude`` = angular speed) or a wrench (force).

    >>> screw_from_axis([0.0, 0.0, 1.0, 0.0, 0.0, 0.0], 0.5, 2.0)
    array([0., 0., 2., 0., 0., 1.])
    """
    L = normalize_line(line)
    h = np.asarray(pitch, dtype=float)
    if np.any(np.isnan(h)):
        raise InputError("pitch is NaN: give a finite pitch or inf for a pure translation/couple")
    m = as_array(magnitude, name="magnitude")
    shape = np.broadcast_shapes(L.shape[:-1], h.shape, m.shape)
    S = np.broadcast_to(L[..., :3], shape + (3,))
    S0 = np.broadcast_to(L[..., 3:], shape + (3,))
    h = np.broadcast_to(h, shape)
    inf = np.isinf(h)[..., None]
    a = np.where(inf, 0.0, S)
    b = np.where(inf, S, S0 + np.where(inf, 0.0, h[..., None]) * S)
    return np.asarray(m)[..., None] * np.concatenate([a, b], axis=-1)


def twist_matrix(V) -> np.ndarray:
    """4x4 matrices ``[[w]x, v; 0, 0]`` of twists ``[w; v]``; ``expm`` of it (times t) is the
    rigid displacement produced by the twist in time t.

    >>> twist_matrix([0.0, 0.0, 1.0, 1.0, 0.0, 0.0]) + 0.0
    array([[ 0., -1.,  0.,  1.],
           [ 1.,  0.,  0.,  0.],
           [ 0.,  0.,  0.,  0.],
           [ 0.,  0.,  0.,  0.]])
    """
    V = as_array(V, shape_tail=(6,), name="twist")
    out = np.zeros(V.shape[:-1] + (4, 4))
    out[..., :3, :3] = skew(V[..., :3])
    out[..., :3, 3] = V[..., 3:]
    return out
