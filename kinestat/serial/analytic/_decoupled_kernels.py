"""Compiled (Numba) kernel of the decoupled solver (three R/P positioning joints, a spherical
wrist): the steps of :mod:`kinestat.serial.analytic.decoupled` (the NumPy reference), one pose
at a time, batches split over the cores with ``prange``.

Per pose: the wrist centre p and joint 1's invariants; the eliminant Ψ(q3) at 8 angles (its
discrete Fourier coefficients; the real roots of the trigonometric polynomial from the real
polynomial that the half-angle substitution makes of it) or at 9 Chebyshev nodes (a power
series), real roots by :func:`kinestat.serial.analytic._hqr.eigvals` on the companion (a
quartic in closed form); joint 2, joint 1, Newton steps on the wrist-centre equation; the
spherical wrist (:func:`kinestat.serial.analytic._cf_kernels.spherical_wrist`, the θ5 = 0/π
families);
Gauss–Newton steps with a truncated pseudo-inverse on candidates whose centre still misses or
whose wrist is near θ5 = 0; verification by forward kinematics, de-duplication (revolute
joints modulo 2π, prismatic ones as lengths) and storage.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.serial._kernels import _jac_column, _start, _step
from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._cf_kernels import (
    _add,
    _cross,
    _dot,
    _mm,
    _mtm,
    _mv,
    _norm,
    _pose_times,
    _rot,
    _rotate,
    _row,
    _scale,
    _sp1,
    _sub,
    clear_wrist,
    spherical_wrist,
)
from kinestat.serial.analytic._hqr import eigvals
from kinestat.serial.analytic._offset_kernels import quartic_real_roots
from kinestat.serial.analytic._solution_kernels import (
    _twist_error,
    angle_distance,
    pose_errors,
    wrap,
)

#: joint-2 elimination modes (``decoupled.Plan.mode``)
MODES = {"full": 0, "row0": 1, "row1": 2, "lin": 3, "perp": 4, "pp": 5}
_FULL, _ROW0, _ROW1, _LIN, _PERP, _PP = 0, 1, 2, 3, 4, 5
_R = 0  # joint kinds of joints 1-3 (1: prismatic)
_Z3 = (0.0, 0.0, 0.0)
_I3 = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
K = 8  # solution slots


@nb.njit(**_INLINE)
def _unpack(Kp):
    """``C (7, 4, 4)``, ``T0inv``, ``W (6, 3)``, ``P (6, 3)``, the wrist centre, r1, r2,
    ``G (2, 2)``, ``e (2, 3)``, ``u (2, 3)``, the x direction across axis 6, the arm's size."""
    return (Kp[:112].reshape((7, 4, 4)), Kp[112:128].reshape((4, 4)), Kp[128:146].reshape((6, 3)),
            Kp[146:164].reshape((6, 3)), Kp[164:167], Kp[167:170], Kp[170:173],
            Kp[173:177].reshape((2, 2)), Kp[177:183].reshape((2, 3)),
            Kp[183:189].reshape((2, 3)), Kp[189:192], Kp[192])


def pack(C, T0inv, W, P, wrist, r1, r2, G, e, u, x6, scale) -> np.ndarray:
    """Pack the pose-independent data (see :func:`_unpack`) into one float array."""
    parts = (C, T0inv, W, P, wrist, r1, r2, G, e, u, x6, np.array([scale]))
    return np.ascontiguousarray(np.concatenate([np.ravel(x) for x in parts]), dtype=np.float64)


@nb.njit(**_INLINE)
def _move(kind, w, r, q, x):
    """``e^{ξ̂ q} x``: rotation about (w, r) or translation along w."""
    if kind == _R:
        return _rotate(w, r, (q, math.cos(q), math.sin(q)), x)
    return _add(x, _scale(w, q))


@nb.njit(**_INLINE)
def _terms(D, kinds, y, p, h, rho2):
    """``(C0, C1, vp0, vp1)`` of ``g_kᵀ Rot(q2) v⊥ + C_k`` (revolute joint 2)."""
    W, r1, r2, e, u = D[2], D[5], D[6], D[8], D[9]
    W0, W1 = _row(W, 0), _row(W, 1)
    rr2 = (r2[0], r2[1], r2[2])
    v = _sub(y, rr2)
    vpar = _dot(v, W1)
    vp0 = _dot(v, _row(e, 0))
    vp1 = _dot(v, _row(e, 1))
    if kinds[0] == _R:
        d = _sub(rr2, (r1[0], r1[1], r1[2]))
        c0 = _dot(W0, d) + _dot(W0, W1) * vpar - h
        c1 = _dot(v, v) + _dot(d, d) + 2.0 * _dot(d, W1) * vpar - rho2
    else:
        rp = _sub(rr2, p)
        u0, u1 = _row(u, 0), _row(u, 1)
        c0 = _dot(u0, rp) + _dot(u0, W1) * vpar
        c1 = _dot(u1, rp) + _dot(u1, W1) * vpar
    return c0, c1, vp0, vp1


@nb.njit(**_INLINE)
def _eliminant(D, kinds, mode, y, p, h, rho2):
    """Ψ at the wrist-centre image y (``decoupled._eliminant``)."""
    W, r1, G, u = D[2], D[5], D[7], D[9]
    W0, W1 = _row(W, 0), _row(W, 1)
    if kinds[1] == _R:
        c0, c1, vp0, vp1 = _terms(D, kinds, y, p, h, rho2)
        if mode == _ROW0:
            return c0
        if mode == _ROW1:
            return c1
        z0 = G[1, 1] * c0 - G[0, 1] * c1
        z1 = -G[1, 0] * c0 + G[0, 0] * c1
        det = G[0, 0] * G[1, 1] - G[0, 1] * G[1, 0]
        return z0 * z0 + z1 * z1 - det * det * (vp0 * vp0 + vp1 * vp1)
    if mode == _PP:
        return _dot(_sub(y, p), _row(u, 1))
    s = _sub(y, (r1[0], r1[1], r1[2]))
    hs = _dot(s, W0)
    if mode == _PERP:
        return hs - h
    a = _dot(W0, W1)
    z = _add(_scale(s, a), _scale(W1, h - hs))
    return _dot(z, z) - a * a * rho2


@nb.njit(**_INLINE)
def _joint2(D, kinds, mode, y, p, h, rho2, snap):
    """``(count, q2a, q2b, ok)``: joint 2 for the wrist-centre image y (``decoupled._joint2``)."""
    W, r1, G, u = D[2], D[5], D[7], D[9]
    W0, W1 = _row(W, 0), _row(W, 1)
    if kinds[1] == _R:
        c0, c1, vp0, vp1 = _terms(D, kinds, y, p, h, rho2)
        if mode == _FULL:
            det = G[0, 0] * G[1, 1] - G[0, 1] * G[1, 0]
            z0 = -(G[1, 1] * c0 - G[0, 1] * c1) / det
            z1 = -(-G[1, 0] * c0 + G[0, 0] * c1) / det
            return 1, math.atan2(vp0 * z1 - vp1 * z0, vp0 * z0 + vp1 * z1), 0.0, True
        j = 1 if mode == _ROW0 else 0
        g0, g1 = G[j, 0], G[j, 1]
        cj = c1 if j == 1 else c0
        al = math.atan2(g1, g0)
        be = math.atan2(vp1, vp0)
        den = math.sqrt(g0 * g0 + g1 * g1) * math.sqrt(vp0 * vp0 + vp1 * vp1)
        c = -cj / (den if den > 0.0 else 1.0)
        if abs(c) > 1.0 - snap:
            c = 1.0 if c > 0.0 else -1.0
        ac = math.acos(min(max(c, -1.0), 1.0))
        return 2, al - be + ac, al - be - ac, abs(c) <= 1.0 + 1e-7 and den > 0.0
    if mode == _PP:
        u0 = _row(u, 0)
        return 1, -_dot(_sub(y, p), u0) / _dot(u0, W1), 0.0, True
    s = _sub(y, (r1[0], r1[1], r1[2]))
    if mode == _LIN:
        return 1, (h - _dot(s, W0)) / _dot(W0, W1), 0.0, True
    b = _dot(s, W1)
    ss = _dot(s, s)
    disc = b * b - (ss - rho2)
    if abs(disc) <= snap * (b * b + ss + rho2):
        disc = 0.0
    r = math.sqrt(max(disc, 0.0))
    return 2, -b + r, -b - r, disc >= -1e-9 * (1.0 + rho2)


@nb.njit(**_INLINE)
def _place(D, kinds, q):
    """``M1 M2 M3 w`` at ``q (3,)``."""
    W, P, w = D[2], D[3], D[4]
    x = (w[0], w[1], w[2])
    for i in (2, 1, 0):
        x = _move(kinds[i], _row(W, i), _row(P, i), q[i], x)
    return x


@nb.njit(**_INLINE)
def _axis(kind, w, r, qi, R, o):
    """Joint axis (ω, r) moved by the joints before it (rotation R, offset o): ``(ω', r', R',
    o')``, R' and o' then including this joint at qi."""
    ax = _mv(R, w)
    pt = _add(_mv(R, r), o)
    if kind == _R:
        Ri = _rot(w, (qi, math.cos(qi), math.sin(qi)))
        o = _add(_mv(R, _sub(r, _mv(Ri, r))), o)
        R = _mm(R, Ri)
    else:
        o = _add(o, _scale(ax, qi))
    return ax, pt, R, o


@nb.njit(**_INLINE)
def _column(kind, ax, pt, x):
    """The position Jacobian's column of a joint whose axis is (ax, pt), at the point x."""
    return _cross(ax, _sub(x, pt)) if kind == _R else ax


@nb.njit(**_INLINE)
def _polish_position(D, kinds, q, p, live, iters):
    """Newton steps on ``M1 M2 M3 w = p`` for ``q (3,)`` in place, each kept where it lowers
    the miss; returns the miss ``|M1 M2 M3 w − p|``."""
    W, P, w, scale = D[2], D[3], D[4], D[11]
    f = _sub(_place(D, kinds, q), p)
    fn = _norm(f)
    small = 1e-14 * (scale + _norm(p))
    for _ in range(iters):
        if not (live and fn > small):
            break
        # the position Jacobian: each axis moved by the joints before it
        R, o = _I3, _Z3
        a0, p0, R, o = _axis(kinds[0], _row(W, 0), _row(P, 0), q[0], R, o)
        a1, p1, R, o = _axis(kinds[1], _row(W, 1), _row(P, 1), q[1], R, o)
        a2, p2, R, o = _axis(kinds[2], _row(W, 2), _row(P, 2), q[2], R, o)
        x = _add(_mv(R, (w[0], w[1], w[2])), o)
        a = _column(kinds[0], a0, p0, x)
        b = _column(kinds[1], a1, p1, x)
        c = _column(kinds[2], a2, p2, x)
        det = _dot(a, _cross(b, c))
        if not abs(det) > 1e-300:
            break
        # J dq = −f by Cramer's rule (columns a, b, c)
        mf = (-f[0], -f[1], -f[2])
        d0 = _dot(mf, _cross(b, c)) / det
        d1 = _dot(a, _cross(mf, c)) / det
        d2 = _dot(a, _cross(b, mf)) / det
        if not (math.isfinite(d0) and math.isfinite(d1) and math.isfinite(d2)):
            break
        qn = (q[0] + d0, q[1] + d1, q[2] + d2)
        fnew = _sub(_place(D, kinds, qn), p)
        nn = _norm(fnew)
        if not nn < fn:
            break
        q[0], q[1], q[2] = qn[0], qn[1], qn[2]
        f = fnew
        fn = nn
    return fn


@nb.njit(**_INLINE)
def _fk(C, jk, q):
    t = _start(C[0])
    for i in range(6):
        t = _step(C[i + 1], jk[i], 0.0, q[i], t)
    return t


@nb.njit(**_OPTS)
def _polish_pose(C, jk, Tn, q, iters, rcond):
    """Gauss–Newton steps ``δq = J⁺ ξ`` (pseudo-inverse truncated at ``rcond``) on q (6,) in
    place, each kept where it lowers the twist error (``_common.newton_polish``)."""
    J = np.empty((6, 6))
    e = np.empty(6)
    en_v = np.empty(6)
    qn = np.empty(6)
    t = _start(C[0])
    for i in range(6):
        _jac_column(t, jk[i], 0.0, J, i)
        t = _step(C[i + 1], jk[i], 0.0, q[i], t)
    en = _twist_error(t, Tn, e)
    for _ in range(iters):
        dq = np.linalg.pinv(J, rcond) @ e
        for i in range(6):
            qn[i] = q[i] + (dq[i] if math.isfinite(dq[i]) else 0.0)
        Jn = np.empty((6, 6))
        t = _start(C[0])
        for i in range(6):
            _jac_column(t, jk[i], 0.0, Jn, i)
            t = _step(C[i + 1], jk[i], 0.0, qn[i], t)
        nn = _twist_error(t, Tn, en_v)
        if nn < en:
            for i in range(6):
                q[i] = qn[i]
                e[i] = en_v[i]
            J = Jn
            en = nn


@nb.njit(**_INLINE)
def _store(n, q, rot, pos, err, sing, sig, fam, dedup, out_q, out_valid, out_pos, out_rot,
           out_sing, out_sign, out_fam, cnt):
    """Store q (6,) (revolute joints wrapped) unless it repeats a stored one; the new count."""
    for i in range(6):
        if rot[i]:
            q[i] = wrap(q[i])
    for j in range(cnt):
        same = True
        for i in range(6):
            d = angle_distance(q[i], out_q[n, j, i]) if rot[i] else abs(q[i] - out_q[n, j, i])
            if not d < dedup:
                same = False
                break
        if same:
            return cnt
    if cnt >= K:
        return cnt
    for i in range(6):
        out_q[n, cnt, i] = q[i]
    out_valid[n, cnt] = True
    out_pos[n, cnt] = pos
    out_rot[n, cnt] = err
    out_sing[n, cnt] = sing
    out_sign[n, cnt] = sig if sing else 0.0
    out_fam[n, cnt] = fam if sing else np.nan
    return cnt + 1


_COS8 = tuple(math.cos(2.0 * math.pi * j / 8.0) for j in range(8))
_SIN8 = tuple(math.sin(2.0 * math.pi * j / 8.0) for j in range(8))
#: the half-angle substitution is taken about this angle (any generic value: a root at
#: θ = _THETA0 + π, where t = tan(φ/2) is infinite, is then unlikely)
_THETA0 = 0.4170
#: ``e^{ikθ0}`` for k = -3 .. 3
_TURN0 = tuple(complex(math.cos(k * _THETA0), math.sin(k * _THETA0)) for k in range(-3, 4))


def _half_angle_table() -> np.ndarray:
    """``[d - 1, k + 3, j]``: the coefficient of t^j in ``(1 + it)^{d+k} (1 − it)^{d−k}``
    (Gaussian integers, exact in floating point), d = 1 .. 3, |k| ≤ d."""
    tab = np.zeros((3, 7, 7), dtype=np.complex128)
    for d in range(1, 4):
        for k in range(-d, d + 1):
            a = np.zeros(7, dtype=np.complex128)
            a[0] = 1.0
            for f in range(2 * d):
                a[1:] = a[1:] + (1j if f < d + k else -1j) * a[:-1]
            tab[d - 1, k + 3] = a
    return tab


_HALF = _half_angle_table()
#: a quartic in t whose top coefficient is at least this fraction of the largest is solved in
#: closed form (:func:`~kinestat.serial.analytic._offset_kernels.quartic_real_roots`: its roots
#: |t| stay below ~1/_QUARTIC_MIN, where Ferrari's method keeps its accuracy), else by the
#: companion matrix
_QUARTIC_MIN = 1e-3


@nb.njit(**_OPTS)
def _trig_roots(ck, d, out, Sr):
    """Real roots θ of the trigonometric polynomial ``Σ_{|k| ≤ d} c_k e^{ikθ}`` (``ck`` holds
    c_{-3} .. c_3) into ``out``; their count. With ``θ = θ0 + φ``, ``t = tan(φ/2)``:
    ``e^{ikφ} (1 + t²)^d = (1 + it)^{d+k} (1 − it)^{d−k}`` (:data:`_HALF`), so the polynomial
    times ``(1 + t²)^d`` is a real polynomial of degree ≤ 2d in t, whose real roots come from
    its companion matrix (:func:`kinestat.serial.analytic._hqr.eigvals`) or, a quartic, from
    Ferrari's method. ``Sr``: the scratch of :func:`_roots`."""
    n2 = 2 * d
    P = Sr[9:16]
    P[:] = 0.0
    for k in range(-d, d + 1):
        c = ck[k + 3] * _TURN0[k + 3]
        for j in range(n2 + 1):
            P[j] += (c * _HALF[d - 1, k + 3, j]).real
    big = 0.0
    for j in range(n2 + 1):
        big = max(big, abs(P[j]))
    top = n2
    while top > 0 and not abs(P[top]) > 1e-14 * big:
        top -= 1
    if top == 0:
        return 0
    if top == 4 and abs(P[4]) >= _QUARTIC_MIN * big:  # Ferrari, not the companion's QR
        k, r = quartic_real_roots(P[4], P[3], P[2], P[1], P[0])
        for i in range(k):
            out[i] = wrap(_THETA0 + 2.0 * math.atan(r[i]))
        return k
    A = Sr[16:52].reshape((6, 6))
    A[:, :] = 0.0
    for j in range(top):
        A[0, j] = -P[top - 1 - j] / P[top]
    for i in range(1, top):
        A[i, i - 1] = 1.0
    wr = Sr[52:58]
    wi = Sr[58:64]
    if not eigvals(A, top, wr, wi):
        return 0
    m = 0
    for i in range(top):
        if abs(wi[i]) <= 1e-5 * (1.0 + math.hypot(wr[i], wi[i])):
            out[m] = wrap(_THETA0 + 2.0 * math.atan(wr[i]))
            m += 1
    return m


@nb.njit(**_INLINE)
def _roots(D, kinds, mode, cheb_t, fit, ctp, p, h, rho2, out, Sr, Cs):
    """Real roots q3 of the eliminant into ``out``; their count. ``Sr (64,)``, ``Cs (16,)``
    complex: scratch."""
    W, P, w, scale = D[2], D[3], D[4], D[11]
    W2, P2 = _row(W, 2), _row(P, 2)
    wc = (w[0], w[1], w[2])
    m = 0
    if kinds[2] == _R:
        psi = Sr[0:8]
        for s in range(8):
            y = _rotate(W2, P2, (2.0 * math.pi * s / 8.0, _COS8[s], _SIN8[s]), wc)
            psi[s] = _eliminant(D, kinds, mode, y, p, h, rho2)
        ck = Cs[0:7]  # c_{-3} .. c_3
        big = 0.0
        for k in range(-3, 4):
            re = 0.0
            im = 0.0
            for s in range(8):  # e^{−2πiks/8}
                j = (k * s) % 8
                re += psi[s] * _COS8[j]
                im -= psi[s] * _SIN8[j]
            ck[k + 3] = complex(re, im) / 8.0
            big = max(big, abs(ck[k + 3]))
        d = 0
        for k in range(3, 0, -1):
            if abs(ck[k + 3]) > 1e-10 * max(big, 1e-300):
                d = k
                break
        if d == 0:
            return 0
        return _trig_roots(ck, d, out, Sr)
    L = 4.0 * scale + _norm(_sub(p, wc))
    psi = Sr[0:9]
    for s in range(9):
        y = _add(wc, _scale(W2, L * cheb_t[s]))
        psi[s] = _eliminant(D, kinds, mode, y, p, h, rho2)
    power = Sr[9:14]
    power[:] = 0.0
    for k in range(5):
        ch = 0.0
        for s in range(9):
            ch += fit[k, s] * psi[s]
        for j in range(5):
            power[j] += ch * ctp[k, j]
    big = 0.0
    for j in range(5):
        big = max(big, abs(power[j]))
    d = 0
    for j in range(4, 0, -1):
        if abs(power[j]) > 1e-10 * max(big, 1e-300):
            d = j
            break
    if d == 0:
        return 0
    A = Sr[16:52].reshape((6, 6))
    A[:, :] = 0.0
    for j in range(d):
        A[0, j] = -power[d - 1 - j] / power[d]
    for i in range(1, d):
        A[i, i - 1] = 1.0
    wr = Sr[52:58]
    wi = Sr[58:64]
    if not eigvals(A, d, wr, wi):
        return 0
    for i in range(d):
        if abs(wi[i]) <= 1e-5 * (1.0 + math.hypot(wr[i], wi[i])):
            out[m] = wr[i] * L
            m += 1
    return m


@nb.njit(**_OPTS)
def _pose(n, Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol, dedup, out_q, out_valid, out_pos,
          out_rot, out_sing, out_sign, out_fam):
    """All solutions of pose n; returns ``(count, placed)``: placed when some root puts the
    wrist centre on p (within 1e-6 of the arm's size)."""
    D = _unpack(Kp)
    C, T0inv, W, P, w, r1, x6, scale = D[0], D[1], D[2], D[3], D[4], D[5], D[10], D[11]
    kinds, mode, jk, rot = ints[0:3], ints[3], ints[4:10], ints[10:16]
    clear_wrist(n, out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam)
    Tn = T[n]
    Rg, tg = _pose_times(Tn, T0inv)
    p = _add(_mv(Rg, (w[0], w[1], w[2])), tg)
    d1 = _sub(p, (r1[0], r1[1], r1[2]))
    h = _dot(d1, _row(W, 0))
    rho2 = _dot(d1, d1)
    q3s = np.empty(6)
    nr = _roots(D, kinds, mode, cheb_t, fit, ctp, p, h, rho2, q3s, np.empty(64),
                np.empty(16, dtype=np.complex128))
    W0, W1, W2, W3, W4, W5 = (_row(W, 0), _row(W, 1), _row(W, 2), _row(W, 3), _row(W, 4),
                              _row(W, 5))
    xs = (x6[0], x6[1], x6[2])
    q = np.empty(6)
    q123 = np.empty(3)
    cnt = 0
    placed = False
    for ir in range(nr):
        q3 = q3s[ir]
        y = _move(kinds[2], W2, _row(P, 2), q3, (w[0], w[1], w[2]))
        nb2, q2a, q2b, ok2 = _joint2(D, kinds, mode, y, p, h, rho2, 1e-12)
        if not ok2:
            continue
        for ib in range(nb2):
            q2 = q2a if ib == 0 else q2b
            x = _move(kinds[1], W1, _row(P, 1), q2, y)
            if kinds[0] == _R:
                q1 = _sp1(W0, (r1[0], r1[1], r1[2]), x, p)[0]
            else:
                q1 = _dot(_sub(p, x), W0)
            q123[0], q123[1], q123[2] = q1, q2, q3
            miss = _polish_position(D, kinds, q123, p, True, 3)
            placed |= miss <= 1e-6 * scale
            R = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
            for i in range(3):
                if kinds[i] == _R:
                    R = _mm(R, _rot(_row(W, i), (q123[i], math.cos(q123[i]), math.sin(q123[i]))))
            Rp = _mtm(R, Rg)
            ok45, off, sing, wa, wb = spherical_wrist(W3, W4, W5, Rp, xs, tol, wrist_tol)
            if not ok45:
                continue
            near = off < 1e-6
            for i45 in range(2):
                t4, t5, t6, sig = wa if i45 == 0 else wb
                q[0], q[1], q[2] = q123[0], q123[1], q123[2]
                q[3], q[4], q[5] = t4[0], t5[0], t6[0]
                if miss > 0.01 * tol or near:
                    _polish_pose(C, jk, Tn, q, 4, 1e-7)
                pos, err = pose_errors(_fk(C, jk, q), Tn)
                if not (pos <= tol and err <= tol):
                    continue
                cnt = _store(n, q, rot, pos, err, sing, sig, wrap(t4[0] + sig * t6[0]), dedup,
                             out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam,
                             cnt)
    return cnt, placed


@nb.njit(parallel=True, **_OPTS)
def solve_batch(Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol, dedup, out_q, out_valid, out_pos,
                out_rot, out_sing, out_sign, out_fam, out_cnt, out_placed):
    """All solutions of N poses into the (uninitialised) outputs (see the module docstring)."""
    for n in nb.prange(T.shape[0]):
        out_cnt[n], out_placed[n] = _pose(n, Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol,
                                          dedup, out_q, out_valid, out_pos, out_rot, out_sing,
                                          out_sign, out_fam)


@nb.njit(**_OPTS)
def solve_serial(Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol, dedup, out_q, out_valid, out_pos,
                 out_rot, out_sing, out_sign, out_fam, out_cnt, out_placed):
    """:func:`solve_batch` on one thread (small batches: no thread start-up)."""
    for n in range(T.shape[0]):
        out_cnt[n], out_placed[n] = _pose(n, Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol,
                                          dedup, out_q, out_valid, out_pos, out_rot, out_sing,
                                          out_sign, out_fam)
