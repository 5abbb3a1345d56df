"""Compiled (Numba) kernel for 6R arms whose axes 2, 3, 4 meet at one point c (a spherical
joint mid-chain), by the steps of the decoupled solver
(:mod:`kinestat.serial.analytic._decoupled_kernels`).

In product-of-exponentials form ``T M⁻¹ = e^{ξ1θ1} W234 e^{ξ5θ5} e^{ξ6θ6}`` with W234 fixing
c, so with ``G = T M⁻¹``: ``e^{ξ5θ5} e^{ξ6θ6} e^{ξ1'θ1} (G⁻¹ c) = c``, ``ξ1' = Ad(G⁻¹) ξ1``.
That is the wrist-centre equation of a positioning chain with joints (5, 6, 1'), whose first
two axes are the arm's own (the elimination of joints 5, 6 is set up once) and whose third
axis and moving point follow the pose. Its real roots (at most 4) give θ5, θ6, θ1; the
rotation ``R2 R3 R4 = R1ᵀ R_G R6ᵀ R5ᵀ`` gives θ2, θ3, θ4 (subproblems 2 and 1; θ3 = 0/π
families ``θ2 + σ θ4`` where axis 4 lines up with axis 2). At most 8 solutions.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.serial._kernels import _start
from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._cf_kernels import (
    _dot,
    _link,
    _mmt,
    _mtm,
    _mtv,
    _pose_times,
    _rot,
    _row,
    _sp1,
    _sub,
    clear_wrist,
    spherical_wrist,
)
from kinestat.serial.analytic._decoupled_kernels import (
    _fk,
    _joint2,
    _move,
    _polish_pose,
    _polish_position,
    _roots,
    _store,
    _unpack,
)
from kinestat.serial.analytic._solution_kernels import pose_errors, wrap

_Z3 = (0.0, 0.0, 0.0)
_CHUNK = 16  # poses per scratch allocation in the parallel loop


@nb.njit(**_OPTS)
def _scratch():
    """Work arrays of :func:`_pose` (one set per chunk of poses)."""
    return (np.empty((6, 3)), np.empty((6, 3)), np.empty(3), np.empty(6), np.empty(6),
            np.empty(3), np.empty(64), np.empty(16, dtype=np.complex128))


@nb.njit(**_INLINE)
def _pose(n, D0, D, kinds, mode, jk, rot, cheb_t, fit, ctp, T, tol, wrist_tol, dedup, out_q,
          out_valid, out_pos, out_rot, out_sing, out_sign, out_fam, S):
    """All solutions of pose n; returns the count. ``D0``: the unpacked data
    (:func:`~kinestat.serial.analytic._decoupled_kernels._unpack`) of
    :func:`~kinestat.serial.analytic._decoupled_kernels.pack` with axis rows (5, 6, 1, 2, 3,
    4), points (5, 6, 1, c, c, c), the point c in the wrist slot and the direction across
    axis 4 in the x slot; ``D`` the same with the scratch's axes and points (row 2 and the
    wrist point are the pose's), ``S``: :func:`_scratch`."""
    C, T0inv, W, P, cw, r1, r2, G2, e, u, x4, scale = D0
    clear_wrist(n, out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam)
    Tn = T[n]
    # G = T M⁻¹ and, per pose, axis 1' and the moving point G⁻¹ c
    Rg, tg = _pose_times(Tn, T0inv)
    Wv, Pv, wv, q3s, q, q123, Sr, Cs = S
    w1 = _mtv(Rg, _row(W, 2))
    p1 = _mtv(Rg, _sub(_row(P, 2), tg))
    c = (cw[0], cw[1], cw[2])
    wc = _mtv(Rg, _sub(c, tg))
    for i in range(3):
        Wv[2, i] = w1[i]
        Pv[2, i] = p1[i]
    wv[0], wv[1], wv[2] = wc[0], wc[1], wc[2]
    d1 = _sub(c, (r1[0], r1[1], r1[2]))
    h = _dot(d1, _row(W, 0))
    rho2 = _dot(d1, d1)
    nr = _roots(D, kinds, mode, cheb_t, fit, ctp, c, h, rho2, q3s, Sr, Cs)
    W5, W6, W1h = _row(W, 0), _row(W, 1), _row(W, 2)
    W2, W3, W4 = _row(W, 3), _row(W, 4), _row(W, 5)
    xs = (x4[0], x4[1], x4[2])
    f0 = _start(C[0])
    cnt = 0
    for ir in range(nr):
        y = _move(0, w1, p1, q3s[ir], wc)
        nb2, q2a, q2b, ok2 = _joint2(D, kinds, mode, y, c, h, rho2, 1e-12)
        if not ok2:
            continue
        for ib in range(nb2):
            q2 = q2a if ib == 0 else q2b
            x = _move(0, W6, _row(P, 1), q2, y)
            q123[0] = _sp1(W5, (r1[0], r1[1], r1[2]), x, c)[0]
            q123[1], q123[2] = q2, q3s[ir]
            miss = _polish_position(D, kinds, q123, c, True, 3)
            t5, t6, t1 = q123[0], q123[1], q123[2]
            a1 = (t1, math.cos(t1), math.sin(t1))
            a5 = (t5, math.cos(t5), math.sin(t5))
            a6 = (t6, math.cos(t6), math.sin(t6))
            R1 = _rot(W1h, a1)
            R5 = _rot(W5, a5)
            R6 = _rot(W6, a6)
            f1 = _link(C, 1, a1, f0)
            Rp = _mmt(_mmt(_mtm(R1, Rg), R6), R5)  # R2 R3 R4 = R1ᵀ R_G R6ᵀ R5ᵀ
            ok23, off, sing, wa, wb = spherical_wrist(W2, W3, W4, Rp, xs, tol, wrist_tol)
            if not ok23:
                continue
            near = off < 1e-6
            for i23 in range(2):
                t2, t3, t4, sig = wa if i23 == 0 else wb
                q[0], q[1], q[2], q[3], q[4], q[5] = t1, t2[0], t3[0], t4[0], t5, t6
                if miss > 0.01 * tol or near:
                    _polish_pose(C, jk, Tn, q, 4, 1e-7)
                    pos, err = pose_errors(_fk(C, jk, q), Tn)
                else:  # FK from the angles' cosines and sines (no cos/sin calls)
                    f = _link(C, 6, a6, _link(C, 5, a5, _link(C, 4, t4, _link(C, 3, t3,
                                                                            _link(C, 2, t2, f1)))))
                    pos, err = pose_errors(f, Tn)
                if not (pos <= tol and err <= tol):
                    continue
                cnt = _store(n, q, rot, pos, err, sing, sig, wrap(t2[0] + sig * t4[0]), dedup,
                             out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam,
                             cnt)
    return cnt


@nb.njit(**_OPTS)
def _poses(lo, hi, Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol, dedup, out_q, out_valid,
           out_pos, out_rot, out_sing, out_sign, out_fam, out_cnt):
    """Poses lo .. hi − 1 (one call per chunk: the arrays' reference counts, the unpacking and
    the scratch are paid once per chunk, not per pose)."""
    D0 = _unpack(Kp)
    C, T0inv, W, P, cw, r1, r2, G2, e, u, x4, scale = D0
    S = _scratch()
    Wv, Pv, wv = S[0], S[1], S[2]
    for i in range(6):
        for j in range(3):
            Wv[i, j] = W[i, j]
            Pv[i, j] = P[i, j]
    D = (C, T0inv, Wv, Pv, wv, r1, r2, G2, e, u, x4, scale)
    kinds, mode, jk, rot = ints[0:3], ints[3], ints[4:10], ints[10:16]
    for n in range(lo, hi):
        out_cnt[n] = _pose(n, D0, D, kinds, mode, jk, rot, cheb_t, fit, ctp, T, tol, wrist_tol,
                           dedup, out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam,
                           S)


@nb.njit(parallel=True, **_OPTS)
def solve_batch(Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol, dedup, out_q, out_valid, out_pos,
                out_rot, out_sing, out_sign, out_fam, out_cnt):
    """All solutions of N poses into the (uninitialised) outputs."""
    N = T.shape[0]
    for c in nb.prange((N + _CHUNK - 1) // _CHUNK):
        _poses(c * _CHUNK, min(N, (c + 1) * _CHUNK), Kp, ints, cheb_t, fit, ctp, T, tol,
               wrist_tol, dedup, out_q, out_valid, out_pos, out_rot, out_sing, out_sign, out_fam,
               out_cnt)


@nb.njit(**_OPTS)
def solve_serial(Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol, dedup, out_q, out_valid, out_pos,
                 out_rot, out_sing, out_sign, out_fam, out_cnt):
    """:func:`solve_batch` on one thread."""
    _poses(0, T.shape[0], Kp, ints, cheb_t, fit, ctp, T, tol, wrist_tol, dedup, out_q, out_valid,
           out_pos, out_rot, out_sing, out_sign, out_fam, out_cnt)
