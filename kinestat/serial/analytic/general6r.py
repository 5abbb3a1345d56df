"""Every inverse-kinematics solution of a general 6R chain by the eigenvalue method.

Raghavan & Roth (1993), in the numerically stable form of Manocha & Canny (1994):

1. RR eq. 4 and its 14 invariants give ``P(θ3) R(θ4, θ5) = Q S(θ1, θ2)``
   (:mod:`kinestat.serial.analytic._rr_algebra`; Manocha–Canny eq. 9), with the constant of
   ``S`` moved to the left.
2. θ1, θ2 are eliminated by the left null space of Q (an SVD: 6 equations when rank Q = 8).
3. The half-angle substitution ``xk = tan(φk/2)`` (φk = θk − offset, fixed offsets keep θk = π
   off the pole) and multiplication of the 6 equations by ``x4`` give 12 equations, linear in the
   12 power products ``x4^i x5^j`` (i ≤ 3, j ≤ 2): ``(A2 x3² + A1 x3 + A0) v = 0``
   (Manocha–Canny eq. 13).
4. ``x3`` are the eigenvalues of the 24x24 companion pencil (the standard problem with
   ``A2⁻¹`` when A2 is well conditioned, otherwise the generalised one, ``scipy.linalg.eig``);
   up to 16 are real (the spurious ``x3 = ±i`` of the half-angle factor are not). The
   compiled kernel deflates the 8 spurious ones first (their invariant subspace is known from
   the null space of ``A(i)``; :mod:`kinestat.serial.analytic._rr_deflate`) and solves the
   16x16 quotient, and reruns suspect poses with the QZ eigenvalues
   (:mod:`kinestat.serial.analytic._rr_qz`; ``recheck``).
5. x4, x5 from the eigenvector's power-product ratios; (c1, s1, c2, s2) from the linear
   equations ``Q S = P R`` (least squares); θ6 from the remaining rotation.
6. Newton steps against FK polish each root; a root counts only if FK reproduces the pose
   within ``tol``.
"""

from __future__ import annotations

import math
import sys
import threading
import weakref
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.linalg

from kinestat.errors import InputError, ModelError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic import _rr_algebra as rr
from kinestat.serial.analytic._common import (
    _ENTRY,
    nan_array,
    newton_polish,
    pack,
    reasons,
    run_kernels,
)
from kinestat.serial.analytic.result import IKAllResult
from kinestat.serial.fk import fk

__all__ = ["solve_general_6r", "Formulation", "FORMULATIONS", "formulation", "MAX_SOLUTIONS",
           "OFFSETS", "HINTS", "PRESET", "model_arrays", "search", "single_call"]

MAX_SOLUTIONS = 16
"""A general 6R has at most 16 inverse-kinematics solutions (Lee & Liang 1988; RR 1993)."""

OFFSETS = (0.4170, -1.2137, 0.7751)
"""Shifts (rad) of θ3, θ4, θ5 before the half-angle substitution (any generic values)."""

_COND_MAX = 1e10  # A2 more ill-conditioned than this: generalised eigenproblem


@dataclass(frozen=True)
class Formulation:
    """Which loop the elimination is written on.

    The IK closes the loop ``Z1 Λ1 Z2 Λ2 … Z6 Λ6 = I`` with ``Λi = Ci`` (i ≤ 5) and the pose link
    ``Λ6 = C6 T⁻¹ C0``. Any cyclic shift of it (``shift``) and its inverse (``reverse``: joints
    6…1 with values −q) is the same problem; RR eq. 4 is written on ``Z_J1 M1 … Z_J6 M6 = I``.
    Special geometries (intersecting or parallel axes) can make one formulation's pencil
    singular while another stays regular; :func:`formulation` picks one per model.
    """

    reverse: bool = False
    shift: int = 0

    def joints(self) -> tuple[tuple[int, ...], float]:
        """The joint order J (0-based original indices) and the sign of their values."""
        order = (5, 4, 3, 2, 1, 0) if self.reverse else (0, 1, 2, 3, 4, 5)
        return order[self.shift:] + order[:self.shift], (-1.0 if self.reverse else 1.0)

    def links(self, C: np.ndarray, T: np.ndarray) -> list:
        """The six links ``M1 … M6`` (constant ``(4, 4)`` or per pose ``(N, 4, 4)``)."""
        lam = [C[1], C[2], C[3], C[4], C[5], C[6] @ _inv_rigid(T) @ C[0]]
        if self.reverse:
            lam = [_inv_rigid(m) for m in (lam[4], lam[3], lam[2], lam[1], lam[0], lam[5])]
        return lam[self.shift:] + lam[:self.shift]


FORMULATIONS = tuple(Formulation(r, s) for s in (0, 5, 1, 4, 2, 3) for r in (False, True))
"""Formulations in the order tried (the first two keep the left side pose-independent)."""


def _inv_rigid(T: np.ndarray) -> np.ndarray:
    R = np.swapaxes(T[..., :3, :3], -1, -2)
    out = np.zeros(T.shape)
    out[..., :3, :3] = R
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", R, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


_H3 = np.einsum("ai,bj,ck->abcijk", rr.HALF_ANGLE, rr.HALF_ANGLE,
                rr.HALF_ANGLE).reshape(27, 27)


def check_general(model: ChainModel) -> None:
    """Raise :class:`ModelError` unless the model is six revolute joints."""
    if model.n != 6:
        raise ModelError(f"ik_all: model {model.name!r} has {model.n} joints; exactly 6 needed")
    kinds = [j.kind for j in model.joints]
    if any(k != "revolute" for k in kinds):
        raise ModelError(
            f"ik_all: the general 6R eigenvalue method needs six revolute joints; model "
            f"{model.name!r} has {kinds} (prismatic/screw joints: only closed forms, none "
            f"applies to this geometry)"
        )


def _pencil(M: list, N: int):
    """Per pose: the matrix polynomial ``A (N, 3, 12, 12)``, the reduced left side ``Lt``
    ``(N, 14, 27)``, the SVD of Q (for back-substitution) and the rank-deficient mask."""
    Ts = _inv_rigid(M[5])
    fT = rr.invariants(Ts[..., :3, 3], Ts[..., :3, 2])
    K = rr.right_tensor(M[0])
    Rh = np.einsum("...abij,...j->...iab", K, fT)
    Rh = np.broadcast_to(Rh, (N, 15, 3, 3))[:, 1:].reshape(N, 14, 9)
    L = rr.left_tensor(M[1], M[2], M[3], M[4], np.array(OFFSETS))
    Lt = np.broadcast_to(L[..., 1:, :, :, :], (N, 14, 3, 3, 3)).reshape(N, 14, 27).copy()
    Lt[:, :, 0] -= Rh[:, :, 0]
    Q = Rh[:, :, 1:]
    U, s, Vt = np.linalg.svd(Q, full_matrices=True)
    deficient = s[:, 7] <= 1e-10 * s[:, 0]
    E = np.swapaxes(U[:, :, 8:], 1, 2) @ Lt  # (N, 6, 27)
    Ep = (E @ _H3).reshape(N, 6, 3, 3, 3)  # powers of x3, x4, x5
    A = np.zeros((N, 3, 12, 12))
    blk = np.moveaxis(Ep, 2, 1).reshape(N, 3, 6, 9)
    A[:, :, :6, :9] = blk
    A[:, :, 6:, 3:] = blk
    return A, Lt, (U, s, Vt), deficient


def _eig(A: np.ndarray):
    """Eigenvalues ``(N, 24)`` and eigenvectors ``(N, 24, 24)`` of the pencils, complex."""
    N = A.shape[0]
    A = A / np.max(np.abs(A), axis=(1, 2, 3))[:, None, None, None]
    A0, A1, A2 = A[:, 0], A[:, 1], A[:, 2]
    cond = np.linalg.cond(A2)
    good = np.isfinite(cond) & (cond < _COND_MAX)
    w = np.full((N, 24), np.nan + 0j)
    V = np.zeros((N, 24, 24), dtype=complex)
    I12 = np.eye(12)
    if np.any(good):
        g = np.flatnonzero(good)
        X = np.linalg.solve(A2[g], np.concatenate([A0[g], A1[g]], axis=2))
        M = np.zeros((g.size, 24, 24))
        M[:, :12, 12:] = I12
        M[:, 12:, :12] = -X[:, :, :12]
        M[:, 12:, 12:] = -X[:, :, 12:]
        w[g], V[g] = np.linalg.eig(M)
    for i in np.flatnonzero(~good):
        a = np.zeros((24, 24))
        b = np.eye(24)
        a[:12, 12:] = I12
        a[12:, :12] = -A0[i]
        a[12:, 12:] = -A1[i]
        b[12:, 12:] = A2[i]
        wi, Vi = scipy.linalg.eig(a, b)
        wi = np.where(np.isfinite(wi), wi, np.nan)
        w[i], V[i] = wi, Vi
    return w, V


def _ratio(v: np.ndarray, axis: int) -> np.ndarray:
    """Least-squares ratio x with ``v[.., i+1] = x v[.., i]`` along ``axis`` of v (.., 4, 3)."""
    a = np.moveaxis(v, axis, -1)
    lo, hi = a[..., :-1], a[..., 1:]
    num = np.sum(hi * lo, axis=(-2, -1))
    den = np.sum(lo * lo, axis=(-2, -1))
    return num / np.where(den > 0, den, np.nan)


def _angles_345(w: np.ndarray, V: np.ndarray):
    """θ3, θ4, θ5 ``(N, 24)`` and a realness mask from the eigenpairs."""
    real = np.isfinite(w) & (np.abs(w.imag) <= 1e-6 * (1.0 + np.abs(w)))
    x3 = np.where(real, w.real, 0.0)
    top = np.abs(x3) <= 1.0
    v = np.where(top[:, None, :], V[:, :12, :], V[:, 12:, :])  # (N, 12, 24)
    v = np.moveaxis(v, 1, 2)  # (N, 24, 12)
    k = np.argmax(np.abs(v), axis=-1)
    ph = np.take_along_axis(v, k[..., None], axis=-1)
    v = (v * np.conj(ph) / np.abs(np.where(ph == 0, 1.0, ph))).real.reshape(v.shape[:2] + (4, 3))
    x4 = _ratio(v, 2)
    x5 = _ratio(v, 3)
    ok = real & np.isfinite(x4) & np.isfinite(x5)
    t3 = 2.0 * np.arctan(x3) + OFFSETS[0]
    t4 = 2.0 * np.arctan(np.where(ok, x4, 0.0)) + OFFSETS[1]
    t5 = 2.0 * np.arctan(np.where(ok, x5, 0.0)) + OFFSETS[2]
    return t3, t4, t5, ok


def _monomials(t: np.ndarray) -> np.ndarray:
    return np.stack([np.ones_like(t), np.cos(t), np.sin(t)], axis=-1)


def _angles_12(Lt, svd, t3, t4, t5):
    """θ1, θ2 from ``Q S = Lt m(θ3, θ4, θ5)`` in least squares (Manocha–Canny eq. 9)."""
    U, s, Vt = svd
    m = np.einsum("nka,nkb,nkc->nkabc", _monomials(t3 - OFFSETS[0]), _monomials(t4 - OFFSETS[1]),
                  _monomials(t5 - OFFSETS[2])).reshape(t3.shape + (27,))
    rhs = np.einsum("nij,nkj->nki", Lt, m)  # (N, 24, 14)
    inv_s = np.where(s > 1e-12 * s[:, :1], 1.0 / np.where(s > 0, s, 1.0), 0.0)
    coef = np.einsum("nki,nij->nkj", rhs, U[:, :, :8]) * inv_s[:, None, :]
    S = np.einsum("nkj,nji->nki", coef, Vt)  # (N, 24, 8): (a, b) ≠ (0, 0) of m(θ1) m(θ2)
    t1 = np.arctan2(S[..., 5], S[..., 2])
    t2 = np.arctan2(S[..., 1], S[..., 0])
    return t1, t2


def _theta6(M: list, q5: np.ndarray) -> np.ndarray:
    """θ6 of the loop from ``Z6 = (Z1 M1 … Z5 M5)⁻¹ M6⁻¹``."""
    G = np.broadcast_to(np.eye(4), q5.shape[:-1] + (4, 4)).copy()
    for i in range(5):
        c, s = np.cos(q5[..., i]), np.sin(q5[..., i])
        Z = np.zeros(q5.shape[:-1] + (4, 4))
        Z[..., 0, 0] = c
        Z[..., 0, 1] = -s
        Z[..., 1, 0] = s
        Z[..., 1, 1] = c
        Z[..., 2, 2] = Z[..., 3, 3] = 1.0
        Mi = M[i] if M[i].ndim == 2 else M[i][:, None]
        G = G @ Z @ Mi
    Ts = _inv_rigid(M[5])
    Ts = Ts if Ts.ndim == 2 else Ts[:, None]
    R6 = np.swapaxes(G[..., :3, :3], -1, -2) @ Ts[..., :3, :3]
    return np.arctan2(R6[..., 1, 0] - R6[..., 0, 1], R6[..., 0, 0] + R6[..., 1, 1])


def candidates(model: ChainModel, T: np.ndarray, form: Formulation):
    """Raw candidate solutions ``(N, 24, 6)`` with mask ``(N, 24)`` before polishing."""
    N = T.shape[0]
    M = form.links(np.asarray(model.constants), T)
    A, Lt, svd, deficient = _pencil(M, N)
    w, V = _eig(A)
    t3, t4, t5, ok = _angles_345(w, V)
    t1, t2 = _angles_12(Lt, svd, t3, t4, t5)
    th5 = np.stack([t1, t2, t3, t4, t5], axis=-1)
    th = np.concatenate([th5, _theta6(M, th5)[..., None]], axis=-1)
    order, sign = form.joints()
    q = np.empty_like(th)
    q[..., list(order)] = sign * th
    ok &= np.all(np.isfinite(q), axis=-1) & ~deficient[:, None]
    return q, ok, deficient


def _raw_completeness(model: ChainModel, form: Formulation, n: int = 24,
                      seed: int = 20261201) -> float:
    """Fraction of random configurations (``n``, drawn with ``seed``) found among a
    formulation's polished candidates."""
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(model.lower), model.lower, -math.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, math.pi)
    q0 = rng.uniform(lo, hi, (n, 6))
    # one configuration per FK call: the batch kernel runs on every thread, and on a shared
    # machine a parallel region of a few rows waits milliseconds for a busy core
    res = solve_general_6r(model, np.stack([fk(model, q) for q in q0]), form=form)
    d = np.abs(np.mod(res.q - q0[:, None, :] + math.pi, 2 * math.pi) - math.pi).max(-1)
    return float(np.mean(np.any(np.where(res.valid, d, np.inf) < 1e-6, axis=1)))


#: a formulation found for a model of the same kind (a locked arm's chain folded at another
#: value of the same joint): model -> Formulation, taken when it finds every one of
#: ``_HINT_CHECKS`` random configurations (else the search runs as for any model)
HINTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_HINT_CHECKS = 12

#: models whose kernel arrays are known for a formulation (a locked arm's chain folded at a
#: value, :mod:`kinestat.serial.analytic.locked_general`): model -> (Formulation, the tuple of
#: :func:`model_arrays`, trusted); a trusted formulation is taken without a search or a check
PRESET: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@lru_cache(maxsize=32)
def formulation(model: ChainModel) -> tuple[Formulation, float]:
    """The first formulation (of :data:`FORMULATIONS`) that finds every one of 24 random
    configurations of ``model``, or the best one with its completeness fraction (a
    :data:`HINTS` formulation first, checked on fewer)."""
    check_general(model)
    preset = PRESET.get(model)
    if preset is not None and preset[2]:
        return preset[0], 1.0
    hint = HINTS.get(model)
    if hint is not None and _raw_completeness(model, hint, _HINT_CHECKS) == 1.0:
        return hint, 1.0
    return search(model)


def search(model: ChainModel) -> tuple[Formulation, float]:
    """:func:`formulation` without a hint (not cached)."""
    best = (FORMULATIONS[0], -1.0)
    for form in FORMULATIONS:
        frac = _raw_completeness(model, form)
        if frac == 1.0:
            return form, frac
        if frac > best[1]:
            best = (form, frac)
    return best


def _solve(model, T, form, tol, polish_iters) -> IKAllResult:
    q, ok, deficient = candidates(model, T, form)
    N, C, n = q.shape
    flat = np.flatnonzero(ok.ravel())
    Tc = np.repeat(T, C, axis=0)[flat]
    qf = q.reshape(-1, n)
    qf[flat] = newton_polish(model, qf[flat], Tc, polish_iters)
    res = pack(model, qf.reshape(N, C, n), ok, T, MAX_SOLUTIONS, tol=tol,
               method=_method_name(form), reason_none=_REASON_NONE)
    if np.any(deficient):
        r = res.reason.copy()
        r[deficient & (res.n_solutions == 0)] = _REASON_DEFICIENT
        object.__setattr__(res, "reason", r)
    return res


_PARALLEL_MIN = 32  # smaller batches run on one thread

_REASON_NONE = ("no real solution: the pose is outside the workspace (no real root of the "
                "Raghavan–Roth eigenproblem reproduces it)")
_REASON_DEFICIENT = ("degenerate elimination: the θ1-θ2 coefficient matrix Q of Raghavan–Roth "
                     "eq. 9 is rank deficient for this pose")


def model_arrays(model: ChainModel, form: Formulation) -> tuple:
    """:func:`_compiled_data` without the spurious subspace's basis: ``(C, consts, links, LH,
    h0, L, off, order, sign)``."""
    C = np.ascontiguousarray(model.constants)
    M = form.links(C, np.eye(4)[None])
    M = [m[0] if m.ndim == 3 else m for m in M]
    L = rr.left_tensor(M[1], M[2], M[3], M[4], np.array(OFFSETS))[1:].reshape(14, 27)
    order, sign = form.joints()
    # the pose link is C6 T⁻¹ C0 (= G⁻¹) forwards and its inverse G when reversed
    at0 = 0 if form.shift == 0 else (2 if not form.reverse else 1)
    at5 = 0 if form.shift == 5 else (1 if not form.reverse else 2)
    consts = np.stack([_inv_rigid(C[0]), _inv_rigid(C[6]), M[0], _inv_rigid(M[5])])
    LH = np.ascontiguousarray(L @ _H3)
    return (C, np.ascontiguousarray(consts), np.ascontiguousarray(np.stack(M[1:5])), LH,
            np.ascontiguousarray(_H3[0]), np.ascontiguousarray(L), np.array(OFFSETS),
            np.array(list(order) + [at0, at5], dtype=np.int64), float(sign))


@lru_cache(maxsize=64)
def _compiled_data(model: ChainModel, form: Formulation):
    """Pose-independent arguments of the compiled kernel (formulations with shift 0 or 5,
    whose pose link is M1 or M6): ``form (4, 4, 4)`` = C0⁻¹, C6⁻¹, constant M1, constant Ts;
    the constant links M2..M5; ``L H3``, ``H3[0]``, L; the joint order with the pose-link
    codes of M1 and Ts appended (0 constant, 1 ``C0⁻¹ T C6⁻¹``, 2 its inverse); the basis of
    the companion's spurious subspace (:func:`kinestat.serial.analytic._rr_deflate.
    model_basis`: pose-independent)."""
    from kinestat.serial.analytic._rr_deflate import model_basis  # lazy: Numba start-up

    preset = PRESET.get(model)
    arrays = preset[1] if preset is not None and preset[0] == form else model_arrays(model, form)
    return arrays + model_basis(arrays[3])


RECHECK = {"never": 0, "suspect": 1, "always": 2}
"""When the compiled kernel recovers a pose's roots again from the QZ eigenvalues
(:mod:`kinestat.serial.analytic._rr_qz`; they replace the companion's): never, on poses its
first pass marks as suspect (the default), always. Where the companion is unusable (its
leading coefficient singular for every Möbius parameter) QZ is the only pass in every mode."""


def run_kernel(model, T, form, tol, polish_iters, recheck="suspect"):
    """The compiled kernel on poses ``T (N, 4, 4)``: ``q (N, 16, 6)``, valid, position and
    rotation errors, the per-pose flags, the numbers of solutions and ``stats (N, 7)``: real
    eigenvalues tried and lost
    by the first pass, its nearest-real complex eigenvalue ``|Im x| / (1 + |x|)``, its count,
    1.0 where the QZ pass ran, the smallest relative pivot of the companion's leading
    coefficient (0 where it was unusable), the first pass's largest real-eigenvalue error."""
    K = sys.modules.get("kinestat.serial.analytic._rr_kernels")
    if K is None:
        from kinestat.serial.analytic import _rr_kernels as K  # lazy: Numba start-up

    C, consts, links, LH, h0, L, off, order, sign, basis, index = _compiled_data(model, form)
    N = T.shape[0]
    K16 = MAX_SOLUTIONS
    q = np.empty((N, K16, 6))  # every pose's slots are cleared by the kernel
    valid = np.empty((N, K16), dtype=bool)
    pos = np.empty((N, K16))
    rot = np.empty((N, K16))
    flags = np.zeros(N, dtype=np.int64)
    counts = np.zeros(N, dtype=np.int64)
    stats = np.zeros((N, 7))
    args = (C, T, consts, links, LH, h0, L, off, order, sign, basis, index, float(tol),
            int(polish_iters), 1e-6, RECHECK[recheck], q, valid, pos, rot, flags, counts, stats)
    run_kernels(K.solve_batch, K.solve_serial, args, T, _PARALLEL_MIN)
    return q, valid, pos, rot, flags, counts, stats


def _solve_compiled(model, T, form, tol, polish_iters, recheck="suspect",
                    shape=None) -> IKAllResult:
    K = sys.modules.get("kinestat.serial.analytic._rr_kernels")
    if K is None:
        from kinestat.serial.analytic import _rr_kernels as K  # lazy: Numba start-up

    q, valid, pos, rot, flags, nsol, _ = run_kernel(model, T, form, tol, polish_iters, recheck)
    N, K16 = valid.shape
    # result building (NumPy's per-call costs matter in a single call, so one pose takes the
    # scalar route and the result is built once, in its final shape)
    flagged = flags[0] != K.FLAG_OK if N == 1 else flags.any()
    reason = reasons(nsol, _REASON_NONE)
    if flagged:
        reason[(flags == K.FLAG_DEFICIENT) & (nsol == 0)] = _REASON_DEFICIENT
        redo = np.flatnonzero(flags == K.FLAG_ILL_CONDITIONED)
        if redo.size:  # dggev failed in the kernel: the NumPy reference for these poses
            sub = _solve(model, T[redo], form, tol, polish_iters)
            q[redo], valid[redo], pos[redo], rot[redo] = (sub.q, sub.valid, sub.position_error,
                                                          sub.rotation_error)
            nsol[redo], reason[redo] = sub.n_solutions, sub.reason
    if shape == ():
        return IKAllResult.build_one(q, valid, pos, rot, np.zeros((1, K16), dtype=bool),
                                     np.zeros((1, K16)), nan_array((1, K16)), None, nsol,
                                     reason[0], _method_name(form), tol)
    return IKAllResult.build((N,) if shape is None else shape, q=q, valid=valid,
                             position_error=pos, rotation_error=rot,
                             singular=np.zeros((N, K16), dtype=bool),
                             family_sign=np.zeros((N, K16)), family_value=nan_array((N, K16)),
                             family_joints=None, n_solutions=nsol, reason=reason,
                             method=_method_name(form), tol=tol)


def bind_one(model: ChainModel, check_entry, put=None):
    """The single-pose call of the compiled kernel for ``model`` with its default formulation,
    recheck and polishing (``ik_all``'s fast path): ``one(T (1, 4, 4) plain, tol: float)``,
    the result of :func:`solve_general_6r` with ``shape=()``, or None where that call must run
    instead (a pose not orthonormal to rounding, a flagged pose, no compiled entry yet).
    ``check_entry``: the compiled entry of the closed forms' ``check_rigid``. The per-model
    arguments and entry points are bound once: a few µs of a single call are Python steps.
    ``put``: ``(entry, take, j, v)``, a locked arm's step that puts the joints back
    (:func:`kinestat.serial.analytic._locked_kernels.joints_out`: ``q`` then holds the full
    chain's ``take.shape[0]`` joints, joint ``j`` at ``v``), run in the same call."""
    form, _ = formulation(model)
    if form.shift not in (0, 5):
        return None
    run = single_call(check_entry, form, None if put is None else put[:3])
    if run is None:
        return None
    args = _compiled_data(model, form)
    v = 0.0 if put is None else put[3]

    def one(T, tol):
        return run(T, tol, args, v)
    return one


def single_call(check_entry, form: Formulation, put=None):
    """:func:`bind_one`'s call with the pose-independent arguments given per call:
    ``run(T (1, 4, 4) plain, tol, args, v)``, ``args`` the tuple of :func:`_compiled_data`
    (of any model solved by ``form``: a locked arm's chain at each value of the joint), ``v``
    the locked value ``put = (entry, take, j)`` puts back (unused without ``put``); None
    while the compiled entry points are not recorded."""
    K = sys.modules.get("kinestat.serial.analytic._rr_kernels")
    entry = _ENTRY.get((K.solve_serial, None)) if K is not None else None
    if entry is None or check_entry is None:
        return None
    K16 = MAX_SOLUTIONS
    shape = (1, K16)
    # no singular families here: the same read-only arrays serve every result
    singular, family_sign, family_value = np.zeros(shape, dtype=bool), np.zeros(shape), \
        nan_array(shape)
    for a in (singular, family_sign, family_value):
        a.flags.writeable = False
    put_entry, take, j = (None, None, 0) if put is None else put
    method = _method_name(form)
    shape_q = (K16, 6 if put is None else take.shape[0])
    local = threading.local()
    singular, family_sign, family_value = singular[0], family_sign[0], family_value[0]
    single = IKAllResult.single

    def run(T, tol, args, v):
        bad, n_project = check_entry(T, 1e-6)
        if bad >= 0 or n_project:
            return None
        C, consts, links, LH, h0, L, off, order, sign, basis, index = args
        q = np.empty((1, K16, 6))  # the kernel clears the slots and sets flags, nsol
        valid = np.empty(shape, dtype=bool)
        pos = np.empty(shape)
        rot = np.empty(shape)
        work = getattr(local, "work", None)  # flags, nsol, stats: read here, kept per thread
        if work is None:
            work = local.work = (np.empty(1, dtype=np.int64), np.empty(1, dtype=np.int64),
                                 np.empty((1, 7)))
        flags, nsol, stats = work
        entry(C, T, consts, links, LH, h0, L, off, order, sign, basis, index, tol, 8, 1e-6, 1, q,
              valid, pos, rot, flags, nsol, stats)
        if flags[0] != 0:
            return None
        c = nsol[0]
        if put_entry is not None:
            qn = np.empty(shape_q)
            put_entry(q[0], take, j, v, qn)
            return single(qn, valid[0], pos[0], rot[0], singular, family_sign, family_value,
                          None, c, "" if c else _REASON_NONE, method, tol)
        return single(q[0], valid[0], pos[0], rot[0], singular, family_sign, family_value,
                      None, c, "" if c else _REASON_NONE, method, tol)
    return run


def _method_name(form: Formulation) -> str:
    return f"raghavan-roth{'-reversed' if form.reverse else ''}-shift{form.shift}"


def solve_general_6r(model: ChainModel, T: np.ndarray, *, tol: float = 1e-9,
                     polish_iters: int = 8, form: Formulation | None = None,
                     backend: str = "numba", recheck: str = "suspect",
                     shape: tuple[int, ...] | None = None) -> IKAllResult:
    """All IK solutions of a 6R ``model`` for poses ``T (N, 4, 4)`` (Raghavan–Roth 1993).

    Returns an :class:`IKAllResult` with ``K = 16`` slots. ``form`` defaults to the model's
    :func:`formulation`; ``backend`` ``"numba"`` (compiled kernel, for formulations with shift
    0 or 5) or ``"numpy"`` (the reference). ``recheck`` (compiled kernel): when the roots are
    recovered from the QZ eigenvalues instead of the companion's, :data:`RECHECK`. ``shape``:
    the batch shape of a compiled result (default ``(N,)``; the NumPy reference always returns
    ``(N,)``).
    """
    check_general(model)
    if recheck not in RECHECK:
        raise InputError(f"solve_general_6r: recheck={recheck!r}; one of {sorted(RECHECK)}")
    if form is None:
        form, _ = formulation(model)
    if backend == "numba" and form.shift in (0, 5):
        return _solve_compiled(model, np.ascontiguousarray(T), form, tol, polish_iters, recheck,
                               shape)
    return _solve(model, T, form, tol, polish_iters)
