"""Singular configurations and architecturally singular designs of the platform.

A pose is singular when the six leg lines are linearly dependent (rank of the line Jacobian
``j`` below six, Vibhute 2011 after eq. 2-8): the legs cannot balance some wrench and the top
has an infinitesimal freedom. A *design* is architecturally singular when this happens at every
pose: then the platform has a self-motion and no forward kinematics or statics is possible.

For the special 6-6 this has a closed form. Each leg's squared length is a fixed combination of
two squared lengths of the equivalent 3-3, with weights ``1 − t`` and ``t`` (``t`` the fraction
of the edge at which the edge point sits). The six equations are solvable for the 3-3 lengths
unless ``Π(1 − t_i) = Π t_i``; then a one-parameter family of 3-3 platforms — a continuum of
poses — has the same six leg lengths: a self-motion at every pose. The layout with every edge
point at its edge's midpoint (all t = 1/2, the Griffis–Duffy "midpoint" platform, cf. Husty &
Karger) is the best known case.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from kinestat.errors import ModelError
from kinestat.parallel._refine import apply_twist
from kinestat.parallel.legs import line_jacobian

if TYPE_CHECKING:  # the platform builder calls check_design
    from kinestat.parallel.platform import Platform

__all__ = ["singularity_measure", "reduction_products", "reduction_conditioning",
           "is_architecturally_singular", "check_design"]

#: Below this, a dimensionless measure counts as singular.
SINGULAR_TOL = 1e-9


def singularity_measure(platform: Platform, pose) -> np.ndarray:
    """Dimensionless |det| of the line Jacobian with moments divided by ``platform.scale``.

    0 at a singular pose; of order 1 for a well-conditioned one (columns are unit lines).
    Batched over poses (...,4,4) → (...).
    """
    j = line_jacobian(platform, pose).copy()
    j[..., 3:, :] /= platform.scale
    return np.abs(np.linalg.det(j))


def reduction_products(t) -> tuple[float, float]:
    """(Π(1 − t), Π t) of the six edge fractions: equal when the special 6-6 → 3-3 reduction is
    singular (its determinant is their difference).

    >>> reduction_products([0.5] * 6)
    (0.015625, 0.015625)
    """
    t = np.asarray(t, dtype=float)
    return float(np.prod(1.0 - t)), float(np.prod(t))


def reduction_conditioning(t) -> float:
    """|Π(1 − t) − Π t| / max(Π(1 − t), Π t): 0 when the special 6-6 → 3-3 reduction is singular."""
    a, b = reduction_products(t)
    den = max(abs(a), abs(b), 1e-300)
    return abs(a - b) / den


def _sample_poses(platform: Platform, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    tw = rng.normal(size=(n, 6)) * np.r_[0.15, 0.15, 0.15, [0.1 * platform.scale] * 3]
    return apply_twist(np.broadcast_to(platform.home_pose, (n, 4, 4)), tw)


def is_architecturally_singular(platform: Platform, samples: int = 8, seed: int = 0) -> bool:
    """True if the line Jacobian is singular at every one of ``samples`` random poses near home."""
    m = singularity_measure(platform, _sample_poses(platform, samples, seed))
    return bool(np.all(m < SINGULAR_TOL))


def check_design(platform: Platform) -> None:
    """Refuse architecturally singular designs (and a singular home pose) with an explanation.

    Raises:
        ModelError: the design has a self-motion, or its home pose is singular.

    >>> from kinestat.parallel.platform import special_6_6
    >>> check_design(special_6_6())   # the 2011 prototype: accepted; all edge midpoints: refused
    >>> special_6_6(base_offset=60.0, top_offset=30.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    kinestat.errors.ModelError: platform 'special-6-6' is architecturally singular: ...
    """
    lay = platform.layout
    if lay is not None and reduction_conditioning(lay.t) < SINGULAR_TOL:
        t = np.round(lay.t, 6).tolist()
        raise ModelError(
            f"platform {platform.name!r} is architecturally singular: its edge points sit at "
            f"edge fractions t = {t} with prod(1 - t) = prod(t) (e.g. every point at an edge "
            "midpoint), so the six leg lengths fix the equivalent 3-3 only up to a "
            "one-parameter family: the top has a self-motion at every pose and cannot sense "
            "or resist some wrench. Move the edge points (e.g. offsets 28 and 14 on sides 120 "
            "and 60, as the 2011 prototype)")
    if is_architecturally_singular(platform):
        raise ModelError(
            f"platform {platform.name!r} is architecturally singular: the six leg lines are "
            "linearly dependent at every pose tested near home (a self-motion). Change the "
            "attachment points")
    if singularity_measure(platform, platform.home_pose) < SINGULAR_TOL:
        raise ModelError(
            f"the home pose of platform {platform.name!r} is a singular configuration (the leg "
            "lines are linearly dependent there); choose another home height or twist")
