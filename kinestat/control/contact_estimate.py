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
* ``sin α = −û·ŝ`` for a chord in the surface: μ is a property of the contact, so an
  estimate over many cycles is far less noisy than one chord.
* the normal force is ``f_n = f·n̂`` and the friction force ``f − f_n n̂``: the friction is
  measured and reported, not fought.

The controller is not told the surface or μ. Frictionless, ``μ̂ = 0`` and ``n̂ = û``.

**Curvature of the path.** The normal of a curved surface turns as the tip travels: by
``κ Δs`` over a step ``Δs`` (``κ`` the normal curvature along the travel, positive convex).
The measured tips lie in the surface, so a circle fitted to the recent tips in the plane of
the normal and the travel (:func:`fit_circle`, :func:`path_curvature`) measures κ, and the
normal at the next point is predicted by turning the estimate by ``κ Δs`` towards the travel
(:func:`turn_by_curvature`) instead of lagging the surface by a step.

**Probing.** Before the force is raised the tip sticks where it touched, and with friction its
force can lie anywhere in the cone: the normal is not observable from the force. Touches of
the surface around the first contact are surface points, and the plane fitted to them
(:func:`fit_plane`) gives the normal; for touches placed symmetrically about the centre
(``±r`` across and along) the fitted plane's slope is the central difference of the surface,
exact for a quadric, so a curved surface costs no bias at the centre.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "cone_normal",
    "fit_circle",
    "path_curvature",
    "turn_by_curvature",
    "fit_plane",
]


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


def fit_circle(x, y) -> np.ndarray:
    """The algebraic circle ``A (x² + y²) + B x − y + D = 0`` fitted to points (x, y) by linear
    least squares in the residual of ``y`` (a Kåsa fit normalised on the ``y`` coefficient, so
    a straight line ``y = B x + D`` is the case ``A = 0``: well conditioned for flat paths;
    exact for exact points on any circle not centred on the x axis — with x along the path
    and y along its normal, the centre is off it).

    Shapes: x, y (N,) with N ≥ 3 → (3,) ``[A, B, D]``.

    >>> (np.round(fit_circle([-0.6, 0.0, 0.6], [-0.2, 0.0, -0.2]), 12) + 0.0).tolist()
    [-0.5, 0.0, 0.0]
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    M = np.column_stack([x * x + y * y, x, np.ones_like(x)])
    coef, *_ = np.linalg.lstsq(M, y, rcond=None)
    return coef


def path_curvature(points, tip, normal, tangent, min_span: float,
                   noise: float = 0.0) -> float:
    """The normal curvature (1/mm, positive where the surface is convex: the circle's centre
    inside the material, on the −``normal`` side) of the tip path along ``tangent``: the
    points (and ``tip``) in the plane of ``tangent`` and ``normal`` through ``tip``, a circle
    fitted (:func:`fit_circle`), ``κ = −2A / sqrt(B² + 1 − 4AD)`` (the signed inverse radius).
    0 when the points span less than ``min_span`` mm along the tangent, are fewer than 4, or
    when the arc's sagitta ``|κ| span²/8`` is below twice the fit's RMS residual (noise) or
    below ``noise`` mm (a scatter of the points that a few of them need not show).

    Shapes: points (N, 3), tip/normal/tangent (3,) (unit, perpendicular).

    >>> a = np.linspace(0.0, 0.05, 6)
    >>> pts = np.column_stack([100 * np.sin(a), 100 * np.cos(a) - 100, 0 * a])
    >>> round(path_curvature(pts[:-1], pts[-1], pts[-1] / 100 + [0, 1, 0],
    ...                      [math.cos(0.05), -math.sin(0.05), 0.0], 1.0), 12)
    0.01
    """
    P = np.asarray(points, dtype=float) - np.asarray(tip, dtype=float)
    if len(P) < 3:
        return 0.0
    x = np.concatenate([P @ tangent, [0.0]])
    if float(x.max() - x.min()) < min_span:
        return 0.0
    y = np.concatenate([P @ normal, [0.0]])
    A, B, D = fit_circle(x, y)
    kappa = float(-2.0 * A / math.sqrt(max(B * B + 1.0 - 4.0 * A * D, 1e-12)))
    # significance: the arc's sagitta over the span must exceed twice the fit's residual
    # (the measured tips' noise); a noisy straight path fits a spurious curvature
    resid = y - (A * (x * x + y * y) + B * x + D)
    span = float(x.max() - x.min())
    if abs(kappa) * span * span / 8.0 < max(2.0 * float(np.sqrt(np.mean(resid * resid))),
                                            noise):
        return 0.0
    return kappa


def turn_by_curvature(normal, tangent, angle: float) -> tuple[np.ndarray, np.ndarray]:
    """The normal and tangent a step further along a path whose normal turns by ``angle``
    (rad, ``κ Δs``; positive turns the normal towards the travel, a convex surface):
    ``n' = cos θ n̂ + sin θ t̂``, ``t' = cos θ t̂ − sin θ n̂``.

    >>> n, t = turn_by_curvature([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], math.pi / 2)
    >>> np.round(n, 12).tolist(), np.round(t, 12).tolist()
    ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0])
    """
    n = np.asarray(normal, dtype=float)
    t = np.asarray(tangent, dtype=float)
    c, s = math.cos(angle), math.sin(angle)
    return c * n + s * t, c * t - s * n


def fit_plane(points, approach) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The plane of surface points touched along ``approach``: the least-squares fit of their
    height against the approach, ``H = α + β x + γ y`` (``x, y`` along two axes ⊥ approach),
    and its unit normal facing against the approach, ``−d̂ − β û − γ v̂``.

    The height fit, not the points' principal plane, is what makes a symmetric pattern
    exact on a curved surface: for touches at the centre and ``±r`` along two axes the
    slopes are the central differences, exact for any quadric height field.

    Args:
        points: (..., k, 3), k ≥ 3.
        approach: (..., 3) the direction the touches were made along (into the surface).

    Returns:
        normal (..., 3); rms (...), the RMS height residual; spread (...), the smaller RMS
        spread of the touches across the approach (near 0 for collinear touches, where the
        plane is undefined).

    >>> n, rms, spread = fit_plane([[0, 0, 0], [1, 0, -1], [0, 1, 0], [1, 1, -1]], [0, 0, -1])
    >>> (np.round(n * math.sqrt(2), 12) + 0.0).tolist(), round(float(rms), 12)
    ([1.0, 0.0, 1.0], 0.0)
    """
    P = np.asarray(points, dtype=float)
    if P.ndim < 2 or P.shape[-1] != 3 or P.shape[-2] < 3:
        raise ValueError(f"fit_plane: points must be (..., k >= 3, 3), got {P.shape}")
    d = np.broadcast_to(np.asarray(approach, dtype=float), P.shape[:-2] + (3,))
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    a = np.where(np.abs(d[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    u = np.cross(d, a)
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    v = np.cross(d, u)
    k = P.shape[-2]
    Q = P - P.mean(axis=-2, keepdims=True)
    x, y = np.einsum("...kj,...j->...k", Q, u), np.einsum("...kj,...j->...k", Q, v)
    h = -np.einsum("...kj,...j->...k", Q, d)
    A = np.stack([x, y], axis=-1)  # centred: the intercept drops out
    AtA = np.swapaxes(A, -1, -2) @ A
    # pinv: collinear touches give a finite (meaningless) slope and a spread near 0
    slope = (np.linalg.pinv(AtA) @ (np.swapaxes(A, -1, -2) @ h[..., None]))[..., 0]
    res = h - (A @ slope[..., None])[..., 0]
    n = -d - slope[..., :1] * u - slope[..., 1:] * v
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    spread = np.sqrt(np.maximum(np.linalg.eigvalsh(AtA)[..., 0], 0.0) / k)
    return n, np.sqrt(np.mean(res ** 2, axis=-1)), spread
