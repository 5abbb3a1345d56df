"""Planar spring examples of Vibhute 2011 §2.1.3.1 (after Duffy and Griffis), batched.

Springs in parallel and in series (eqs. 2-10, 2-11) and the planar two-spring coupling of
Fig. 2-8: point P joined by springs to pivots A and B. With ``θ_i`` the direction of spring
``i`` from its pivot to P, ``c_i = cos θ_i``, ``s_i = sin θ_i``, ``l_i`` its length, ``l0_i``
its free length and ``ρ_i = l0_i / l_i``, the external force that holds P is (eq. 2-12)::

    [fx; fy] = [c1 c2; s1 s2] [k1 l1 (1 − ρ1); k2 l2 (1 − ρ2)]

(positive ``l − l0``: the spring is stretched and pulls P toward its pivot, so the external
force points away from the pivot, as for the platform's legs) and its stiffness, the derivative
of the force with respect to P's position, is (eqs. 2-14, 2-15)::

    K = j diag(k) jᵀ + δj diag(k (1 − ρ)) δjᵀ,   j = [c1 c2; s1 s2],  δj = [−s1 −s2; c1 c2]

``δj`` is the derivative of ``j`` with respect to the angles. Unloaded (ρ = 1) only the first
term is left (eq. 2-25). A point has no rotation, so unlike the spatial platform this K is
symmetric under any load. When θ1 = θ2 (mod π) the springs are parallel and K is singular.
"""

from __future__ import annotations

import numpy as np

from kinestat.errors import InputError, SingularityError
from kinestat.spatial.transforms import as_array

__all__ = [
    "springs_in_parallel",
    "springs_in_series",
    "two_spring_geometry",
    "two_spring_force",
    "two_spring_stiffness",
    "two_spring_compliance",
]


def _positive(k, name: str) -> np.ndarray:
    k = as_array(k, name=name)
    if np.any(k <= 0):
        raise InputError(f"{name} must be positive, got {np.asarray(k).tolist()}")
    return k


def springs_in_parallel(k) -> np.ndarray:
    """Equivalent constant of springs in parallel, ``k_p = Σ k_i`` (eq. 2-10); last axis summed."""
    return np.sum(_positive(k, "spring constants"), axis=-1)


def springs_in_series(k) -> np.ndarray:
    """Equivalent constant of springs in series, ``1/k_s = Σ 1/k_i`` (eq. 2-11)."""
    return 1.0 / np.sum(1.0 / _positive(k, "spring constants"), axis=-1)


def two_spring_geometry(pivots, point):
    """(j, δj, l): the 2×2 direction matrix, its angle derivative and the spring lengths (..., 2).

    ``pivots`` (2, 2) or (..., 2, 2): A and B; ``point`` (..., 2): P.
    """
    piv = as_array(pivots, shape_tail=(2, 2), name="pivots")
    P = as_array(point, shape_tail=(2,), name="point")
    d = P[..., None, :] - piv  # (..., 2 springs, 2)
    l = np.linalg.norm(d, axis=-1)
    if np.any(l <= 0):
        raise InputError("the point coincides with a pivot: the spring direction is undefined")
    u = d / l[..., None]
    j = np.swapaxes(u, -1, -2)  # columns (c_i, s_i)
    dj = np.stack([-j[..., 1, :], j[..., 0, :]], axis=-2)  # columns (−s_i, c_i)
    return j, dj, l


def two_spring_force(pivots, point, k, free_lengths) -> np.ndarray:
    """External force (..., 2) holding P against the two springs (Vibhute eq. 2-12)."""
    j, _, l = two_spring_geometry(pivots, point)
    k = _positive(k, "spring constants")
    l0 = _positive(free_lengths, "free lengths")
    return np.einsum("...ij,...j->...i", j, k * (l - l0))


def two_spring_stiffness(pivots, point, k, free_lengths) -> np.ndarray:
    """Stiffness (..., 2, 2) of the two-spring coupling at P (Vibhute eqs. 2-14, 2-15)."""
    j, dj, l = two_spring_geometry(pivots, point)
    k = _positive(k, "spring constants")
    l0 = _positive(free_lengths, "free lengths")
    kg = k * (1.0 - l0 / l)
    return (np.einsum("...ai,...i,...bi->...ab", j, k * np.ones_like(l), j)
            + np.einsum("...ai,...i,...bi->...ab", dj, kg, dj))


def two_spring_compliance(pivots, point, k, free_lengths, *, tol: float = 1e-12) -> np.ndarray:
    """Compliance K⁻¹ (..., 2, 2); SingularityError when the springs are (nearly) parallel."""
    K = two_spring_stiffness(pivots, point, k, free_lengths)
    det = np.linalg.det(K)
    scale = np.einsum("...ii->...", K) ** 2
    if np.any(np.abs(det) <= tol * scale):
        raise SingularityError("the two springs are parallel (θ1 = θ2 mod π) or the coupling "
                               "has no stiffness across them: K is singular, eq. 2-11 applies")
    return np.linalg.inv(K)
