"""The contact estimate of a sliding point contact with Coulomb friction (issue 13).

A tip sliding on a surface with friction coefficient μ feels the force
``f = f_n (n̂ − μ ŝ)`` (on the tool; ``n̂`` the surface normal out of the material, ``ŝ`` the
unit slip direction in the tangent plane): the force lies on the edge of the friction cone,
tilted from the normal by ``α = atan μ`` away from the slip. Its direction alone is therefore a
biased normal (by α ≈ 16.7° at μ = 0.3). The slip direction is known to the controller (the
chord of its measured tip path, which lies in the surface), so the bias can be removed:

* ``û = f/|f|`` and ``ĝ``, the slip direction made perpendicular to ``û``, span the plane of
  ``n̂`` and ``ŝ``; in it ``n̂ = cos α û + sin α ĝ`` (:func:`cone_normal`). An error of the
  chord within that plane (its elevation out of the surface: noise, a curved path) does not
  change ``ĝ``; an error across it turns ``n̂`` by only ``μ`` times that error.
* ``sin α = −û·ŝ`` for a chord in the surface (:func:`friction_sample`): one sample of μ per
  sliding cycle; μ is a property of the contact, so its running mean
  (:func:`update_friction`) is far less noisy than one chord.
* the normal force is ``f_n = f·n̂`` and the friction force ``f − f_n n̂``
  (:func:`normal_and_friction`): the friction is measured and reported, not fought.

The controller is not told the surface or μ. Frictionless, ``μ̂ = 0`` and ``n̂ = û``.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "cone_normal",
    "friction_sample",
    "update_friction",
    "normal_and_friction",
    "MIN_FRICTION_WEIGHT",
]

MIN_FRICTION_WEIGHT = 0.05
"""The running mean of μ weights a new sample at least this much (it follows a slow change)."""


def _unit(v) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def cone_normal(force_on_tool, slip, mu) -> np.ndarray:
    """The surface normal (out of the material) of a sliding contact: ``n̂ = cos α û + sin α ĝ``
    with ``α = atan μ``, ``û`` the force on the tool's direction and ``ĝ`` the slip direction
    made perpendicular to ``û`` (Coulomb's law ``f = f_n (n̂ − μ ŝ)``, module docstring).

    Shapes: force_on_tool (..., 3), slip (..., 3), mu (...) → (..., 3).

    >>> n = cone_normal([-0.3, 0.0, 1.0], [1.0, 0.0, 0.1], 0.3)
    >>> np.round(n, 12).tolist()
    [0.0, 0.0, 1.0]
    """
    u = _unit(force_on_tool)
    s = np.asarray(slip, dtype=float)
    g = _unit(s - np.sum(s * u, axis=-1, keepdims=True) * u)
    a = np.arctan(np.asarray(mu, dtype=float))[..., None]
    return np.cos(a) * u + np.sin(a) * g


def friction_sample(force_on_tool, chord) -> float:
    """One sample of the friction coefficient, ``tan α`` with ``sin α = −û·ĉ``: the force on a
    sliding tip leans from the normal by α against the slip ``ĉ`` (a chord of the tip path,
    which lies in the surface). Signed: noise makes it negative at times, and a running mean of
    signed samples is unbiased where a clipped one is not (frictionless contacts).

    >>> round(friction_sample([-0.3, 0.0, 1.0], [2.0, 0.0, 0.0]), 12)
    0.3
    """
    u = _unit(force_on_tool)
    c = _unit(chord)
    s = min(max(-float(u @ c), -0.99), 0.99)
    return s / math.sqrt(1.0 - s * s)


def update_friction(mu: float, samples: int, sample: float) -> tuple[float, int]:
    """The running mean of μ with one more sample (weight ``1/k``, at least
    :data:`MIN_FRICTION_WEIGHT`)."""
    k = samples + 1
    w = max(1.0 / k, MIN_FRICTION_WEIGHT)
    return (1.0 - w) * mu + w * sample, k


def normal_and_friction(force_on_tool, normal) -> tuple[float, np.ndarray]:
    """The normal force ``f·n̂`` (N, positive pressing) and the friction force ``f − (f·n̂) n̂``
    (the tangential part, (3,))."""
    f = np.asarray(force_on_tool, dtype=float)
    n = np.asarray(normal, dtype=float)
    fn = float(f @ n)
    return fn, f - fn * n
