"""Compiled (Numba) kernels of the PUMA 762 closed form (:mod:`kinestat.robots.puma762`).

They compute what the NumPy reference (:mod:`kinestat.robots.puma762._reference`:
``reverse_arrays`` + :func:`~kinestat.robots.puma762.forward.pose_residuals`) computes,
one pose at a time in scalars: the wrist centre, φ1 (two roots), θ3 (two roots), θ2, then for
each arm the wrist angles θ5 (two roots), θ4 and θ6 (Vibhute eqs. 2-47..2-53 as written out in
the reference), and — when asked — the forward analysis of every branch (eq. 2-33) as the
verification. Batches are split over the cores with ``prange``; the single-pose entry points
also check and build the frame from the thesis's description (``frame6``) and mark duplicate
solutions, so that one reverse analysis is one compiled call.

Compiled on first use and cached on disk (``cache=True``, in ``__pycache__``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

# mechanism parameters and status codes: defined once, in params (Numba freezes them)
from kinestat.robots.puma762.params import (
    _A,
    _CA,
    _S,
    _SA,
    A23,
    S2,
    S4,
    S6,
    STATUS_INSIDE_CYLINDER,
    STATUS_OK,
    STATUS_TOO_FAR,
    STATUS_TOO_NEAR,
)
from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial._numba_options import PI as _PI
from kinestat.serial._numba_options import SQRT8 as _SQRT8
from kinestat.serial._numba_options import TWO_PI as _TWO_PI
from kinestat.spatial.tolerances import ORTHO_TOL

_NO_ARM = (0.0,) * 12

# classification of the branches of one pose (single-pose entry points)
KIND_INVALID = 0
KIND_SOLUTION = 1
KIND_FAMILY = 2
KIND_DUPLICATE = 3

# input errors of the single-pose entry points (the caller words the message)
ERR_NONE = 0
ERR_NONFINITE_P = 1
ERR_NONFINITE_Z = 2
ERR_NONFINITE_X = 3
ERR_NONFINITE_P6 = 4
ERR_Z_NOT_UNIT = 5
ERR_X_NOT_UNIT = 6
ERR_NOT_PERPENDICULAR = 7
ERR_NOT_RIGID = 8


@nb.njit(**_OPTS)
def _wrap(x):
    return (x + _PI) % _TWO_PI - _PI


@nb.njit(**_OPTS)
def _link(ca, sa, a, S, c, s, f):
    """Frame columns ``f = (x, y, z, p)`` (12 scalars) times ``Rx(α) Tx(a) Rz(θ) Tz(S)``
    (eq. 2-26) given cos θ, sin θ: the reference's ``_frame_columns`` step."""
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = f
    if a != 0.0:
        p0 += a * x0
        p1 += a * x1
        p2 += a * x2
    if sa != 0.0:
        y0, z0 = ca * y0 + sa * z0, ca * z0 - sa * y0
        y1, z1 = ca * y1 + sa * z1, ca * z1 - sa * y1
        y2, z2 = ca * y2 + sa * z2, ca * z2 - sa * y2
    x0, y0 = c * x0 + s * y0, c * y0 - s * x0
    x1, y1 = c * x1 + s * y1, c * y1 - s * x1
    x2, y2 = c * x2 + s * y2, c * y2 - s * x2
    if S != 0.0:
        p0 += S * z0
        p1 += S * z1
        p2 += S * z2
    return (x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2)


@nb.njit(**_OPTS)
def _arm(c1, s1, c2, s2, c3, s3):
    """Frame 3 of ``F_1T · 1_2T · 2_3T`` (eq. 2-33's first three factors)."""
    f = (c1, s1, 0.0, -s1, c1, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
    f = _link(_CA[0], _SA[0], _A[0], _S[0], c2, s2, f)
    return _link(_CA[1], _SA[1], _A[1], _S[1], c3, s3, f)


@nb.njit(**_OPTS)
def _wrist_residual(f, c4, s4, c5, s5, c6, s6, T):
    """Frame 6 from the arm's frame 3 and the wrist angles, against the pose ``T``: (position
    error of frame 6's origin, rotation angle ``2 asin(|R − R_t|_F / 2√2)``)."""
    f = _link(_CA[2], _SA[2], _A[2], _S[2], c4, s4, f)
    f = _link(_CA[3], _SA[3], _A[3], _S[3], c5, s5, f)
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = _link(_CA[4], _SA[4], _A[4], _S[4],
                                                           c6, s6, f)
    dp = (p0 - T[0, 3]) ** 2 + (p1 - T[1, 3]) ** 2 + (p2 - T[2, 3]) ** 2
    d2 = ((x0 - T[0, 0]) ** 2 + (x1 - T[1, 0]) ** 2 + (x2 - T[2, 0]) ** 2
          + (y0 - T[0, 1]) ** 2 + (y1 - T[1, 1]) ** 2 + (y2 - T[2, 1]) ** 2
          + (z0 - T[0, 2]) ** 2 + (z1 - T[1, 2]) ** 2 + (z2 - T[2, 2]) ** 2)
    return math.sqrt(dp), 2.0 * math.asin(min(math.sqrt(d2) / _SQRT8, 1.0))


@nb.njit(**_OPTS)
def solve_pose(T, tol, s5_tol, verify, q, valid, sing, fsum, fval, pe, re):
    """All eight branches of one pose of frame 6 ``T (4, 4)`` into ``q (8, 6)`` and the flag
    and residual arrays ``(8,)``, exactly as ``reverse_batch_pose`` reports them; returns the
    status code. Branch ``4·i1 + 2·i3 + i5``. The verification is the forward analysis of the
    returned angles (the arm's frame 3 shared by the two wrist branches)."""
    r00, r10, r20 = T[0, 0], T[1, 0], T[2, 0]  # a67_F (x6)
    r02, r12, r22 = T[0, 2], T[1, 2], T[2, 2]  # S6_F (z6)
    wx = T[0, 3] - S6 * r02  # wrist centre W = P6 − S6 · S6_F
    wy = T[1, 3] - S6 * r12
    wz = T[2, 3] - S6 * r22
    # φ1: −sin φ1 Wx + cos φ1 Wy = −S2, ux = ±sqrt(r² − S2²)
    r = math.hypot(wx, wy)
    inside = r < S2 - tol
    ux = math.sqrt(max((r - S2) * (r + S2), 0.0))
    # θ3: ux² + Wz² = a23² + S4² − 2 a23 S4 sin θ3
    rho = math.hypot(ux, wz)
    too_far = rho > A23 + S4 + tol
    too_near = rho < abs(A23 - S4) - tol
    s3 = min(max((A23 * A23 + S4 * S4 - rho * rho) / (2.0 * A23 * S4), -1.0), 1.0)
    d_near = abs(A23 - S4)
    d_far = A23 + S4
    c3 = math.sqrt(max((rho - d_near) * (rho + d_near), 0.0)
                   * max((d_far - rho) * (d_far + rho), 0.0)) / (2.0 * A23 * S4)
    status = STATUS_OK
    if too_near:
        status = STATUS_TOO_NEAR
    if too_far:
        status = STATUS_TOO_FAR
    if inside:
        status = STATUS_INSIDE_CYLINDER
    ok = status == STATUS_OK
    pe0 = np.nan
    re0 = np.nan
    if verify and not ok:  # the reference verifies an invalid branch at q = 0
        f0 = _arm(1.0, 0.0, 1.0, 0.0, 1.0, 0.0)
        pe0, re0 = _wrist_residual(f0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, T)
    aw = math.atan2(wy, wx)
    clean_lim = 1e-3 * tol
    for i1 in range(2):
        ux_i = ux if i1 == 0 else -ux
        phi = _wrap(aw + math.atan2(S2, ux_i))
        cf = math.cos(phi)
        sf = math.sin(phi)
        hz = cf * r02 + sf * r12
        hx = cf * r00 + sf * r10
        n12 = cf * r12 - sf * r02
        n10 = cf * r10 - sf * r00
        a_wz = math.atan2(wz, ux_i)
        for i3 in range(2):
            c3_i = c3 if i3 == 0 else -c3
            th3 = math.atan2(s3, c3_i)
            th2 = _wrap(a_wz - math.atan2(S4 * c3_i, A23 - S4 * s3))
            th23 = th2 + th3
            c23 = math.cos(th23)
            s23 = math.sin(th23)
            n02 = c23 * hz + s23 * r22
            n22 = c23 * r22 - s23 * hz
            n00 = c23 * hx + s23 * r20
            n20 = c23 * r20 - s23 * hx
            c5 = -n22
            s5m = math.hypot(n02, n12)
            is_sing = s5m < s5_tol
            is_sum = c5 < 0.0
            clean = s5m * 2.0 * (S6 + 1.0) <= clean_lim
            arm = _NO_ARM
            if verify and ok:
                arm = _arm(cf, sf, math.cos(th2), math.sin(th2), math.cos(th3), math.sin(th3))
            for i5 in range(2):
                sign = 1.0 if i5 == 0 else -1.0
                s5 = s5m * sign
                th5 = math.atan2(s5, c5)
                th4 = 0.0 if clean else math.atan2(n12 * sign, n02 * sign)
                c4 = math.cos(th4)
                s4 = math.sin(th4)
                v0 = c4 * n00 + s4 * n10
                v1 = c4 * n10 - s4 * n00
                th6 = math.atan2(-v1, c5 * v0 + s5 * n20)
                b = 4 * i1 + 2 * i3 + i5
                v = ok
                if verify:
                    if ok:
                        pe[b], re[b] = _wrist_residual(arm, c4, s4, math.cos(th5),
                                                       math.sin(th5), math.cos(th6),
                                                       math.sin(th6), T)
                        v = pe[b] <= tol and re[b] <= tol
                    else:
                        pe[b] = pe0
                        re[b] = re0
                else:
                    pe[b] = np.nan
                    re[b] = np.nan
                qb = q[b]
                valid[b] = v
                if v:
                    qb[0] = phi
                    qb[1] = th2
                    qb[2] = th3
                    qb[3] = th4
                    qb[4] = th5
                    qb[5] = th6
                else:
                    for j in range(6):
                        qb[j] = np.nan
                sing[b] = is_sing and v
                fsum[b] = is_sum and is_sing and v
                if is_sing and v:
                    fval[b] = _wrap(th6 + th4) if is_sum else _wrap(th6 - th4)
                else:
                    fval[b] = np.nan
    return status


@nb.njit(**_INLINE)
def _solve_row(T, k, tol, s5_tol, verify, q, valid, sing, fsum, fval, status, pe, re):
    """:func:`solve_pose` of pose ``k``; returns 1 when it is not finite (its row is left
    unwritten), else 0."""
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[k, i, j]):
                return 1
    status[k] = solve_pose(T[k], tol, s5_tol, verify, q[k], valid[k], sing[k], fsum[k],
                           fval[k], pe[k], re[k])
    return 0


@nb.njit(**_OPTS)
def reverse_serial(T, tol, s5_tol, verify, q, valid, sing, fsum, fval, status, pe, re):
    """:func:`reverse_batch` on one thread (small batches: no thread start-up)."""
    bad = 0
    for k in range(T.shape[0]):
        bad += _solve_row(T, k, tol, s5_tol, verify, q, valid, sing, fsum, fval, status, pe, re)
    return bad


@nb.njit(parallel=True, **_OPTS)
def reverse_batch(T, tol, s5_tol, verify, q, valid, sing, fsum, fval, status, pe, re):
    """:func:`solve_pose` over ``T (N, 4, 4)``; returns the number of non-finite poses (their
    rows are left unwritten)."""
    bad = 0
    for k in nb.prange(T.shape[0]):
        bad += _solve_row(T, k, tol, s5_tol, verify, q, valid, sing, fsum, fval, status, pe, re)
    return bad


@nb.njit(**_INLINE)
def _finite3(v):
    """True when the three components of ``v`` are finite."""
    return math.isfinite(v[0]) and math.isfinite(v[1]) and math.isfinite(v[2])


@nb.njit(**_INLINE)
def _axes_deviation(z0, z1, z2, x0, x1, x2):
    """|‖S6‖ − 1|, |‖a67‖ − 1| and |S6·a67| of the end effector's two unit vectors."""
    return (abs(math.sqrt(z0 * z0 + z1 * z1 + z2 * z2) - 1.0),
            abs(math.sqrt(x0 * x0 + x1 * x1 + x2 * x2) - 1.0),
            abs(z0 * x0 + z1 * x1 + z2 * x2))


@nb.njit(**_INLINE)
def _axes_problem(z0, z1, z2, x0, x1, x2, tol):
    """(error code, deviation) of S6 and a67 against ``tol``: ``(ERR_NONE, 0)`` when both are
    unit vectors and perpendicular."""
    dz, dx, dd = _axes_deviation(z0, z1, z2, x0, x1, x2)
    if dz > tol:
        return ERR_Z_NOT_UNIT, dz
    if dx > tol:
        return ERR_X_NOT_UNIT, dx
    if dd > tol:
        return ERR_NOT_PERPENDICULAR, dd
    return ERR_NONE, 0.0


@nb.njit(**_OPTS)
def _frame6(p0, p1, p2, z0, z1, z2, x0, x1, x2, t0, t1, t2, T):
    """``frame6``: normalise S6, Gram–Schmidt a67 against it, y = z × x, origin p − R p6."""
    nz = math.sqrt(z0 * z0 + z1 * z1 + z2 * z2)
    z0 /= nz
    z1 /= nz
    z2 /= nz
    d = z0 * x0 + z1 * x1 + z2 * x2
    x0 -= d * z0
    x1 -= d * z1
    x2 -= d * z2
    nx = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    x0 /= nx
    x1 /= nx
    x2 /= nx
    y0 = z1 * x2 - z2 * x1
    y1 = z2 * x0 - z0 * x2
    y2 = z0 * x1 - z1 * x0
    T[0, 0], T[0, 1], T[0, 2], T[0, 3] = x0, y0, z0, p0 - (x0 * t0 + y0 * t1 + z0 * t2)
    T[1, 0], T[1, 1], T[1, 2], T[1, 3] = x1, y1, z1, p1 - (x1 * t0 + y1 * t1 + z1 * t2)
    T[2, 0], T[2, 1], T[2, 2], T[2, 3] = x2, y2, z2, p2 - (x2 * t0 + y2 * t1 + z2 * t2)
    T[3, 0], T[3, 1], T[3, 2], T[3, 3] = 0.0, 0.0, 0.0, 1.0


@nb.njit(**_OPTS)
def frame6_rows(P, Z, X, P6, T):
    """``frame6`` for rows ``(N, 3)`` into ``T (N, 4, 4)``; returns the largest |‖S6‖ − 1|,
    |‖a67‖ − 1| and |S6·a67| (the caller checks them against its tolerance). Inputs finite."""
    dz = 0.0
    dx = 0.0
    dd = 0.0
    for k in range(P.shape[0]):
        z0, z1, z2 = Z[k, 0], Z[k, 1], Z[k, 2]
        x0, x1, x2 = X[k, 0], X[k, 1], X[k, 2]
        ez, ex, ed = _axes_deviation(z0, z1, z2, x0, x1, x2)
        dz = max(dz, ez)
        dx = max(dx, ex)
        dd = max(dd, ed)
        _frame6(P[k, 0], P[k, 1], P[k, 2], z0, z1, z2, x0, x1, x2, P6[k, 0], P6[k, 1],
                P6[k, 2], T[k])
    return dz, dx, dd


@nb.njit(**_OPTS)
def _same(a0, a1, a2, a3, b0, b1, b2, b3, tol):
    return (abs(_wrap(a0 - b0)) <= tol and abs(_wrap(a1 - b1)) <= tol
            and abs(_wrap(a2 - b2)) <= tol and abs(_wrap(a3 - b3)) <= tol)


@nb.njit(**_OPTS)
def _classify(q, valid, sing, fsum, fval, dup_tol, kind):
    """Mark each branch: invalid, a distinct isolated solution, a distinct wrist-singular family
    or a duplicate of an earlier one (the reference rules of ``puma762.reverse.reverse_one``)."""
    for k in range(8):
        if not valid[k]:
            kind[k] = KIND_INVALID
            continue
        kind[k] = KIND_DUPLICATE
        dup = False
        for j in range(k):
            if kind[j] == KIND_FAMILY and sing[k] and fsum[j] == fsum[k]:
                if _same(q[j, 0], q[j, 1], q[j, 2], fval[j], q[k, 0], q[k, 1], q[k, 2],
                         fval[k], dup_tol):
                    dup = True
                    break
            elif kind[j] == KIND_SOLUTION and not sing[k]:
                if (_same(q[j, 0], q[j, 1], q[j, 2], q[j, 3], q[k, 0], q[k, 1], q[k, 2],
                          q[k, 3], dup_tol)
                        and abs(_wrap(q[j, 4] - q[k, 4])) <= dup_tol
                        and abs(_wrap(q[j, 5] - q[k, 5])) <= dup_tol):
                    dup = True
                    break
        if not dup:
            kind[k] = KIND_FAMILY if sing[k] else KIND_SOLUTION


@nb.njit(**_OPTS)
def _solve_one(T, tol, s5_tol, err, bad):
    q = np.empty((8, 6))
    valid = np.zeros(8, dtype=np.bool_)
    sing = np.zeros(8, dtype=np.bool_)
    fsum = np.zeros(8, dtype=np.bool_)
    fval = np.empty(8)
    pe = np.empty(8)
    re = np.empty(8)
    kind = np.zeros(8, dtype=np.int8)
    status = STATUS_OK
    n_sol = 0
    n_fam = 0
    if err == ERR_NONE:
        status = solve_pose(T, tol, s5_tol, True, q, valid, sing, fsum, fval, pe, re)
        _classify(q, valid, sing, fsum, fval, max(1e3 * tol, 1e-9), kind)
        for k in range(8):
            n_sol += kind[k] == KIND_SOLUTION
            n_fam += kind[k] == KIND_FAMILY
    branches = np.empty(n_sol, dtype=np.int64)
    sols = np.empty((n_sol, 6))
    i = 0
    for k in range(8):
        if kind[k] == KIND_SOLUTION:
            branches[i] = k
            for j in range(6):  # element by element: a row assignment compiles Numba's
                sols[i, j] = q[k, j]  # shape-mismatch message (seconds at first compile)
            i += 1
    n_bad = 0
    for k in range(8):
        n_bad += not valid[k]
    return (err, bad, status, T, q, valid, sing, fsum, fval, pe, re, sols, branches, n_fam,
            n_bad)


@nb.njit(**_OPTS)
def reverse_vectors_one(p, z, x, p6, unit_tol, tol, s5_tol):
    """One verified reverse analysis from ``P_tool_F``, ``S6_F``, ``a67_F``, ``P_tool_6``
    (each ``(3,)``), with ``frame6``'s checks (error code and offending value) and the branch
    classification. Returns ``(err, bad, status, T, q, valid, singular, family_sum,
    family_value, position_error, rotation_error, solutions, branches, n_families,
    n_invalid)``: the distinct isolated solutions and their branch indices, the number of
    distinct wrist-singular families (the first branch of each is ``singular`` and not a
    duplicate) and of invalid branches."""
    err = ERR_NONE
    bad = 0.0
    if not _finite3(p):
        err = ERR_NONFINITE_P
    elif not _finite3(z):
        err = ERR_NONFINITE_Z
    elif not _finite3(x):
        err = ERR_NONFINITE_X
    elif not _finite3(p6):
        err = ERR_NONFINITE_P6
    T = np.empty((4, 4))
    if err == ERR_NONE:
        err, bad = _axes_problem(z[0], z[1], z[2], x[0], x[1], x[2], unit_tol)
        if err == ERR_NONE:
            _frame6(p[0], p[1], p[2], z[0], z[1], z[2], x[0], x[1], x[2], p6[0], p6[1], p6[2],
                    T)
    return _solve_one(T, tol, s5_tol, err, bad)


@nb.njit(**_OPTS)
def reverse_pose_one(M, tol, s5_tol):
    """:func:`reverse_vectors_one` for a 4x4 pose ``M``: checks it is a finite rigid transform
    (|R Rᵀ − I| ≤ ORTHO_TOL, det R ≥ 0), then ``frame6`` of its columns (tolerance ORTHO_TOL)."""
    err = ERR_NONE
    bad = 0.0
    for i in range(4):
        for j in range(4):
            if not math.isfinite(M[i, j]):
                err = ERR_NOT_RIGID
    T = np.empty((4, 4))
    if err == ERR_NONE:
        dev = 0.0
        for i in range(3):
            for j in range(3):
                s = M[i, 0] * M[j, 0] + M[i, 1] * M[j, 1] + M[i, 2] * M[j, 2]
                dev = max(dev, abs(s - (1.0 if i == j else 0.0)))
        det = (M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
               - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
               + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0]))
        if dev > ORTHO_TOL or det < 0.0:
            err = ERR_NOT_RIGID
    if err == ERR_NONE:
        z0, z1, z2 = M[0, 2], M[1, 2], M[2, 2]
        x0, x1, x2 = M[0, 0], M[1, 0], M[2, 0]
        err, bad = _axes_problem(z0, z1, z2, x0, x1, x2, ORTHO_TOL)
        if err == ERR_NONE:
            _frame6(M[0, 3], M[1, 3], M[2, 3], z0, z1, z2, x0, x1, x2, 0.0, 0.0, 0.0, T)
    return _solve_one(T, tol, s5_tol, err, bad)
