"""Paden–Kahan subproblems, batched (Paden 1986; Murray, Li & Sastry 1994, §3.2.2).

Every argument broadcasts over leading batch dimensions; axes are unit vectors ``ω (..., 3)``
through points ``r (..., 3)``; angles are radians. Each function returns the angle(s) and a mask
saying where a real solution exists (within ``tol``). ``rotate`` is the exponential
``e^{ξ̂θ}`` of a revolute twist applied to points.
"""

from __future__ import annotations

import numpy as np

__all__ = ["rotation_matrix", "rotate", "sp1", "sp2", "sp3", "sp4"]


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def rotation_matrix(w, theta) -> np.ndarray:
    """Rodrigues' formula ``R = I + sin θ [ω] + (1 − cos θ) [ω]²`` (MLS eq. 2.14), ``(..., 3, 3)``.

    >>> np.round(rotation_matrix(np.array([0, 0, 1.0]), np.pi / 2) @ [1.0, 0, 0], 12)
    array([0., 1., 0.])
    """
    w = np.asarray(w, dtype=float)
    th = np.asarray(theta, dtype=float)
    c, s = np.cos(th)[..., None, None], np.sin(th)[..., None, None]
    z = np.zeros(np.broadcast_shapes(w.shape[:-1], th.shape))
    wx, wy, wz = (np.broadcast_to(w[..., i], z.shape) for i in range(3))
    K = np.stack([np.stack([z, -wz, wy], -1), np.stack([wz, z, -wx], -1),
                  np.stack([-wy, wx, z], -1)], -2)
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def rotate(w, r, theta, x) -> np.ndarray:
    """``r + R(ω, θ)(x − r)``: the point x rotated by θ about the axis (ω, r)."""
    R = rotation_matrix(w, theta)
    return r + np.einsum("...ij,...j->...i", R, x - r)


def sp1(w, r, p, q, tol: float = 1e-9):
    """Subproblem 1: θ with ``e^{ξ̂θ} p = q`` (rotation about one axis; MLS §3.2.2).

    ``θ = atan2(ωᵀ(u' × v'), u'ᵀv')`` with u', v' the projections of ``p − r``, ``q − r`` on the
    plane normal to ω. Returns ``(θ, exists, free)``: ``exists`` where the projections have equal
    length and equal height along ω (within ``tol``); ``free`` where p lies on the axis (every θ).
    """
    u, v = p - r, q - r
    up = u - _dot(u, w)[..., None] * w
    vp = v - _dot(v, w)[..., None] * w
    th = np.arctan2(_dot(w, np.cross(up, vp)), _dot(up, vp))
    nu, nv = np.linalg.norm(up, axis=-1), np.linalg.norm(vp, axis=-1)
    scale = 1.0 + np.maximum(nu, nv)
    exists = (np.abs(nu - nv) <= tol * scale) & (np.abs(_dot(w, u - v)) <= tol * scale)
    return th, exists, nu <= tol * scale


def sp2(w1, w2, r, p, q, tol: float = 1e-9):
    """Subproblem 2: θ1, θ2 with ``e^{ξ̂1θ1} e^{ξ̂2θ2} p = q`` for axes meeting at r (MLS §3.2.2).

    The intermediate point ``c = r + α ω1 + β ω2 ± γ (ω1 × ω2)`` with
    ``α = ((ω1ᵀω2) ω2ᵀu − ω1ᵀv) / ((ω1ᵀω2)² − 1)``, ``β = ((ω1ᵀω2) ω1ᵀv − ω2ᵀu) / ((ω1ᵀω2)² − 1)``
    and ``γ² = (|u|² − α² − β² − 2αβ ω1ᵀω2) / |ω1 × ω2|²``; then ``θ2 = sp1(ω2: p → c)``,
    ``θ1 = sp1(ω1: c → q)``. Returns ``(θ1 (..., 2), θ2 (..., 2), exists (...,))`` for the two
    signs of γ (equal when γ = 0).
    """
    u, v = p - r, q - r
    c12 = _dot(w1, w2)
    den = c12 ** 2 - 1.0
    a = (c12 * _dot(w2, u) - _dot(w1, v)) / den
    b = (c12 * _dot(w1, v) - _dot(w2, u)) / den
    x = np.cross(w1, w2)
    g2 = (_dot(u, u) - a * a - b * b - 2.0 * a * b * c12) / _dot(x, x)
    scale = 1.0 + _dot(u, u)
    exists = (g2 >= -tol * scale) & (np.abs(_dot(u, u) - _dot(v, v)) <= tol * scale)
    g = np.sqrt(np.maximum(g2, 0.0))
    sgn = np.array([1.0, -1.0])
    z = (a[..., None, None] * w1[..., None, :] + b[..., None, None] * w2[..., None, :]
         + (g[..., None] * sgn)[..., None] * x[..., None, :])  # (..., 2, 3)
    c = r[..., None, :] + z
    t2, _, _ = sp1(w2[..., None, :], r[..., None, :], p[..., None, :], c)
    t1, _, _ = sp1(w1[..., None, :], r[..., None, :], c, q[..., None, :])
    return t1, t2, exists


def sp3(w, r, p, q, delta, tol: float = 1e-9):
    """Subproblem 3: θ with ``|e^{ξ̂θ} p − q| = δ`` (MLS §3.2.2).

    ``θ = θ0 ± acos((|u'|² + |v'|² − δ'²) / (2 |u'| |v'|))`` with ``θ0`` the angle from u' to v'
    and ``δ'² = δ² − (ωᵀ(p − q))²``. Returns ``(θ (..., 2), exists)``; out-of-range cosines
    within ``tol`` are clipped (a double root).
    """
    u, v = p - r, q - r
    up = u - _dot(u, w)[..., None] * w
    vp = v - _dot(v, w)[..., None] * w
    t0 = np.arctan2(_dot(w, np.cross(up, vp)), _dot(up, vp))
    d2 = delta ** 2 - _dot(w, p - q) ** 2
    nu, nv = np.linalg.norm(up, axis=-1), np.linalg.norm(vp, axis=-1)
    cos = (nu ** 2 + nv ** 2 - d2) / (2.0 * nu * nv)
    exists = (np.abs(cos) <= 1.0 + tol) & (nu * nv > 0)
    acos = np.arccos(np.clip(cos, -1.0, 1.0))
    return np.stack([t0 - acos, t0 + acos], axis=-1), exists


def sp4(h, w, p, d, tol: float = 1e-9):
    """Subproblem 4 (one-axis form): θ with ``hᵀ R(ω, θ) p = d``.

    With ``R p = p∥ + cos θ p⊥ + sin θ (ω × p)``: ``A cos θ + B sin θ = d − hᵀp∥``, so
    ``θ = atan2(B, A) ± acos((d − hᵀp∥) / √(A² + B²))``. Returns ``(θ (..., 2), exists)``.
    """
    par = _dot(w, p)[..., None] * w
    A = _dot(h, p - par)
    B = _dot(h, np.cross(w, p))
    C = d - _dot(h, par)
    n = np.hypot(A, B)
    cos = C / np.where(n > 0, n, 1.0)
    exists = (np.abs(cos) <= 1.0 + tol) & (n > tol)
    phi = np.arctan2(B, A)
    acos = np.arccos(np.clip(cos, -1.0, 1.0))
    return np.stack([phi - acos, phi + acos], axis=-1), exists
