"""Compiled search of a grid of PUMA 762 configurations for the one whose tool best realises a
target (the controller's "vernier", :func:`kinestat.control.controller._solve_counts`).

The grid is the product of a few values per joint: ``n1 × n2 × n3`` arm configurations times
``n4 × n5`` wrist configurations (joint 5's values may depend on joint 4's: the axis 4 → 5
coupling of the cell), joint 6 fixed. Each candidate's tool point and S6 come from the forward
analysis (Vibhute eq. 2-33, the link product of :func:`~kinestat.robots.puma762.forward.forward`
split at frame 3): frame 3 per arm configuration, frame 6 relative to frame 3 per wrist
configuration, so the whole grid costs one product per candidate instead of five. The cost of a
candidate whose tool point is off the target by ``d`` is
``(d·ŝ / w_along)² + (|d − (d·ŝ) ŝ| / w_lateral)² + (acos(S6·ŝ) / w_tilt)²`` (``ŝ`` the target's
S6); the first term alone bounds the cost from below, so most candidates are discarded after a
dot product, and whole arm frames after one (their wrists' tool points lie within a small
radius of their centroid; branch and bound: the minimum and its index are exact, ties go to the
lowest index as ``numpy.argmin``). The trigonometric tables are computed by the caller (with
NumPy's operations, exactly as the forward analysis of the reference would), which keeps the
kernel free of the joint and encoder conventions.

Compiled on first use and cached on disk (``cache=True``, in ``__pycache__``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.robots.puma762._kernels import _link, _wrap, reverse_vectors_one
from kinestat.robots.puma762.params import _A, _CA, _S, _SA
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial._numba_options import TWO_PI as _TWO_PI

__all__ = ["grid_nearest", "select_one", "reverse_select_one", "pose_one"]

#: mm: the rounding slack of grid_nearest's bound on an arm frame's along-S6 terms (the
#: terms are sums of a few products of ~1e3 mm, rounded at ~1e-13 mm)
_BOUND_SLACK = 1e-9


@nb.njit(**_OPTS)
def _wrist_tables(cs4, cs5, cs6, p6):
    """Frame 6 relative to frame 3 for every wrist configuration: the tool point ``(n4, n5,
    3)`` and S6 ``(n4, n5, 3)`` in frame-3 coordinates (links 3-4, 4-5, 5-6 of eq. 2-33)."""
    n4, n5 = cs5.shape[0], cs5.shape[1]
    vp = np.empty((n4, n5, 3))
    vz = np.empty((n4, n5, 3))
    for i4 in range(n4):
        f = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
        f4 = _link(_CA[2], _SA[2], _A[2], _S[2], cs4[i4, 0], cs4[i4, 1], f)
        for i5 in range(n5):
            f5 = _link(_CA[3], _SA[3], _A[3], _S[3], cs5[i4, i5, 0], cs5[i4, i5, 1], f4)
            x0, x1, x2, y0, y1, y2, z0, z1, z2, q0, q1, q2 = _link(
                _CA[4], _SA[4], _A[4], _S[4], cs6[0], cs6[1], f5)
            vp[i4, i5, 0] = x0 * p6[0] + y0 * p6[1] + z0 * p6[2] + q0
            vp[i4, i5, 1] = x1 * p6[0] + y1 * p6[1] + z1 * p6[2] + q1
            vp[i4, i5, 2] = x2 * p6[0] + y2 * p6[1] + z2 * p6[2] + q2
            vz[i4, i5, 0] = z0
            vz[i4, i5, 1] = z1
            vz[i4, i5, 2] = z2
    return vp, vz


@nb.njit(**_OPTS)
def _candidate_cost(f3, vp, vz, tp, ts, along, w_lat, w_tilt, a_term):
    """The full cost of one candidate given its arm frame ``f3``, its wrist's frame-3 tool
    point ``vp`` and S6 ``vz``, and its along-S6 term ``a_term``."""
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = f3
    d0 = x0 * vp[0] + y0 * vp[1] + z0 * vp[2] + p0 - tp[0]
    d1 = x1 * vp[0] + y1 * vp[1] + z1 * vp[2] + p1 - tp[1]
    d2 = x2 * vp[0] + y2 * vp[1] + z2 * vp[2] + p2 - tp[2]
    l0 = d0 - along * ts[0]
    l1 = d1 - along * ts[1]
    l2 = d2 - along * ts[2]
    lat = math.sqrt(l0 * l0 + l1 * l1 + l2 * l2) / w_lat
    s0 = x0 * vz[0] + y0 * vz[1] + z0 * vz[2]
    s1 = x1 * vz[0] + y1 * vz[1] + z1 * vz[2]
    s2 = x2 * vz[0] + y2 * vz[1] + z2 * vz[2]
    c = min(max(s0 * ts[0] + s1 * ts[1] + s2 * ts[2], -1.0), 1.0)
    tilt = math.acos(c) / w_tilt
    return a_term + lat * lat + tilt * tilt


@nb.njit(**_OPTS)
def grid_nearest(cs1, cs2, cs3, cs4, cs5, cs6, p6, tp, ts, w_along, w_lat, w_tilt, seed):
    """The grid candidate of least cost (module docstring): ``(index, along, cost)``.

    Args:
        cs1, cs2, cs3: ``(n1, 2)``, ``(n2, 2)``, ``(n3, 2)`` cos and sin of joints 1..3's values.
        cs4: ``(n4, 2)``; cs5: ``(n4, n5, 2)`` joint 5's values for each of joint 4's;
            cs6: ``(2,)`` joint 6 (fixed).
        p6: ``(3,)`` the tool point in frame 6; tp, ts: ``(3,)`` the target tool point and S6.
        w_along, w_lat, w_tilt: the cost's scales (mm, mm, rad).
        seed: a candidate index evaluated first (a good guess speeds the bound up).

    The index is ``(((i1 n2 + i2) n3 + i3) n4 + i4) n5 + i5``; ``along`` is the chosen tool
    point's offset from the target along ``ts`` (mm).
    """
    n1, n2, n3 = cs1.shape[0], cs2.shape[0], cs3.shape[0]
    n4, n5 = cs5.shape[0], cs5.shape[1]
    vp, vz = _wrist_tables(cs4, cs5, cs6, p6)
    # the wrists' tool points lie within ``rho`` of their centroid ``vc``: an arm frame whose
    # centroid term is off by more than ``rho`` (+ rounding slack) beyond the best cost's bound
    # cannot hold a better candidate (|u| ≤ 1), so its wrists are skipped together
    vc0, vc1, vc2 = 0.0, 0.0, 0.0
    for i4 in range(n4):
        for i5 in range(n5):
            vc0 += vp[i4, i5, 0]
            vc1 += vp[i4, i5, 1]
            vc2 += vp[i4, i5, 2]
    vc0, vc1, vc2 = vc0 / (n4 * n5), vc1 / (n4 * n5), vc2 / (n4 * n5)
    rho = 0.0
    for i4 in range(n4):
        for i5 in range(n5):
            e0, e1, e2 = vp[i4, i5, 0] - vc0, vp[i4, i5, 1] - vc1, vp[i4, i5, 2] - vc2
            rho = max(rho, math.sqrt(e0 * e0 + e1 * e1 + e2 * e2))
    rho = rho * (1.0 + 1e-12) + _BOUND_SLACK
    best = np.inf
    best_k = -1
    best_along = 0.0
    nw = n4 * n5
    for sweep in range(2):  # sweep 0: the seed's arm only; sweep 1: the whole grid
        for i1 in range(n1):
            c1, s1 = cs1[i1, 0], cs1[i1, 1]
            f1 = (c1, s1, 0.0, -s1, c1, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
            for i2 in range(n2):
                f2 = _link(_CA[0], _SA[0], _A[0], _S[0], cs2[i2, 0], cs2[i2, 1], f1)
                for i3 in range(n3):
                    arm = (i1 * n2 + i2) * n3 + i3
                    if sweep == 0 and arm != seed // nw:
                        continue
                    f3 = _link(_CA[1], _SA[1], _A[1], _S[1], cs3[i3, 0], cs3[i3, 1], f2)
                    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = f3
                    a0 = (p0 - tp[0]) * ts[0] + (p1 - tp[1]) * ts[1] + (p2 - tp[2]) * ts[2]
                    u0 = x0 * ts[0] + x1 * ts[1] + x2 * ts[2]
                    u1 = y0 * ts[0] + y1 * ts[1] + y2 * ts[2]
                    u2 = z0 * ts[0] + z1 * ts[1] + z2 * ts[2]
                    if sweep == 1:
                        lo = abs(a0 + vc0 * u0 + vc1 * u1 + vc2 * u2) - rho
                        if lo > 0.0:
                            a = lo / w_along
                            if a * a > best:
                                continue  # every wrist's along term exceeds the best cost
                    for i4 in range(n4):
                        for i5 in range(n5):
                            k = arm * nw + i4 * n5 + i5
                            if sweep == 0 and k != seed:
                                continue
                            v = vp[i4, i5]
                            along = a0 + v[0] * u0 + v[1] * u1 + v[2] * u2
                            a = along / w_along
                            a_term = a * a
                            if a_term > best:
                                continue
                            cost = _candidate_cost(f3, v, vz[i4, i5], tp, ts, along, w_lat,
                                                   w_tilt, a_term)
                            if cost < best or (cost == best and k < best_k):
                                best, best_k, best_along = cost, k, along
    return best_k, best_along, best


@nb.njit(**_OPTS)
def _wrap_near(a, c, lo, hi):
    """``wrap_into_limits`` for one angle: ``a`` shifted by whole turns to the value nearest
    ``c`` inside ``[lo, hi]`` (1e-12 slack); ``(value, ok)``, the plain wrap when none is."""
    base = c + _wrap(a - c)
    best = base
    best_d = np.inf
    for m in range(-2, 3):
        cand = base + float(m) * _TWO_PI
        if cand >= lo - 1e-12 and cand <= hi + 1e-12:
            d = abs(cand - c)
            if d < best_d:
                best_d = d
                best = cand
    return best, best_d < np.inf


@nb.njit(**_OPTS)
def select_one(q, valid, sing, fsum, fval, q_now, offset, lo, hi, axis):
    """The least-motion selection of one pose's eight branches (``select_batch`` with
    ``current_q``, one pose): the chosen axis angles into ``axis (6,)``; returns whether any
    branch lies within the limits. ``offset`` is the axis − joint angle offset (6,), ``lo``,
    ``hi`` the axis limits (radians). Wrist-singular branches split the free motion between
    axes 4 and 6."""
    cur = np.empty(6)
    for j in range(6):
        cur[j] = q_now[j] + offset[j]
    cur[0], _ = _wrap_near(cur[0], cur[0], lo[0], hi[0])
    c4, c6 = cur[3], cur[5]
    best_motion = np.inf
    found = False
    a = np.empty(6)
    w = np.empty(6)
    for k in range(q.shape[0]):
        if not valid[k]:
            continue
        for j in range(6):
            a[j] = q[k, j] + offset[j]
        if sing[k]:
            e_sum = _wrap(fval[k] - (c4 + c6))
            e_dif = _wrap(fval[k] - (c6 - c4))
            if fsum[k]:
                a[3], a[5] = c4 + e_sum / 2, c6 + e_sum / 2
            else:
                a[3], a[5] = c4 - e_dif / 2, c6 + e_dif / 2
        ok = True
        motion = 0.0
        for j in range(6):
            w[j], ok_j = _wrap_near(a[j], cur[j], lo[j], hi[j])
            ok = ok and ok_j
            motion += abs(w[j] - cur[j])
        if ok and motion < best_motion:
            best_motion = motion
            found = True
            for j in range(6):
                axis[j] = w[j]
    return found


@nb.njit(**_OPTS)
def pose_one(cs, T):
    """``F_6T`` (eq. 2-33) into ``T (4, 4)`` from the cos and sin ``cs (6, 2)`` of the joint
    angles: the link product of ``forward._frame_columns``, the same operations in the same
    order."""
    c1, s1 = cs[0, 0], cs[0, 1]
    f = (c1, s1, 0.0, -s1, c1, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
    for k in range(5):
        f = _link(_CA[k], _SA[k], _A[k], _S[k], cs[k + 1, 0], cs[k + 1, 1], f)
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = f
    T[0, 0], T[0, 1], T[0, 2], T[0, 3] = x0, y0, z0, p0
    T[1, 0], T[1, 1], T[1, 2], T[1, 3] = x1, y1, z1, p1
    T[2, 0], T[2, 1], T[2, 2], T[2, 3] = x2, y2, z2, p2
    T[3, 0], T[3, 1], T[3, 2], T[3, 3] = 0.0, 0.0, 0.0, 1.0


@nb.njit(**_OPTS)
def reverse_select_one(p, z, x, p6, q_now, offset, lo, hi, axis):
    """:func:`~kinestat.robots.puma762._kernels.reverse_vectors_one` (tolerances 1e-6, 1e-9,
    1e-10) and :func:`select_one` in one call (one dispatch): the axis angles of the
    least-motion solution within ``[lo, hi]`` into ``axis``; False when the reverse analysis
    fails (an error code or status), finds no valid branch or none lies within the limits
    (the caller then runs the NumPy path for its message)."""
    out = reverse_vectors_one(p, z, x, p6, 1e-6, 1e-9, 1e-10)
    err, status, q, valid, sing, fsum, fval = out[0], out[2], out[4], out[5], out[6], out[7], \
        out[8]
    if err or status:
        return False
    any_valid = False
    for i in range(valid.shape[0]):
        if valid[i]:
            any_valid = True
            break
    if not any_valid:
        return False
    return select_one(q, valid, sing, fsum, fval, q_now, offset, lo, hi, axis)
