"""Compiled (Numba) closed form of the spherical-wrist arm whose shoulder axes 1, 2 do not meet
(KUKA, ABB, Fanuc, Stäubli: an offset shoulder), one pose per ``prange`` iteration; the NumPy
reference is :mod:`kinestat.serial.analytic.pieper_offset`, the derivation is there.

The wrist centre p fixes θ1, θ2, θ3; the wrist (axes 4, 5, 6 meeting) is then solved as for the
meeting shoulder (:func:`kinestat.serial.analytic._cf_kernels.wrist_store`).

- Axes 1, 2 skew: the distance of p from axis 1 and its height along it, two equations linear
  in (cos θ2, sin θ2), eliminate θ2 and leave a quartic in tan(θ3/2) (Pieper 1968); θ2 and θ1
  then follow by subproblem 1.
- Axes 1, 2 parallel: the height of p along them fixes θ3 (subproblem 4), its distance from
  axis 1 fixes θ2 (subproblem 3), θ1 by subproblem 1.
"""

from __future__ import annotations

import cmath
import math

import numba as nb
import numpy as np

from kinestat.serial._kernels import _start
from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._cf_kernels import (
    RIGID_TOL,
    _add,
    _cross,
    _dot,
    _mv,
    _norm,
    _pair,
    _pose_status,
    _pose_times,
    _rot,
    _row,
    _scale,
    _sp1,
    _sp3,
    _sp4,
    _sub,
    clear_wrist,
    lazy,
    wrist_store,
)

#: a root of the quartic whose imaginary part is within this fraction of 1 + |t| is taken as
#: real (a double root at the workspace boundary splits by ~√ε); the FK check then decides
_IMAG_REL = 1e-5


@nb.njit(**_INLINE)
def _cubic_max_root(A, B, C):
    """The largest real root of ``m³ + A m² + B m + C`` (Cardano, then two Newton steps)."""
    P = B - A * A / 3.0
    Q = 2.0 * A * A * A / 27.0 - A * B / 3.0 + C
    disc = 0.25 * Q * Q + P * P * P / 27.0
    if disc >= 0.0:
        sd = math.sqrt(disc)
        y = np.cbrt(-0.5 * Q + sd) + np.cbrt(-0.5 * Q - sd)
    else:
        rp = math.sqrt(-P / 3.0)
        arg = min(max(-0.5 * Q / (rp * rp * rp), -1.0), 1.0)
        y = 2.0 * rp * math.cos(math.acos(arg) / 3.0)
    m = y - A / 3.0
    for _ in range(2):
        f = ((m + A) * m + B) * m + C
        df = (3.0 * m + 2.0 * A) * m + B
        if df == 0.0:
            break
        m -= f / df
    return m


@nb.njit(**_INLINE)
def _polish(c4, c3, c2, c1, c0, t):
    """Two Newton steps of the quartic from t."""
    for _ in range(2):
        f = (((c4 * t + c3) * t + c2) * t + c1) * t + c0
        df = ((4.0 * c4 * t + 3.0 * c3) * t + 2.0 * c2) * t + c1
        if df == 0.0:
            break
        t -= f / df
    return t


@nb.njit(**_OPTS)
def quartic_real_roots(c4, c3, c2, c1, c0):
    """``(k, roots)``: the real roots of ``c4 t⁴ + … + c0`` (c4 ≠ 0; Ferrari's method through the
    resolvent cubic's largest root, each root polished by Newton), ``roots`` a 4-tuple of which
    the first k are set."""
    b = c3 / c4
    c = c2 / c4
    d = c1 / c4
    e = c0 / c4
    p = c - 0.375 * b * b
    q = d - 0.5 * b * c + 0.125 * b * b * b
    r = e - 0.25 * b * d + b * b * c / 16.0 - 3.0 * b * b * b * b / 256.0
    m = _cubic_max_root(p, 0.25 * p * p - r, -0.125 * q * q)
    # tuples, not lists: no heap allocation per pose, and less code to load from the cache
    if m <= 1e-14 * (1.0 + abs(p) + abs(r)):  # biquadratic (q = 0)
        sq = cmath.sqrt(p * p - 4.0 * r + 0j)
        y1 = cmath.sqrt(0.5 * (-p + sq))
        y2 = cmath.sqrt(0.5 * (-p - sq))
        z = (y1, -y1, y2, -y2)
    else:
        s = math.sqrt(2.0 * m)
        k1 = 0.5 * p + m + 0.5 * q / s
        k2 = 0.5 * p + m - 0.5 * q / s
        d1 = cmath.sqrt(s * s - 4.0 * k1 + 0j)
        d2 = cmath.sqrt(s * s - 4.0 * k2 + 0j)
        z = (0.5 * (s + d1), 0.5 * (s - d1), 0.5 * (-s + d2), 0.5 * (-s - d2))
    out = (0.0, 0.0, 0.0, 0.0)
    k = 0
    for i in range(4):
        t = z[i].real - 0.25 * b
        if abs(z[i].imag) <= _IMAG_REL * (1.0 + abs(t)):
            out = _put(out, k, _polish(c4, c3, c2, c1, c0, t))
            k += 1
    return k, out


@nb.njit(**_INLINE)
def _put(v, k, x):
    """The 4-tuple v with entry k set to x."""
    return (x if k == 0 else v[0], x if k == 1 else v[1], x if k == 2 else v[2],
            x if k == 3 else v[3])


@nb.njit(**_INLINE)
def _sq(l0, l1, l2, f):
    """Add the square of the linear form ``l0 + l1 cos θ + l2 sin θ`` to the Fourier
    coefficients ``f = (A0, A1, B1, A2, B2)`` of ``A0 + A1 cos θ + B1 sin θ + A2 cos 2θ +
    B2 sin 2θ``."""
    return (f[0] + l0 * l0 + 0.5 * (l1 * l1 + l2 * l2), f[1] + 2.0 * l0 * l1,
            f[2] + 2.0 * l0 * l2, f[3] + 0.5 * (l1 * l1 - l2 * l2), f[4] + l1 * l2)


@nb.njit(**_INLINE)
def _fourier_at(f, c, s):
    """The Fourier series f at the angle of cosine c, sine s."""
    return f[0] + f[1] * c + f[2] * s + f[3] * (c * c - s * s) + f[4] * 2.0 * s * c


@nb.njit(**_OPTS)
def theta3_roots(f):
    """``(k, c, s)``: the cosines and sines (4-tuples, the first k set) of the real roots of the
    Fourier series ``f`` (degree 2). By ``t = tan((θ − β)/2)`` a quartic in t; β (a multiple
    of π/2) puts t = ∞ where |f| is largest, so that the leading coefficient is not small."""
    best = -1.0
    cb = 1.0
    sb = 0.0
    for j in range(4):
        c = (1.0, 0.0, -1.0, 0.0)[j]
        s = (0.0, 1.0, 0.0, -1.0)[j]
        v = abs(_fourier_at(f, -c, -s))  # the value at β + π
        if v > best:
            best, cb, sb = v, c, s
    A0 = f[0]
    A1 = f[1] * cb + f[2] * sb
    B1 = f[2] * cb - f[1] * sb
    c2b = cb * cb - sb * sb
    s2b = 2.0 * sb * cb
    A2 = f[3] * c2b + f[4] * s2b
    B2 = f[4] * c2b - f[3] * s2b
    cs = (1.0, 1.0, 1.0, 1.0)
    sn = (0.0, 0.0, 0.0, 0.0)
    c4 = A0 - A1 + A2
    if c4 == 0.0:
        return 0, (1.0, 1.0, 1.0, 1.0), (0.0, 0.0, 0.0, 0.0)
    k, t = quartic_real_roots(c4, 2.0 * B1 - 4.0 * B2, 2.0 * A0 - 6.0 * A2, 2.0 * B1 + 4.0 * B2,
                              A0 + A1 + A2)
    for i in range(k):
        ti = t[i]
        den = 1.0 + ti * ti
        cp = (1.0 - ti * ti) / den
        sp = 2.0 * ti / den
        cs = _put(cs, i, cp * cb - sp * sb)
        sn = _put(sn, i, sp * cb + cp * sb)
    return k, cs, sn


@nb.njit(**_OPTS)
def _offset_pose(n, C, T, T0inv, W, P, w, x6, G, tol, wrist_tol, dedup, newton, out_q, out_s,
                 out_valid, out_pos, out_rot, out_sing, out_sign, out_fam):
    clear_wrist(n, out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam)
    status = _pose_status(T, n, RIGID_TOL)
    if status:
        return -status
    Tn = T[n]
    Rg, tg = _pose_times(Tn, T0inv)
    W0, W1, W2 = _row(W, 0), _row(W, 1), _row(W, 2)
    P0, P1, P2 = _row(P, 0), _row(P, 1), _row(P, 2)
    wc = (w[0], w[1], w[2])
    pw = _add(_mv(Rg, wc), tg)
    m = _sub(wc, P2)
    xs = (x6[0], x6[1], x6[2])
    f0 = _start(C[0])
    cnt = 0
    if G[19] == 1.0:  # axes 1, 2 parallel
        ok3, a3, b3 = _sp4(W0, W2, m, _dot(W0, _sub(pw, P2)), tol)
        if not ok3:
            return 0
        foot = _add(P0, _scale(W0, _dot(W0, _sub(pw, P0))))
        for i3 in range(2):
            t3 = a3 if i3 == 0 else b3
            R3 = _rot(W2, t3)
            g3 = _add(P2, _mv(R3, m))
            ok2, t2a, t2b = _sp3(W1, P1, g3, foot, _norm(_sub(pw, foot)), tol)
            if not ok2:
                continue
            for i2 in range(2):
                t2 = t2a if i2 == 0 else t2b
                q2 = _add(P1, _mv(_rot(W1, t2), _sub(g3, P1)))
                t1 = _sp1(W0, P0, q2, pw)
                if out_s is not None:
                    t1, t2, t3 = lazy(t1), lazy(t2), lazy(t3)
                cnt = wrist_store(n, C, Tn, Rg, W, xs, t1, t2, t3, R3, f0, tol, wrist_tol,
                                  dedup, newton, out_q, out_s, out_valid, out_pos, out_rot,
                                  out_sing, out_sign, out_fam, cnt)
        return cnt
    o1 = (G[0], G[1], G[2])
    r2 = (G[3], G[4], G[5])
    u0 = (G[6], G[7], G[8])
    u1 = (G[9], G[10], G[11])
    u2 = (G[12], G[13], G[14])
    A, sa, ca = G[15], G[16], G[17]
    d = _sub(pw, o1)
    rho2 = _dot(d, d)
    zeta = _dot(W0, d)
    # |u|² = N0 + N1 c + N2 s and ω2·u = H0 + H1 c + H2 s, u = g3(θ3) − r2
    N0 = _dot(u0, u0) + _dot(u1, u1)
    N1 = 2.0 * _dot(u0, u1)
    N2 = 2.0 * _dot(u0, u2)
    H0, H1, H2 = _dot(W1, u0), _dot(W1, u1), _dot(W1, u2)
    # x = e1·R2 u⊥ and y = e2·R2 u⊥, linear in (1, c, s); x² + y² = |u|² − (ω2·u)²
    X = ((rho2 - A * A - N0) / (2.0 * A), -N1 / (2.0 * A), -N2 / (2.0 * A))
    Y = ((zeta - ca * H0) / sa, -ca * H1 / sa, -ca * H2 / sa)
    f = (-N0, -N1, -N2, 0.0, 0.0)
    f = _sq(X[0], X[1], X[2], f)
    f = _sq(Y[0], Y[1], Y[2], f)
    f = _sq(H0, H1, H2, f)
    k, cs, sn = theta3_roots(f)
    e1 = _scale(_sub(r2, o1), 1.0 / A)
    e2 = _cross(W1, e1)
    for i in range(k):
        c, s = cs[i], sn[i]
        t3 = (math.atan2(s, c), c, s)
        R3 = _rot(W2, t3)
        u = _add(u0, _add(_scale(u1, c), _scale(u2, s)))
        up = _sub(u, _scale(W1, _dot(W1, u)))
        v = _add(_scale(e1, X[0] + X[1] * c + X[2] * s), _scale(e2, Y[0] + Y[1] * c + Y[2] * s))
        t2 = _pair(_dot(W1, _cross(up, v)), _dot(up, v))
        q2 = _add(r2, _mv(_rot(W1, t2), u))
        t1 = _sp1(W0, o1, q2, pw)
        if out_s is not None:
            t1, t2, t3 = lazy(t1), lazy(t2), lazy(t3)
        cnt = wrist_store(n, C, Tn, Rg, W, xs, t1, t2, t3, R3, f0, tol, wrist_tol, dedup, newton,
                          out_q, out_s, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam,
                          cnt)
    return cnt


@nb.njit(**_INLINE)
def _unpack(Kp):
    """The data packed by :func:`kinestat.serial.analytic._offset_pack.pack`: ``C (7, 4, 4)``,
    ``T0inv``, ``W (6, 3)``, ``P (6, 3)``, the wrist centre, a unit vector normal to axis 6 and
    the shoulder's 20 numbers ``G``."""
    return (Kp[:112].reshape((7, 4, 4)), Kp[112:128].reshape((4, 4)), Kp[128:146].reshape((6, 3)),
            Kp[146:164].reshape((6, 3)), Kp[164:167], Kp[167:170], Kp[170:190])


@nb.njit(**_OPTS)
def offset_one(Kp, T, tol, wrist_tol, q, valid, pos, rot, sing, sign, fam):
    """:func:`~kinestat.serial.analytic._offset_batch.offset_serial` on one pose without
    Newton steps, the outputs in a one-pose result's shapes (as
    :func:`kinestat.serial.analytic._cf_single.pieper_one`): the count, or negative where the
    caller takes the full path."""
    C, T0inv, W, P, w, x6, G = _unpack(Kp)
    return _offset_pose(0, C, T, T0inv, W, P, w, x6, G, tol, wrist_tol, 1e-6, None,
                        q[None], None, valid[None], pos[None],
                        rot[None], sing[None], sign[None],
                        fam[None])
