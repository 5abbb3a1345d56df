"""Compiled (Numba) kernels of the closed forms (:mod:`kinestat.serial.analytic.closed_form`
is the NumPy reference): Paden–Kahan subproblems on 3-vectors, one pose per ``prange``
iteration, FK verification and de-duplication in the kernel."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.serial.analytic._rr_kernels import _mm, _mtm, _mtv, _mv, _polish, _wrap

_OPTS = {"cache": True, "nogil": True, "error_model": "numpy"}


@nb.njit(inline="always", **_OPTS)
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@nb.njit(inline="always", **_OPTS)
def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


@nb.njit(inline="always", **_OPTS)
def _rot(w, th):
    """Rodrigues' rotation matrix (MLS eq. 2.14)."""
    c = math.cos(th)
    s = math.sin(th)
    v = 1.0 - c
    x, y, z = w[0], w[1], w[2]
    R = np.empty((3, 3))
    R[0, 0] = c + x * x * v
    R[0, 1] = x * y * v - z * s
    R[0, 2] = x * z * v + y * s
    R[1, 0] = y * x * v + z * s
    R[1, 1] = c + y * y * v
    R[1, 2] = y * z * v - x * s
    R[2, 0] = z * x * v - y * s
    R[2, 1] = z * y * v + x * s
    R[2, 2] = c + z * z * v
    return R


@nb.njit(inline="always", **_OPTS)
def _rotate(w, r, th, x):
    return r + _mv(_rot(w, th), x - r)


@nb.njit(inline="always", **_OPTS)
def _sp1(w, r, p, q):
    """Subproblem 1: the angle of p → q about (ω, r); returns (θ, |u'|)."""
    u = p - r
    v = q - r
    up = u - _dot(u, w) * w
    vp = v - _dot(v, w) * w
    return math.atan2(_dot(w, _cross(up, vp)), _dot(up, vp)), math.sqrt(_dot(up, up))


@nb.njit(**_OPTS)
def _sp2(w1, w2, r, p, q, out, tol):
    """Subproblem 2 (axes meeting at r): out[k] = (θ1, θ2) for k = 0, 1; returns existence."""
    u = p - r
    v = q - r
    c12 = _dot(w1, w2)
    den = c12 * c12 - 1.0
    a = (c12 * _dot(w2, u) - _dot(w1, v)) / den
    b = (c12 * _dot(w1, v) - _dot(w2, u)) / den
    x = _cross(w1, w2)
    uu = _dot(u, u)
    g2 = (uu - a * a - b * b - 2.0 * a * b * c12) / _dot(x, x)
    if g2 < -tol * (1.0 + uu) or abs(uu - _dot(v, v)) > tol * (1.0 + uu):
        return False
    g = math.sqrt(max(g2, 0.0))
    for k in range(2):
        c = r + a * w1 + b * w2 + (g if k == 0 else -g) * x
        out[k, 1], _ = _sp1(w2, r, p, c)
        out[k, 0], _ = _sp1(w1, r, c, q)
    return True


@nb.njit(**_OPTS)
def _sp3(w, r, p, q, delta, out, tol):
    """Subproblem 3: out[0:2] = θ with |e^{ξ̂θ} p − q| = δ; returns existence."""
    u = p - r
    v = q - r
    up = u - _dot(u, w) * w
    vp = v - _dot(v, w) * w
    t0 = math.atan2(_dot(w, _cross(up, vp)), _dot(up, vp))
    h = _dot(w, p - q)
    d2 = delta * delta - h * h
    nu = math.sqrt(_dot(up, up))
    nv = math.sqrt(_dot(vp, vp))
    if nu * nv == 0.0:
        return False
    c = (nu * nu + nv * nv - d2) / (2.0 * nu * nv)
    if abs(c) > 1.0 + tol:
        return False
    a = math.acos(min(max(c, -1.0), 1.0))
    out[0] = t0 - a
    out[1] = t0 + a
    return True


@nb.njit(**_OPTS)
def _sp4(h, w, p, d, out, tol):
    """Subproblem 4 (one axis): out[0:2] = θ with hᵀ R(ω, θ) p = d; returns existence."""
    par = _dot(w, p) * w
    A = _dot(h, p - par)
    B = _dot(h, _cross(w, p))
    C = d - _dot(h, par)
    n = math.hypot(A, B)
    if n <= tol:
        return False
    c = C / n
    if abs(c) > 1.0 + tol:
        return False
    phi = math.atan2(B, A)
    a = math.acos(min(max(c, -1.0), 1.0))
    out[0] = phi - a
    out[1] = phi + a
    return True


@nb.njit(**_OPTS)
def _fk(C, q):
    """``C0 Rz(q1) C1 … Rz(q6) C6`` with the running transform in scalars (no temporaries)."""
    F = np.empty((4, 4))
    r00, r01, r02, p0 = C[0, 0, 0], C[0, 0, 1], C[0, 0, 2], C[0, 0, 3]
    r10, r11, r12, p1 = C[0, 1, 0], C[0, 1, 1], C[0, 1, 2], C[0, 1, 3]
    r20, r21, r22, p2 = C[0, 2, 0], C[0, 2, 1], C[0, 2, 2], C[0, 2, 3]
    for i in range(6):
        c = math.cos(q[i])
        s = math.sin(q[i])
        a0 = c * r00 + s * r01
        a1 = c * r10 + s * r11
        a2 = c * r20 + s * r21
        r01 = c * r01 - s * r00
        r11 = c * r11 - s * r10
        r21 = c * r21 - s * r20
        r00, r10, r20 = a0, a1, a2
        M = C[i + 1]
        n00 = r00 * M[0, 0] + r01 * M[1, 0] + r02 * M[2, 0]
        n01 = r00 * M[0, 1] + r01 * M[1, 1] + r02 * M[2, 1]
        n02 = r00 * M[0, 2] + r01 * M[1, 2] + r02 * M[2, 2]
        p0 = r00 * M[0, 3] + r01 * M[1, 3] + r02 * M[2, 3] + p0
        n10 = r10 * M[0, 0] + r11 * M[1, 0] + r12 * M[2, 0]
        n11 = r10 * M[0, 1] + r11 * M[1, 1] + r12 * M[2, 1]
        n12 = r10 * M[0, 2] + r11 * M[1, 2] + r12 * M[2, 2]
        p1 = r10 * M[0, 3] + r11 * M[1, 3] + r12 * M[2, 3] + p1
        n20 = r20 * M[0, 0] + r21 * M[1, 0] + r22 * M[2, 0]
        n21 = r20 * M[0, 1] + r21 * M[1, 1] + r22 * M[2, 1]
        n22 = r20 * M[0, 2] + r21 * M[1, 2] + r22 * M[2, 2]
        p2 = r20 * M[0, 3] + r21 * M[1, 3] + r22 * M[2, 3] + p2
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = n00, n01, n02, n10, n11, n12, n20, n21, n22
    F[0, 0], F[0, 1], F[0, 2], F[0, 3] = r00, r01, r02, p0
    F[1, 0], F[1, 1], F[1, 2], F[1, 3] = r10, r11, r12, p1
    F[2, 0], F[2, 1], F[2, 2], F[2, 3] = r20, r21, r22, p2
    F[3, 0], F[3, 1], F[3, 2], F[3, 3] = 0.0, 0.0, 0.0, 1.0
    return F


@nb.njit(**_OPTS)
def _store(n, C, T, q, tol, dedup, out_q, out_valid, out_pos, out_rot, cnt):
    """Verify q by FK against T and store it unless it repeats a stored one; new count."""
    F = _fk(C, q)
    pos = math.sqrt((F[0, 3] - T[0, 3]) ** 2 + (F[1, 3] - T[1, 3]) ** 2
                    + (F[2, 3] - T[2, 3]) ** 2)
    d = math.sqrt(np.sum((F[:3, :3] - T[:3, :3]) ** 2))
    rot = 2.0 * math.asin(min(d / (2.0 * math.sqrt(2.0)), 1.0))
    if not (pos <= tol and rot <= tol):  # rounding near a singular set: two Newton steps
        pos, rot = _polish(C, T, q, 2)
        if not (pos <= tol and rot <= tol):
            return cnt
    for i in range(6):
        q[i] = _wrap(q[i])
    for j in range(cnt):
        dmax = 0.0
        for i in range(6):
            dmax = max(dmax, abs(_wrap(q[i] - out_q[n, j, i])))
        if dmax < dedup:
            return cnt
    if cnt >= out_q.shape[1]:
        return cnt
    out_q[n, cnt] = q
    out_valid[n, cnt] = True
    out_pos[n, cnt] = pos
    out_rot[n, cnt] = rot
    return cnt + 1


@nb.njit(**_OPTS)
def _pieper_pose(n, C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, dedup, out_q, out_valid,
                 out_pos, out_rot, out_sing, out_sign, out_fam):
    g = _mm(T[n], T0inv)
    Rg = np.ascontiguousarray(g[:3, :3])
    pw = _mv(Rg, w) + g[:3, 3]
    t3 = np.empty(2)
    if not _sp3(W[2], P[2], w, s, math.sqrt(_dot(pw - s, pw - s)), t3, tol):
        return
    t12 = np.empty((2, 2))
    t45 = np.empty((2, 2))
    z = np.zeros(3)
    q = np.empty(6)
    cnt = 0
    for i3 in range(2):
        w3 = _rotate(W[2], P[2], t3[i3], w)
        if not _sp2(W[0], W[1], s, w3, pw, t12, tol):
            continue
        R3 = _rot(W[2], t3[i3])
        for i12 in range(2):
            R123 = _mm(_mm(_rot(W[0], t12[i12, 0]), _rot(W[1], t12[i12, 1])), R3)
            Rp = _mtm(R123, Rg)
            target = _mv(Rp, W[5])
            cr = _cross(W[3], target)
            sing = math.sqrt(_dot(cr, cr)) < wrist_tol
            if sing:  # θ4 free: θ4 = 0, align ω6 with θ5 alone
                t45[0, 0] = 0.0
                t45[0, 1], _ = _sp1(W[4], z, W[5], target)
                t45[1, 0] = t45[0, 0]
                t45[1, 1] = t45[0, 1]
            elif not _sp2(W[3], W[4], z, W[5], target, t45, tol):
                continue
            for i45 in range(2):
                R5 = _rot(W[4], t45[i45, 1])
                R45 = _mm(_rot(W[3], t45[i45, 0]), R5)
                t6, _ = _sp1(W[5], z, x6, _mtv(R45, _mv(Rp, x6)))
                q[0] = t12[i12, 0]
                q[1] = t12[i12, 1]
                q[2] = t3[i3]
                q[3] = t45[i45, 0]
                q[4] = t45[i45, 1]
                q[5] = t6
                new = _store(n, C, T[n], q, tol, dedup, out_q, out_valid, out_pos, out_rot, cnt)
                if new > cnt and sing:
                    sig = 1.0 if _dot(W[3], _mv(R5, W[5])) >= 0.0 else -1.0
                    out_sing[n, cnt] = True
                    out_sign[n, cnt] = sig
                    out_fam[n, cnt] = _wrap(q[3] + sig * q[5])
                cnt = new


@nb.njit(parallel=True, **_OPTS)
def pieper_batch(C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, dedup, out_q, out_valid, out_pos,
                 out_rot, out_sing, out_sign, out_fam):
    """Spherical-wrist closed form for N poses (outputs pre-filled by the caller)."""
    for n in nb.prange(T.shape[0]):
        _pieper_pose(n, C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, dedup, out_q, out_valid,
                     out_pos, out_rot, out_sing, out_sign, out_fam)


@nb.njit(**_OPTS)
def _three_parallel_pose(n, C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol, dedup, out_q,
                         out_valid, out_pos, out_rot):
    g = _mm(T[n], T0inv)
    Rg = np.ascontiguousarray(g[:3, :3])
    tg = np.ascontiguousarray(g[:3, 3])
    h = W[1]
    q56 = _mv(Rg, p56) + tg
    psi = np.empty(2)
    if not _sp4(h, W[0], q56 - P[0], _dot(h, p56 - P[0]), psi, tol):
        return
    t5 = np.empty(2)
    t3 = np.empty(2)
    z = np.zeros(3)
    q = np.empty(6)
    cnt = 0
    for i1 in range(2):
        Rr = _mm(_rot(W[0], psi[i1]), Rg)
        if not _sp4(h, W[4], W[5], _dot(h, _mv(Rr, W[5])), t5, tol):
            continue
        hr = _mtv(Rr, h)
        cr = _cross(hr, W[5])
        if math.sqrt(_dot(cr, cr)) < wrist_tol:
            continue  # wrist-singular: axis 6 parallel to axes 2-4 (not reported)
        for i5 in range(2):
            R5 = _rot(W[4], t5[i5])
            t6, _ = _sp1(W[5], z, hr, _mtv(R5, h))
            R6 = _rot(W[5], t6)
            R234 = _mm(Rr, _mm(R5, R6).T)
            phi, _ = _sp1(h, z, xh, _mv(R234, xh))
            y = _rotate(W[5], P[5], -t6, _rotate(W[4], P[4], -t5[i5], P[3]))
            y = _rotate(W[0], P[0], psi[i1], _mv(Rg, y) + tg)
            if not _sp3(W[2], P[2], P[3], P[1], math.sqrt(_dot(y - P[1], y - P[1])), t3, tol):
                continue
            for i3 in range(2):
                t2, _ = _sp1(W[1], P[1], _rotate(W[2], P[2], t3[i3], P[3]), y)
                q[0] = -psi[i1]
                q[1] = t2
                q[2] = t3[i3]
                q[3] = sg[2] * (phi - sg[0] * t2 - sg[1] * t3[i3])
                q[4] = t5[i5]
                q[5] = t6
                cnt = _store(n, C, T[n], q, tol, dedup, out_q, out_valid, out_pos, out_rot, cnt)


@nb.njit(parallel=True, **_OPTS)
def three_parallel_batch(C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol, dedup, out_q,
                         out_valid, out_pos, out_rot):
    """Three-parallel-axes (UR-type) closed form for N poses."""
    for n in nb.prange(T.shape[0]):
        _three_parallel_pose(n, C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol, dedup, out_q,
                             out_valid, out_pos, out_rot)


@nb.njit(**_OPTS)
def pieper_serial(C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, dedup, out_q, out_valid,
                  out_pos, out_rot, out_sing, out_sign, out_fam):
    """:func:`pieper_batch` on one thread (small batches: no thread start-up)."""
    for n in range(T.shape[0]):
        _pieper_pose(n, C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, dedup, out_q, out_valid,
                     out_pos, out_rot, out_sing, out_sign, out_fam)


@nb.njit(**_OPTS)
def three_parallel_serial(C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol, dedup, out_q,
                          out_valid, out_pos, out_rot):
    """:func:`three_parallel_batch` on one thread."""
    for n in range(T.shape[0]):
        _three_parallel_pose(n, C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol, dedup, out_q,
                             out_valid, out_pos, out_rot)


@nb.njit(**_OPTS)
def first_non_rigid(T, tol):
    """Index of the first pose of ``T (N, 4, 4)`` that is not a finite rigid transform (rotation
    orthonormal with det +1 within tol, last row [0, 0, 0, 1]), or −1."""
    for n in range(T.shape[0]):
        bad = False
        for i in range(4):
            for j in range(4):
                if not math.isfinite(T[n, i, j]):
                    bad = True
        if bad or T[n, 3, 0] != 0.0 or T[n, 3, 1] != 0.0 or T[n, 3, 2] != 0.0 or \
                T[n, 3, 3] != 1.0:
            return n
        for i in range(3):
            for j in range(3):
                d = T[n, i, 0] * T[n, j, 0] + T[n, i, 1] * T[n, j, 1] + T[n, i, 2] * T[n, j, 2]
                if abs(d - (1.0 if i == j else 0.0)) > tol:
                    return n
        det = (T[n, 0, 0] * (T[n, 1, 1] * T[n, 2, 2] - T[n, 1, 2] * T[n, 2, 1])
               - T[n, 0, 1] * (T[n, 1, 0] * T[n, 2, 2] - T[n, 1, 2] * T[n, 2, 0])
               + T[n, 0, 2] * (T[n, 1, 0] * T[n, 2, 1] - T[n, 1, 1] * T[n, 2, 0]))
        if abs(det - 1.0) > tol:
            return n
    return -1
