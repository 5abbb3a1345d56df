"""NumPy reference of the PUMA 762 reverse analysis — private, for the tests (the public
functions always run :mod:`kinestat.robots.puma762._kernels`; their deprecated
``backend="numpy"`` switch lands here)."""

from __future__ import annotations

import numpy as np

from kinestat.robots.puma762.forward import pose_residuals
from kinestat.robots.puma762.params import (
    A23,
    N_BRANCHES,
    S2,
    S4,
    S6,
    STATUS_INSIDE_CYLINDER,
    STATUS_OK,
    STATUS_TOO_FAR,
    STATUS_TOO_NEAR,
    _wrap,
)

__all__ = ["reverse_arrays", "reverse_numpy"]


def reverse_arrays(T: np.ndarray, tol: float, s5_tol: float):
    """φ1, θ3, θ2, θ5, θ4, θ6 for poses of frame 6 ``T (*B, 4, 4)``: pure array arithmetic.

    Branch axes: φ1 (i1), θ3 (i3), θ5 (i5); arrays shaped ``(*B, 2, 1)`` depend on φ1 only,
    ``(*B, 1, 2)`` on θ3 only, ``(*B, 2, 2)`` on the arm, ``(*B, 2, 2, 2)`` on all three.
    """
    shape = T.shape[:-2]
    r00, r10, r20 = T[..., 0, 0], T[..., 1, 0], T[..., 2, 0]  # a67_F (x6)
    r02, r12, r22 = T[..., 0, 2], T[..., 1, 2], T[..., 2, 2]  # S6_F (z6)
    # wrist centre W = P6 − S6 · S6_F (the loop closed through the hypothetical link 7)
    wx = T[..., 0, 3] - S6 * r02
    wy = T[..., 1, 3] - S6 * r12
    wz = T[..., 2, 3] - S6 * r22

    # φ1 (eq. 2-47 in fixed-frame form): −sin φ1 Wx + cos φ1 Wy = −S2, two roots; ux is the
    # wrist's distance from S1 along the arm plane, ±sqrt(r² − S2²).
    r = np.hypot(wx, wy)
    inside = r < S2 - tol
    ux = np.sqrt(np.maximum((r - S2) * (r + S2), 0.0))
    ux2 = np.stack([ux, -ux], axis=-1)[..., :, None]  # (*B, 2, 1)
    phi = _wrap(np.arctan2(wy, wx)[..., None, None] + np.arctan2(S2, ux2))

    # θ3 (eq. 2-53): ux² + Wz² = a23² + S4² − 2 a23 S4 sin θ3, two roots ±cos θ3
    rho = np.hypot(ux, wz)
    too_far = rho > A23 + S4 + tol
    too_near = rho < abs(A23 - S4) - tol
    s3 = np.clip((A23 * A23 + S4 * S4 - rho * rho) / (2.0 * A23 * S4), -1.0, 1.0)
    d_near, d_far = abs(A23 - S4), A23 + S4  # cos θ3 from the factored (1 − s3)(1 + s3)
    c3 = np.sqrt(np.maximum((rho - d_near) * (rho + d_near), 0.0)
                 * np.maximum((d_far - rho) * (d_far + rho), 0.0)) / (2.0 * A23 * S4)
    c3_2 = np.stack([c3, -c3], axis=-1)[..., None, :]  # (*B, 1, 2)
    s3b = s3[..., None, None]
    th3 = np.arctan2(s3b, c3_2)

    # θ2 (eqs. 2-50, 2-51): Rz(θ2) (a23 − S4 s3, S4 c3) = (ux, Wz)
    th2 = _wrap(np.arctan2(wz[..., None, None], ux2)
                - np.arctan2(S4 * c3_2, (A23 - S4 * s3b)))  # (*B, 2, 2)

    # Wrist: N = Rx(90°) · F_3R^T · F_6R = Rz(θ4) · Rx(90°) Rz(θ5) Rx(90°) · Rz(θ6), where
    # F_3R = Rz(φ1) Rx(90°) Rz(θ2 + θ3); only N's third column and first column are needed.
    cf, sf = np.cos(phi), np.sin(phi)  # (*B, 2, 1)
    th23 = th2 + th3
    c23, s23 = np.cos(th23), np.sin(th23)  # (*B, 2, 2)
    e = lambda v: v[..., None, None]  # noqa: E731  (*B) -> (*B, 1, 1)
    hz = cf * e(r02) + sf * e(r12)
    hx = cf * e(r00) + sf * e(r10)
    n02 = c23 * hz + s23 * e(r22)
    n12 = cf * e(r12) - sf * e(r02)
    n22 = c23 * e(r22) - s23 * hz
    n00 = c23 * hx + s23 * e(r20)
    n10 = cf * e(r10) - sf * e(r00)
    n20 = c23 * e(r20) - s23 * hx

    # θ5: N[:, 2] = (c4 s5, s4 s5, −c5), two roots ±; |s5| from the first two components
    # (not sqrt(1 − c5²), which loses half the digits near θ5 = 0 or π).
    c5 = -n22
    s5m = np.hypot(n02, n12)
    sign = np.array([1.0, -1.0])
    f = lambda v: v[..., None]  # noqa: E731  (*B, 2, 2) -> (*B, 2, 2, 1)
    s5 = f(s5m) * sign  # (*B, 2, 2, 2)
    th5 = np.arctan2(s5, f(c5))
    sing = np.broadcast_to(f(s5m < s5_tol), s5.shape)
    # θ4 from the third column (scale-free atan2). On a singular branch any θ4 will do: the
    # representative is θ4 = 0 when that moves frame 6 by far less than ``tol`` (|ΔS6| ≤ 2|s5|),
    # otherwise the computed θ4, which reproduces the pose exactly.
    th4 = np.arctan2(f(n12) * sign, f(n02) * sign)
    clean = s5m * 2.0 * (S6 + 1.0) <= 1e-3 * tol
    th4 = np.where(f(clean), 0.0, th4)
    # θ6 from the remainder Rz(θ6) = (Rz(θ4) Rx90 Rz(θ5) Rx90)^T N, exact even near singular:
    # with v = Rz(−θ4) N[:, 0], cos θ6 = c5 v0 + s5 v2 and sin θ6 = −v1.
    c4, s4 = np.cos(th4), np.sin(th4)
    v0 = c4 * f(n00) + s4 * f(n10)
    v1 = c4 * f(n10) - s4 * f(n00)
    th6 = np.arctan2(-v1, f(c5) * v0 + s5 * f(n20))

    q = np.empty(shape + (2, 2, 2, 6))
    q[..., 0] = f(phi)
    q[..., 1] = f(th2)
    q[..., 2] = f(th3)
    q[..., 3] = th4
    q[..., 4] = th5
    q[..., 5] = th6
    q = q.reshape(shape + (N_BRANCHES, 6))
    sing = sing.reshape(shape + (N_BRANCHES,))
    fam_sum = np.broadcast_to(f(c5 < 0.0), s5.shape).reshape(shape + (N_BRANCHES,))
    fam_val = np.where(sing, _wrap(np.where(fam_sum, q[..., 5] + q[..., 3],
                                            q[..., 5] - q[..., 3])), np.nan)

    status = np.full(shape, STATUS_OK, dtype=np.int8)
    status[too_near] = STATUS_TOO_NEAR
    status[too_far] = STATUS_TOO_FAR
    status[inside] = STATUS_INSIDE_CYLINDER
    return q, sing, fam_sum, fam_val, status


def reverse_numpy(T: np.ndarray, verify: bool, tol: float, s5_tol: float):
    """The plain array reference: :func:`reverse_arrays` and :func:`pose_residuals`."""
    q, sing, fam_sum, fam_val, status = reverse_arrays(T, tol, s5_tol)
    valid = np.broadcast_to((status == STATUS_OK)[..., None], sing.shape).copy()
    if verify:
        pe, re = pose_residuals(np.where(valid[..., None], q, 0.0), T[..., None, :, :])
        valid &= (pe <= tol) & (re <= tol)
    else:
        pe = np.full(sing.shape, np.nan)
        re = np.full(sing.shape, np.nan)
    q = np.where(valid[..., None], q, np.nan)
    sing = sing & valid
    fam_val = np.where(sing, fam_val, np.nan)
    return q, valid, sing, fam_sum & sing, fam_val, status, pe, re
