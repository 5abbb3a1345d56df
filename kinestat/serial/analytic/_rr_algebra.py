"""The linear algebra of the Raghavan–Roth elimination for the general 6R, batched.

Raghavan & Roth (1993) close the loop ``C0 Z1 C1 … Z6 C6 = T`` as ::

    C2 Z3 C3 Z4 C4 Z5 C5 = Z2⁻¹ C1⁻¹ Z1⁻¹ (C0⁻¹ T C6⁻¹) Z6⁻¹                (RR eq. 4)

and take, of both sides, the image ``p`` of the origin and ``l`` of the z direction (θ6 drops
out). The 14 quantities ``p, l, p·p, p·l, p×l, (p·p) l − 2 (p·l) p`` (RR eqs. 9–14) transform
*linearly* under any rigid motion and under a joint rotation ``Rz(θ) = D0 + cos θ Dc + sin θ
Ds``; with a leading constant 1 they form the 15-vector :func:`invariants` and every rigid motion
acts on it by the 15x15 matrix :func:`rigid_action`. So the left side is a trilinear form in
``(1, cos θk, sin θk)``, k = 3, 4, 5 (a ``(15, 3, 3, 3)`` tensor, fixed by the model) and the right
side a bilinear form in ``(1, cos θk, sin θk)``, k = 1, 2 (a ``(15, 3, 3)`` tensor per pose): the
14 equations ``P(θ3) R(θ4, θ5) = Q S(θ1, θ2)`` of Manocha & Canny (1994, eq. 9) without any
symbolic expansion.

Index of the 15-vector: 0 the constant 1; 1–3 p; 4–6 l; 7 p·p; 8 p·l; 9–11 p×l; 12–14
(p·p) l − 2 (p·l) p.
"""

from __future__ import annotations

import numpy as np

__all__ = ["invariants", "rigid_action", "joint_basis", "HALF_ANGLE", "left_tensor",
           "right_tensor"]

_P, _L, _PP, _PL, _X, _V = slice(1, 4), slice(4, 7), 7, 8, slice(9, 12), slice(12, 15)

HALF_ANGLE = np.array([[1.0, 0.0, 1.0], [1.0, 0.0, -1.0], [0.0, 2.0, 0.0]])
"""Row m: the coefficients of ``x⁰, x¹, x²`` of ``(1 + x²)·m`` for ``m = 1, cos θ, sin θ`` with
``x = tan(θ/2)`` (the half-angle substitution of RR §3)."""


def _skew(t: np.ndarray) -> np.ndarray:
    z = np.zeros(t.shape[:-1])
    return np.stack([np.stack([z, -t[..., 2], t[..., 1]], -1),
                     np.stack([t[..., 2], z, -t[..., 0]], -1),
                     np.stack([-t[..., 1], t[..., 0], z], -1)], -2)


def invariants(p: np.ndarray, l: np.ndarray) -> np.ndarray:
    """The 15-vector ``(1, p, l, p·p, p·l, p×l, (p·p) l − 2 (p·l) p)`` (RR eqs. 9–14), batched.

    ``p, l``: ``(..., 3)``; returns ``(..., 15)``.

    >>> invariants(np.array([1.0, 0, 0]), np.array([0, 0, 1.0]))[[0, 7, 8]]
    array([1., 1., 0.])
    """
    p = np.asarray(p, dtype=float)
    l = np.asarray(l, dtype=float)  # noqa: E741
    pp = np.sum(p * p, axis=-1, keepdims=True)
    pl = np.sum(p * l, axis=-1, keepdims=True)
    one = np.ones_like(pp)
    return np.concatenate([one, p, l, pp, pl, np.cross(p, l), pp * l - 2.0 * pl * p], axis=-1)


def rigid_action(T: np.ndarray) -> np.ndarray:
    """The 15x15 matrix M with ``invariants(R p + t, R l) = M · invariants(p, l)`` for a rigid
    ``T (..., 4, 4)``; returns ``(..., 15, 15)``.

    Derived from ``p' = R p + t``, ``l' = R l``: ``p'·p' = p·p + 2 tᵀR p + t·t``,
    ``p'·l' = p·l + tᵀR l``, ``p'×l' = R(p×l) + [t]× R l`` and
    ``v' = R v − 2 [t]× R (p×l) + (t·t) R l − 2 t tᵀ R l − 2 (p·l) t``.
    """
    T = np.asarray(T, dtype=float)
    R, t = T[..., :3, :3], T[..., :3, 3]
    tx = _skew(t)
    tt = np.sum(t * t, axis=-1)[..., None, None]
    tR = np.einsum("...i,...ij->...j", t, R)
    M = np.zeros(T.shape[:-2] + (15, 15))
    M[..., 0, 0] = 1.0
    M[..., _P, _P] = R
    M[..., _P, 0] = t
    M[..., _L, _L] = R
    M[..., _PP, _PP] = 1.0
    M[..., _PP, _P] = 2.0 * tR
    M[..., _PP, 0] = tt[..., 0, 0]
    M[..., _PL, _PL] = 1.0
    M[..., _PL, _L] = tR
    M[..., _X, _X] = R
    M[..., _X, _L] = tx @ R
    M[..., _V, _V] = R
    M[..., _V, _X] = -2.0 * tx @ R
    M[..., _V, _L] = tt * R - 2.0 * t[..., :, None] * tR[..., None, :]
    M[..., _V, _PL] = -2.0 * t
    return M


def joint_basis(sign: float = 1.0) -> np.ndarray:
    """``(3, 15, 15)``: D0, Dc, Ds with ``rigid_action(Rz(θ)) = D0 + cos θ Dc + sign sin θ Ds``.

    ``sign = -1`` gives the inverse rotation ``Rz(−θ)`` in the monomials of θ.
    """
    R0 = np.diag([0.0, 0.0, 1.0])
    Rc = np.diag([1.0, 1.0, 0.0])
    Rs = sign * np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    out = np.zeros((3, 15, 15))
    for k, Rk in enumerate((R0, Rc, Rs)):
        for blk in (_P, _L, _X, _V):
            out[k, blk, blk] = Rk
    out[0, 0, 0] = out[0, _PP, _PP] = out[0, _PL, _PL] = 1.0
    return out


def _rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def left_tensor(C2, C3, C4, C5, offsets) -> np.ndarray:
    """``(..., 15, 3, 3, 3)``: the invariants of ``C2 Z3 C3 Z4 C4 Z5 C5 (o, z)`` (RR eq. 4's left).

    Entry ``[..., :, a, b, c]`` multiplies ``m_a(φ3) m_b(φ4) m_c(φ5)`` with ``m = (1, cos, sin)``
    and ``θk = φk + offsets[k-3]`` (constant shifts that keep θk = π off the half-angle pole).
    The ``Ck (..., 4, 4)`` broadcast.
    """
    D = joint_basis(1.0)
    f0 = invariants(np.zeros(3), np.array([0.0, 0.0, 1.0]))
    v5 = rigid_action(_rz(offsets[2]) @ C5) @ f0  # (..., 15)
    t5 = np.einsum("cij,...j->...ic", D, v5)
    t4 = np.einsum("bij,...jk,...kc->...ibc", D, rigid_action(_rz(offsets[1]) @ C4), t5)
    t3 = np.einsum("aij,...jk,...kbc->...iabc", D, rigid_action(_rz(offsets[0]) @ C3), t4)
    return np.einsum("...ij,...jabc->...iabc", rigid_action(C2), t3)


def right_tensor(C1) -> np.ndarray:
    """``(..., 3, 3, 15, 15)`` K with
    ``invariants(Z2⁻¹ C1⁻¹ Z1⁻¹ (p, l)) = Σ m_a(θ1) m_b(θ2) K[a, b] f`` (RR eq. 4's right side
    before the pose ``(p, l)`` is applied)."""
    Dm = joint_basis(-1.0)
    M1 = rigid_action(np.linalg.inv(C1))
    return np.einsum("bij,...jk,akl->...abil", Dm, M1, Dm)
