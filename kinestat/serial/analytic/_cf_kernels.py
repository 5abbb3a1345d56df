"""Compiled (Numba) kernels of the closed forms (:mod:`kinestat.serial.analytic.closed_form`
is the NumPy reference): Paden–Kahan subproblems, one pose per ``prange`` iteration, FK
verification and de-duplication in the kernel.

Allocation-free: 3-vectors are 3-tuples and rotations 9-tuples (row-major) held in registers;
the verification runs the serial FK kernel's scalar steps (through
:mod:`kinestat.serial.analytic._solution_kernels`) and writes straight into the caller's output
arrays. Only the rare pose whose candidate misses
the tolerance (rounding next to a singular set) allocates, for two Newton steps.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.serial._kernels import _affine, _start, _turn
from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._cf_storage import store_angles, store_pair
from kinestat.serial.analytic._solution_kernels import wrap as _wrap

_Z3 = (0.0, 0.0, 0.0)
#: a pose's rotation must be orthonormal with det +1 within this (the NumPy check's default)
RIGID_TOL = 1e-6


# -- 3-vectors and rotations as tuples ----------------------------------------------------------
@nb.njit(**_INLINE)
def _row(A, i):
    return (A[i, 0], A[i, 1], A[i, 2])


@nb.njit(**_INLINE)
def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@nb.njit(**_INLINE)
def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@nb.njit(**_INLINE)
def _scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@nb.njit(**_INLINE)
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@nb.njit(**_INLINE)
def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@nb.njit(**_INLINE)
def _norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@nb.njit(**_INLINE)
def _pair(y, x):
    """``(θ, cos θ, sin θ)`` of ``θ = atan2(y, x)``: the cosine and sine are the normalised
    arguments (no cos/sin call; equal to ``cos θ``, ``sin θ`` to rounding)."""
    h = math.sqrt(x * x + y * y)
    if h == 0.0:
        return 0.0, 1.0, 0.0
    return math.atan2(y, x), x / h, y / h


@nb.njit(**_INLINE)
def _unit(y, x):
    """``(cos θ, sin θ)`` of ``θ = atan2(y, x)`` (θ itself not needed)."""
    h = math.sqrt(x * x + y * y)
    if h == 0.0:
        return 1.0, 0.0
    return x / h, y / h


@nb.njit(**_INLINE)
def _shift(a, c, s, sign):
    """``(θa + sign·α, cos, sin)`` for θa given by its cosine ``a[-2]`` and sine ``a[-1]`` (an
    angle triple or a pair) and α by c, s: the angle-addition formulas, the angle from the
    resulting pair."""
    cs = a[-2] * c - sign * a[-1] * s
    sn = a[-1] * c + sign * a[-2] * s
    return math.atan2(sn, cs), cs, sn


@nb.njit(**_INLINE)
def _rot(w, a):
    """Rodrigues' rotation matrix (MLS eq. 2.14) as a row-major 9-tuple, for the angle triple
    ``a = (θ, cos θ, sin θ)``."""
    c = a[1]
    s = a[2]
    v = 1.0 - c
    x, y, z = w[0], w[1], w[2]
    return (c + x * x * v, x * y * v - z * s, x * z * v + y * s,
            y * x * v + z * s, c + y * y * v, y * z * v - x * s,
            z * x * v - y * s, z * y * v + x * s, c + z * z * v)


@nb.njit(**_INLINE)
def _neg(a):
    """The angle triple of −θ."""
    return -a[0], a[1], -a[2]


@nb.njit(**_INLINE)
def _mv(R, x):
    return (R[0] * x[0] + R[1] * x[1] + R[2] * x[2],
            R[3] * x[0] + R[4] * x[1] + R[5] * x[2],
            R[6] * x[0] + R[7] * x[1] + R[8] * x[2])


@nb.njit(**_INLINE)
def _mtv(R, x):
    """``Rᵀ x``."""
    return (R[0] * x[0] + R[3] * x[1] + R[6] * x[2],
            R[1] * x[0] + R[4] * x[1] + R[7] * x[2],
            R[2] * x[0] + R[5] * x[1] + R[8] * x[2])


@nb.njit(**_INLINE)
def _mm(A, B):
    return (A[0] * B[0] + A[1] * B[3] + A[2] * B[6], A[0] * B[1] + A[1] * B[4] + A[2] * B[7],
            A[0] * B[2] + A[1] * B[5] + A[2] * B[8],
            A[3] * B[0] + A[4] * B[3] + A[5] * B[6], A[3] * B[1] + A[4] * B[4] + A[5] * B[7],
            A[3] * B[2] + A[4] * B[5] + A[5] * B[8],
            A[6] * B[0] + A[7] * B[3] + A[8] * B[6], A[6] * B[1] + A[7] * B[4] + A[8] * B[7],
            A[6] * B[2] + A[7] * B[5] + A[8] * B[8])


@nb.njit(**_INLINE)
def _mtm(A, B):
    """``Aᵀ B``."""
    return (A[0] * B[0] + A[3] * B[3] + A[6] * B[6], A[0] * B[1] + A[3] * B[4] + A[6] * B[7],
            A[0] * B[2] + A[3] * B[5] + A[6] * B[8],
            A[1] * B[0] + A[4] * B[3] + A[7] * B[6], A[1] * B[1] + A[4] * B[4] + A[7] * B[7],
            A[1] * B[2] + A[4] * B[5] + A[7] * B[8],
            A[2] * B[0] + A[5] * B[3] + A[8] * B[6], A[2] * B[1] + A[5] * B[4] + A[8] * B[7],
            A[2] * B[2] + A[5] * B[5] + A[8] * B[8])


@nb.njit(**_INLINE)
def _mmt(A, B):
    """``A Bᵀ``."""
    return (A[0] * B[0] + A[1] * B[1] + A[2] * B[2], A[0] * B[3] + A[1] * B[4] + A[2] * B[5],
            A[0] * B[6] + A[1] * B[7] + A[2] * B[8],
            A[3] * B[0] + A[4] * B[1] + A[5] * B[2], A[3] * B[3] + A[4] * B[4] + A[5] * B[5],
            A[3] * B[6] + A[4] * B[7] + A[5] * B[8],
            A[6] * B[0] + A[7] * B[1] + A[8] * B[2], A[6] * B[3] + A[7] * B[4] + A[8] * B[5],
            A[6] * B[6] + A[7] * B[7] + A[8] * B[8])


@nb.njit(**_INLINE)
def lazy(a):
    """The angle triple a without its angle (0): for the batch kernels, which store cosines and
    sines only, so that the compiler drops the ``atan2`` that made it."""
    return 0.0, a[1], a[2]


@nb.njit(**_INLINE)
def _rotate(w, r, a, x):
    """The point x turned by the angle triple a about the axis (ω, r)."""
    return _add(r, _mv(_rot(w, a), _sub(x, r)))


@nb.njit(**_INLINE)
def _pose_times(T, A):
    """Rotation (9-tuple) and translation (3-tuple) of ``T · A`` for 4x4 rigid arrays."""
    R = (T[0, 0], T[0, 1], T[0, 2], T[1, 0], T[1, 1], T[1, 2], T[2, 0], T[2, 1], T[2, 2])
    Ra = (A[0, 0], A[0, 1], A[0, 2], A[1, 0], A[1, 1], A[1, 2], A[2, 0], A[2, 1], A[2, 2])
    t = _add(_mv(R, (A[0, 3], A[1, 3], A[2, 3])), (T[0, 3], T[1, 3], T[2, 3]))
    return _mm(R, Ra), t


# -- Paden–Kahan subproblems (the NumPy references are in subproblems.py) -----------------------
# Every angle is the triple (θ, cos θ, sin θ): the rotations and the FK check use the pair, so
# no cos/sin is evaluated (θ comes from atan2 of the same pair).
@nb.njit(**_INLINE)
def _sp1(w, r, p, q):
    """Subproblem 1: the angle of p → q about (ω, r)."""
    u = _sub(p, r)
    v = _sub(q, r)
    up = _sub(u, _scale(w, _dot(u, w)))
    vp = _sub(v, _scale(w, _dot(v, w)))
    return _pair(_dot(w, _cross(up, vp)), _dot(up, vp))


_NONE = (0.0, 1.0, 0.0)


@nb.njit(**_INLINE)
def _sp2(w1, w2, r, p, q, tol):
    """Subproblem 2 (axes meeting at r): ``(exists, θ1, θ2, θ1', θ2')``."""
    u = _sub(p, r)
    v = _sub(q, r)
    c12 = _dot(w1, w2)
    den = c12 * c12 - 1.0
    a = (c12 * _dot(w2, u) - _dot(w1, v)) / den
    b = (c12 * _dot(w1, v) - _dot(w2, u)) / den
    x = _cross(w1, w2)
    uu = _dot(u, u)
    g2 = (uu - a * a - b * b - 2.0 * a * b * c12) / _dot(x, x)
    if g2 < -tol * (1.0 + uu) or abs(uu - _dot(v, v)) > tol * (1.0 + uu):
        return False, _NONE, _NONE, _NONE, _NONE
    g = math.sqrt(max(g2, 0.0))
    base = _add(r, _add(_scale(w1, a), _scale(w2, b)))
    c = _add(base, _scale(x, g))
    d = _sub(base, _scale(x, g))
    return True, _sp1(w1, r, c, q), _sp1(w2, r, p, c), _sp1(w1, r, d, q), _sp1(w2, r, p, d)


@nb.njit(**_INLINE)
def _sp3(w, r, p, q, delta, tol):
    """Subproblem 3: ``(exists, θ, θ')`` with ``|e^{ξ̂θ} p − q| = δ`` (θ0 ∓ acos c)."""
    u = _sub(p, r)
    v = _sub(q, r)
    up = _sub(u, _scale(w, _dot(u, w)))
    vp = _sub(v, _scale(w, _dot(v, w)))
    t0 = _unit(_dot(w, _cross(up, vp)), _dot(up, vp))
    h = _dot(w, _sub(p, q))
    d2 = delta * delta - h * h
    nu = _norm(up)
    nv = _norm(vp)
    if nu * nv == 0.0:
        return False, _NONE, _NONE
    c = (nu * nu + nv * nv - d2) / (2.0 * nu * nv)
    if abs(c) > 1.0 + tol:
        return False, _NONE, _NONE
    c = min(max(c, -1.0), 1.0)
    s = math.sqrt(1.0 - c * c)
    return True, _shift(t0, c, s, -1.0), _shift(t0, c, s, 1.0)


@nb.njit(**_INLINE)
def _sp4(h, w, p, d, tol):
    """Subproblem 4 (one axis): ``(exists, θ, θ')`` with ``hᵀ R(ω, θ) p = d`` (φ ∓ acos c)."""
    par = _scale(w, _dot(w, p))
    A = _dot(h, _sub(p, par))
    B = _dot(h, _cross(w, p))
    C = d - _dot(h, par)
    n = math.sqrt(A * A + B * B)
    if n <= tol:
        return False, _NONE, _NONE
    c = C / n
    if abs(c) > 1.0 + tol:
        return False, _NONE, _NONE
    c = min(max(c, -1.0), 1.0)
    s = math.sqrt(1.0 - c * c)
    phi = (A / n, B / n)
    return True, _shift(phi, c, s, -1.0), _shift(phi, c, s, 1.0)


# -- spherical wrist --------------------------------------------------------------------------
@nb.njit(**_INLINE)
def spherical_wrist(wa, wb, wc, Rp, xs, tol, wrist_tol):
    """A spherical wrist, axes ωa, ωb, ωc through the origin, turned to ``Ra Rb Rc = Rp``
    (9-tuple): ``Ra Rb ωc = Rp ωc`` (subproblem 2) gives θa, θb, then ``Rc xs = (Ra Rb)ᵀ Rp
    xs`` (subproblem 1; xs across ωc) θc. Returns ``(ok, off, sing, a, b)``: off =
    ``|ωa × Rp ωc|``; sing = off < wrist_tol, the singular set (ωc along ωa: θa and θc turn
    together), where θa = 0 and θb aligns ωc alone; a, b the branches ``(θa, θb, θc, σ)`` (angle
    triples; σ the sign of ``ωa · Rb ωc``: on the singular set the family is θa + σ θc); ok
    False when subproblem 2 has no solution."""
    target = _mv(Rp, wc)
    off = _norm(_cross(wa, target))
    sing = off < wrist_tol
    if sing:  # θa free: θa = 0, align ωc with θb alone
        taa = tab = _NONE
        tba = tbb = _sp1(wb, _Z3, wc, target)
    else:
        ok, taa, tba, tab, tbb = _sp2(wa, wb, _Z3, wc, target, tol)
        if not ok:
            none = (_NONE, _NONE, _NONE, 0.0)
            return False, off, sing, none, none
    px = _mv(Rp, xs)
    Rba = _rot(wb, tba)
    Rbb = _rot(wb, tbb)
    tca = _sp1(wc, _Z3, xs, _mtv(_mm(_rot(wa, taa), Rba), px))
    tcb = _sp1(wc, _Z3, xs, _mtv(_mm(_rot(wa, tab), Rbb), px))
    sa = 1.0 if _dot(wa, _mv(Rba, wc)) >= 0.0 else -1.0
    sb = 1.0 if _dot(wa, _mv(Rbb, wc)) >= 0.0 else -1.0
    return True, off, sing, (taa, tba, tca, sa), (tab, tbb, tcb, sb)


# -- verification, de-duplication, storage ------------------------------------------------------
@nb.njit(**_INLINE)
def _link(C, i, a, t):
    """The running FK transform t (12 scalars) times ``Z(θ_i) C_i`` for the angle triple a of
    joint i (1-based): the serial FK kernel's step with the angle's cosine and sine."""
    return _affine(C[i], _turn(a[1], a[2], t))


@nb.njit(**_INLINE)
def _clear(n, out_q, out_valid, out_pos, out_rot):
    """Empty slots of pose n (NaN, not valid): the caller's outputs are uninitialised."""
    for k in range(out_q.shape[1]):
        for i in range(6):
            out_q[n, k, i] = np.nan
        out_valid[n, k] = False
        out_pos[n, k] = np.nan
        out_rot[n, k] = np.nan


@nb.njit(**_INLINE)
def clear_wrist(n, out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam):
    """Empty slots of pose n, with no wrist family."""
    _clear(n, out_q, out_valid, out_pos, out_rot)
    for k in range(out_q.shape[1]):
        out_sing[n, k] = False
        out_sign[n, k] = 0.0
        out_fam[n, k] = np.nan


@nb.njit(**_OPTS)  # not inlined: the offset shoulder calls it twice (one copy to load)
def wrist_store(n, C, Tn, Rg, W, xs, t1, t2, t3, R3, f0, tol, wrist_tol, dedup, newton, out_q,
                out_s, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam, cnt):
    """The spherical wrist (axes 4, 5, 6 meeting) for the arm angles t1, t2, t3 (triples; R3
    the rotation of t3): ``R4 R5 ω6 = R' ω6`` (subproblem 2), θ6 (subproblem 1), each candidate
    verified and stored; on the singular set (ω6 along ω4) the family's sign and value are
    recorded. Returns the new count. ``out_s`` None: angles into ``out_q``; else cosines into
    ``out_q`` and sines into ``out_s`` (:func:`~kinestat.serial.analytic._cf_storage.
    store_pair`, ``dedup`` then the chord)."""
    Rp = _mtm(_mm(_mm(_rot(_row(W, 0), t1), _rot(_row(W, 1), t2)), R3), Rg)
    ok, _off, sing, wa, wb = spherical_wrist(_row(W, 3), _row(W, 4), _row(W, 5), Rp, xs, tol,
                                             wrist_tol)
    if not ok:
        return cnt
    f3 = _link(C, 3, t3, _link(C, 2, t2, _link(C, 1, t1, f0)))  # shared by 2 wrists
    for i45 in range(2):
        t4, t5, t6, sig = wa if i45 == 0 else wb
        f = _link(C, 6, t6, _link(C, 5, t5, _link(C, 4, t4, f3)))
        if out_s is None:
            q = (t1[0], t2[0], t3[0], t4[0], t5[0], t6[0])
            new = store_angles(n, C, Tn, q, f, tol, dedup, newton, out_q, out_valid, out_pos,
                               out_rot, cnt)
            if new > cnt and sing:
                out_fam[n, cnt] = _wrap(out_q[n, cnt, 3] + sig * out_q[n, cnt, 5])
        else:
            new = store_pair(n, C, Tn, (t1[1], t2[1], t3[1], t4[1], t5[1], t6[1]),
                              (t1[2], t2[2], t3[2], t4[2], t5[2], t6[2]), f, tol, dedup,
                              newton, out_q, out_s, out_valid, out_pos, out_rot, cnt)
            if new > cnt and sing:  # θ4 + σ θ6 from the stored cosines and sines
                c4, s4 = out_q[n, cnt, 3], out_s[n, cnt, 3]
                c6, s6 = out_q[n, cnt, 5], out_s[n, cnt, 5]
                out_fam[n, cnt] = _wrap(math.atan2(s4 * c6 + sig * c4 * s6,
                                                   c4 * c6 - sig * s4 * s6))
        if new > cnt and sing:
            out_sing[n, cnt] = True
            out_sign[n, cnt] = sig
        cnt = new
    return cnt


# -- spherical wrist, shoulder axes meeting (Pieper) --------------------------------------------
@nb.njit(**_OPTS)
def _pieper_pose(n, C, T, T0inv, W, P, w, s, x6, tol, wrist_tol, dedup, newton, out_q, out_s,
                 out_valid, out_pos, out_rot, out_sing, out_sign, out_fam):
    clear_wrist(n, out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam)
    status = _pose_status(T, n, RIGID_TOL)
    if status:
        return -status
    Tn = T[n]
    Rg, tg = _pose_times(Tn, T0inv)
    W0, W1, W2 = _row(W, 0), _row(W, 1), _row(W, 2)
    P2 = _row(P, 2)
    wc = (w[0], w[1], w[2])
    sc = (s[0], s[1], s[2])
    xs = (x6[0], x6[1], x6[2])
    pw = _add(_mv(Rg, wc), tg)
    ok3, a3, b3 = _sp3(W2, P2, wc, sc, _norm(_sub(pw, sc)), tol)
    if not ok3:
        return 0
    f0 = _start(C[0])
    cnt = 0
    for i3 in range(2):
        t3 = a3 if i3 == 0 else b3
        R3 = _rot(W2, t3)
        w3 = _add(P2, _mv(R3, _sub(wc, P2)))
        ok12, t1a, t2a, t1b, t2b = _sp2(W0, W1, sc, w3, pw, tol)
        if not ok12:
            continue
        for i12 in range(2):
            t1 = t1a if i12 == 0 else t1b
            t2 = t2a if i12 == 0 else t2b
            if out_s is not None:
                t1, t2, t3 = lazy(t1), lazy(t2), lazy(t3)
            cnt = wrist_store(n, C, Tn, Rg, W, xs, t1, t2, t3, R3, f0, tol, wrist_tol, dedup,
                              newton, out_q, out_s, out_valid, out_pos, out_rot, out_sing,
                              out_sign, out_fam, cnt)
    return cnt


@nb.njit(**_INLINE)
def _unpack(Kp):
    """The pose-independent data packed by :func:`pack` (one array: one argument to unbox per
    call): ``C (7, 4, 4)``, ``T0inv (4, 4)``, ``W (6, 3)``, ``P (6, 3)`` and three 3-vectors."""
    return (Kp[:112].reshape((7, 4, 4)), Kp[112:128].reshape((4, 4)), Kp[128:146].reshape((6, 3)),
            Kp[146:164].reshape((6, 3)), Kp[164:167], Kp[167:170], Kp[170:173])


def pack(C, T0inv, W, P, a, b, c) -> np.ndarray:
    """Pack a kernel's pose-independent data (see :func:`_unpack`) into one float array."""
    return np.ascontiguousarray(np.concatenate([np.ravel(x) for x in (C, T0inv, W, P, a, b, c)]),
                                dtype=np.float64)


# -- three parallel axes, wrist pair meeting (UR type) ------------------------------------------
@nb.njit(**_INLINE)
def _theta4(phi, t2, t3, sg):
    """θ4 = σ3 (φ − σ1 θ2 − σ2 θ3) (axes 2-4 parallel with signs σ) as an angle triple."""
    u = _shift(phi, t2[1], t2[2], -sg[0])
    u = _shift(u, t3[1], t3[2], -sg[1])
    return sg[2] * (phi[0] - sg[0] * t2[0] - sg[1] * t3[0]), u[1], sg[2] * u[2]


@nb.njit(**_OPTS)
def _three_parallel_pose(n, C, T, T0inv, W, P, p56, xh, sg, tol, wrist_tol, dedup, newton, out_q,
                         out_s, out_valid, out_pos, out_rot, out_near):
    _clear(n, out_q, out_valid, out_pos, out_rot)
    out_near[n] = False
    status = _pose_status(T, n, RIGID_TOL)
    if status:
        return -status
    Tn = T[n]
    Rg, tg = _pose_times(Tn, T0inv)
    W0, W1, W2, W4, W5 = _row(W, 0), _row(W, 1), _row(W, 2), _row(W, 4), _row(W, 5)
    P0, P1, P2, P3, P4, P5 = _row(P, 0), _row(P, 1), _row(P, 2), _row(P, 3), _row(P, 4), _row(P, 5)
    h = W1
    pc = (p56[0], p56[1], p56[2])
    xc = (xh[0], xh[1], xh[2])
    q56 = _add(_mv(Rg, pc), tg)
    ok1, psi_a, psi_b = _sp4(h, W0, _sub(q56, P0), _dot(h, _sub(pc, P0)), tol)  # ψ = −θ1
    if not ok1:
        return 0
    f0 = _start(C[0])
    cnt = 0
    for i1 in range(2):
        psi = psi_a if i1 == 0 else psi_b
        Rr = _mm(_rot(W0, psi), Rg)
        hr = _mtv(Rr, h)
        off = _norm(_cross(hr, W5))
        if off < 1e-6:
            out_near[n] = True
        if off < wrist_tol:
            continue  # wrist-singular: axis 6 parallel to axes 2-4 (families.py adds them)
        ok5, t5a, t5b = _sp4(h, W4, W5, _dot(h, _mv(Rr, W5)), tol)
        if not ok5:
            continue
        t1 = _neg(psi)
        f1 = _link(C, 1, t1, f0)
        for i5 in range(2):
            t5 = t5a if i5 == 0 else t5b
            R5 = _rot(W4, t5)
            t6 = _sp1(W5, _Z3, hr, _mtv(R5, h))
            R234 = _mmt(Rr, _mm(R5, _rot(W5, t6)))
            phi = _sp1(h, _Z3, xc, _mv(R234, xc))
            y = _rotate(W5, P5, _neg(t6), _rotate(W4, P4, _neg(t5), P3))
            y = _rotate(W0, P0, psi, _add(_mv(Rg, y), tg))
            ok3, t3a, t3b = _sp3(W2, P2, P3, P1, _norm(_sub(y, P1)), tol)
            if not ok3:
                continue
            for i3 in range(2):
                t3 = t3a if i3 == 0 else t3b
                t2 = _sp1(W1, P1, _rotate(W2, P2, t3, P3), y)
                t4 = _theta4(phi, t2, t3, sg)
                f = _link(C, 6, t6, _link(C, 5, t5, _link(C, 4, t4, _link(
                    C, 3, t3, _link(C, 2, t2, f1)))))
                if out_s is None:
                    q = (t1[0], t2[0], t3[0], t4[0], t5[0], t6[0])
                    cnt = store_angles(n, C, Tn, q, f, tol, dedup, newton, out_q, out_valid,
                                       out_pos, out_rot, cnt)
                else:  # the angles after the kernel: no atan2 here
                    cnt = store_pair(n, C, Tn, (t1[1], t2[1], t3[1], t4[1], t5[1], t6[1]),
                                      (t1[2], t2[2], t3[2], t4[2], t5[2], t6[2]), f, tol,
                                      dedup, newton, out_q, out_s, out_valid, out_pos, out_rot,
                                      cnt)
    return cnt


# -- pose checks ------------------------------------------------------------------------------
@nb.njit(**_INLINE)
def _pose_status(T, n, tol):
    """0: a rotation orthonormal to rounding (1e-13); 1: within tol only (to be projected);
    2: not a finite rigid transform."""
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[n, i, j]):
                return 2
    if T[n, 3, 0] != 0.0 or T[n, 3, 1] != 0.0 or T[n, 3, 2] != 0.0 or T[n, 3, 3] != 1.0:
        return 2
    worst = 0.0
    for i in range(3):
        for j in range(3):
            d = T[n, i, 0] * T[n, j, 0] + T[n, i, 1] * T[n, j, 1] + T[n, i, 2] * T[n, j, 2]
            worst = max(worst, abs(d - (1.0 if i == j else 0.0)))
    if worst > tol:
        return 2
    det = (T[n, 0, 0] * (T[n, 1, 1] * T[n, 2, 2] - T[n, 1, 2] * T[n, 2, 1])
           - T[n, 0, 1] * (T[n, 1, 0] * T[n, 2, 2] - T[n, 1, 2] * T[n, 2, 0])
           + T[n, 0, 2] * (T[n, 1, 0] * T[n, 2, 1] - T[n, 1, 1] * T[n, 2, 0]))
    if abs(det - 1.0) > tol:
        return 2
    return 1 if worst > 1e-13 else 0


@nb.njit(**_OPTS)
def check_rigid(T, tol):
    """``(first, n_project)``: the index of the first pose of ``T (N, 4, 4)`` that is not a
    finite rigid transform (rotation orthonormal with det +1 within tol, last row
    [0, 0, 0, 1]) or −1, and how many poses are orthonormal within tol but not to rounding
    (1e-13: the caller projects them onto the nearest rotation)."""
    n_project = 0
    for n in range(T.shape[0]):
        st = _pose_status(T, n, tol)
        if st == 2:
            return n, n_project
        n_project += st
    return -1, n_project

