"""Closed-form inverse kinematics by Paden–Kahan subproblems, batched over poses.

Product-of-exponentials form ``g = T T(0)⁻¹ = e^{ξ̂1θ1} ⋯ e^{ξ̂6θ6}`` (MLS §3.3) with the axes of
:func:`kinestat.serial.analytic.geometry.home_axes`. Two geometries:

- :func:`solve_pieper`: spherical wrist (axes 4, 5, 6 meet at w) and axes 1, 2 meeting at s.
  ``|g w − s| = |e^{ξ̂3θ3} w − s|`` (subproblem 3: θ3), ``e^{ξ̂1θ1} e^{ξ̂2θ2} (e^{ξ̂3θ3} w) = g w``
  (subproblem 2: θ1, θ2), ``R4 R5 ω6 = R' ω6`` (subproblem 2: θ4, θ5), θ6 (subproblem 1).
  Up to 8 solutions; where ω6 lines up with ω4 (|sin| of their angle < ``wrist_tol``) the branch
  is the one-parameter family ``θ4 + σ θ6 = const``.
- :func:`solve_three_parallel`: axes 2, 3, 4 parallel to h and axes 5, 6 meeting at p (UR-type).
  ``hᵀ e^{−ξ̂1θ1} g p = hᵀ p`` (subproblem 4: θ1), ``hᵀ R5 ω6 = hᵀ R1ᵀ Rg ω6`` (subproblem 4:
  θ5), θ6 and ``φ = Σ θ2..4`` (subproblem 1), θ3 (subproblem 3) and θ2 (subproblem 1) from a
  point on axis 4. Up to 8 solutions; the wrist-singular set (axis 6 parallel to h) is left
  out (no slot), as its family couples four joints.
"""

from __future__ import annotations

import math
import sys
import threading

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic import _offset_pack
from kinestat.serial.analytic._common import (
    _ENTRY,
    call_compiled,
    nan_array,
    pack,
    plain_poses,
    reasons,
)
from kinestat.serial.analytic.geometry import cross3, norm3
from kinestat.serial.analytic.result import IKAllResult
from kinestat.serial.analytic.subproblems import rotate, rotation_matrix, sp1, sp2, sp3, sp4

__all__ = ["solve_pieper", "solve_three_parallel", "solve_pieper_compiled",
           "solve_three_parallel_compiled", "pieper_parts"]

_WRIST_TOL = 1e-10
_PARALLEL_MIN = 256  # smaller batches run on one thread (a pose costs a few µs)
_NEWTON_STEPS = 2  # for a candidate that misses tol (rounding next to a singular set)


def _apply(T: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("...ij,...j->...i", T[..., :3, :3], x) + T[..., :3, 3]


def _mv(R: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("...ij,...j->...i", R, x)


def _perp(w: np.ndarray) -> np.ndarray:
    e = np.eye(3)[int(np.argmin(np.abs(w)))]
    x = cross3(w, e)
    return x / norm3(x)


def _wrap(a):
    return np.mod(a + math.pi, 2.0 * math.pi) - math.pi


def _wrist(W, Rp: np.ndarray, wrist_tol: float):
    """θ4, θ5, θ6 (``(..., 2)`` each), existence, singular mask and family sign/value for
    ``R4 R5 R6 = R'`` with axes 4, 5, 6 meeting (directions ``W[3:6]``)."""
    z = np.zeros(3)
    target = _mv(Rp, W[5])  # R' ω6
    t4, t5, ex = sp2(W[3], W[4], z, W[5], target)
    sing = np.linalg.norm(np.cross(W[3], target), axis=-1) < wrist_tol
    # on the singular set θ4 is free: take θ4 = 0 and align ω6 by θ5 alone
    t5s, _, _ = sp1(W[4], z, W[5], target)
    t4 = np.where(sing[..., None], 0.0, t4)
    t5 = np.where(sing[..., None], t5s[..., None], t5)
    ex = ex | sing
    R45 = rotation_matrix(W[3], t4) @ rotation_matrix(W[4], t5)
    x = _perp(W[5])
    t6, _, _ = sp1(W[5], z, x, _mv(np.swapaxes(R45, -1, -2), _mv(Rp, x)[..., None, :]))
    sig = np.sign(np.sum(W[3] * _mv(rotation_matrix(W[4], t5), W[5]), axis=-1))
    fam = _wrap(t4 + sig * t6)
    return t4, t5, t6, ex, sing, sig, fam


def solve_pieper(model: ChainModel, T: np.ndarray, data: dict, *, tol: float = 1e-9,
                 wrist_tol: float = _WRIST_TOL) -> IKAllResult:
    """All solutions (8 slots) for a spherical-wrist arm whose axes 1, 2 meet; ``T (N, 4, 4)``
    (an offset shoulder: :func:`kinestat.serial.analytic.pieper_offset.solve_pieper_offset`)."""
    ax, w, s = data["axes"], data["wrist"], data["shoulder"]
    W, P = ax.w, ax.r
    N = T.shape[0]
    g = T @ np.linalg.inv(ax.T0)
    pw = _apply(g, w)  # (N, 3)
    t3, e3 = sp3(W[2], P[2], w, s, np.linalg.norm(pw - s, axis=-1))  # (N, 2)
    w3 = rotate(W[2], P[2], t3, w)  # (N, 2, 3)
    t1, t2, e12 = sp2(W[0], W[1], s, w3, pw[:, None, :])  # (N, 2, 2)
    t3 = np.broadcast_to(t3[..., None], t1.shape)
    R123 = rotation_matrix(W[0], t1) @ rotation_matrix(W[1], t2) @ rotation_matrix(W[2], t3)
    Rp = np.swapaxes(R123, -1, -2) @ g[:, None, None, :3, :3]  # (N, 2, 2, 3, 3)
    t4, t5, t6, e45, sing, sig, fam = _wrist(W, Rp, wrist_tol)
    sh = (N, 2, 2, 2)
    q = np.stack([np.broadcast_to(a[..., None], sh) for a in (t1, t2, t3)]
                 + [t4, t5, t6], axis=-1).reshape(N, 8, 6)
    ok = np.broadcast_to(e3[:, None, None, None] & e12[..., None, None] & e45[..., None],
                         sh).reshape(N, 8)
    return pack(model, q, ok, T, 8, tol=tol, method="pieper",
                reason_none="no real solution: the wrist centre is out of reach of the arm "
                            "(subproblem 3 or 2 of the shoulder has no real root)",
                singular=np.broadcast_to(sing[..., None], sh).reshape(N, 8),
                family_sign=np.broadcast_to(sig, sh).reshape(N, 8),
                family_value=np.broadcast_to(fam, sh).reshape(N, 8), family_joints=(3, 5))


def solve_three_parallel(model: ChainModel, T: np.ndarray, data: dict, *, tol: float = 1e-9,
                         wrist_tol: float = _WRIST_TOL) -> IKAllResult:
    """All solutions (8 slots) for axes 2 ∥ 3 ∥ 4 with axes 5, 6 meeting (UR-type)."""
    ax, p = data["axes"], data["p56"]
    W, P = ax.w, ax.r
    N = T.shape[0]
    h = W[1]
    sg = np.array([float(np.sign(W[i] @ h)) for i in (1, 2, 3)])
    g = T @ np.linalg.inv(ax.T0)
    Rg = g[:, :3, :3]
    q56 = _apply(g, p)
    psi, e1 = sp4(h, W[0], q56 - P[0], float(h @ (p - P[0])))  # ψ = −θ1, (N, 2)
    t1 = -psi
    Rr = rotation_matrix(W[0], psi) @ Rg[:, None]  # R1ᵀ Rg, (N, 2, 3, 3)
    t5, e5 = sp4(h, W[4], W[5], np.einsum("i,...ij,j->...", h, Rr, W[5]))  # (N, 2, 2)
    Rr2 = np.broadcast_to(Rr[:, :, None], (N, 2, 2, 3, 3))
    hr = np.einsum("...ji,j->...i", Rr2, h)  # Rrᵀ h
    R5 = rotation_matrix(W[4], t5)
    t6, e6, free6 = sp1(W[5], np.zeros(3), hr, np.einsum("...ji,j->...i", R5, h))
    sing = free6 | (np.linalg.norm(np.cross(hr, W[5]), axis=-1) < wrist_tol)
    R6 = rotation_matrix(W[5], t6)
    R234 = Rr2 @ np.swapaxes(R5 @ R6, -1, -2)
    x = _perp(h)
    phi, _, _ = sp1(h, np.zeros(3), x, _mv(R234, x))
    # the point r4 on axis 4 carried by e^{ξ̂2θ2} e^{ξ̂3θ3} e^{ξ̂4θ4} = e^{−ξ̂1θ1} g e^{−ξ̂6θ6} e^{−ξ̂5θ5}
    y = rotate(W[5], P[5], -t6, rotate(W[4], P[4], -t5, P[3]))
    y = _apply(g[:, None, None], y)
    y = rotate(W[0], P[0], np.broadcast_to(psi[:, :, None], t5.shape), y)
    t3, e3 = sp3(W[2], P[2], P[3], P[1], np.linalg.norm(y - P[1], axis=-1))  # (N, 2, 2, 2)
    y3 = rotate(W[2], P[2], t3, P[3])
    t2, _, _ = sp1(W[1], P[1], y3, y[..., None, :])
    ph = phi[..., None]
    t4 = sg[2] * (ph - sg[0] * t2 - sg[1] * t3)
    sh = (N, 2, 2, 2)
    q = np.stack([np.broadcast_to(t1[:, :, None, None], sh), t2, t3, t4,
                  np.broadcast_to(t5[..., None], sh), np.broadcast_to(t6[..., None], sh)],
                 axis=-1).reshape(N, 8, 6)
    ok = np.broadcast_to(e1[:, None, None, None] & e5[..., None, None]
                         & (e6 & ~sing)[..., None] & e3[..., None], sh).reshape(N, 8)
    return pack(model, q, ok, T, 8, tol=tol, method="three-parallel",
                reason_none="no real solution: the pose is out of reach (subproblem 4 for θ1 or "
                            "θ5, or subproblem 3 for θ3, has no real root), or the wrist is "
                            "singular (axis 6 parallel to axes 2-4)")


_REASON_PIEPER = ("no real solution: the wrist centre is out of reach of the arm (subproblem 3 "
                  "or 2 of the shoulder has no real root)")
_REASON_3P = ("no real solution: the pose is out of reach (subproblem 4 for θ1 or θ5, or "
              "subproblem 3 for θ3, has no real root), or the wrist is singular (axis 6 parallel "
              "to axes 2-4)")


def _outputs(N: int, K: int):
    """Uninitialised outputs ``q (N, K, 6)``, ``valid``, ``pos``, ``rot`` and the counts ``(N,)``
    (the kernels clear every pose's slots first)."""
    return (np.empty((N, K, 6)), np.empty((N, K), dtype=bool), np.empty((N, K)),
            np.empty((N, K)), np.empty(N, dtype=np.int64))


def _bind_single(kernel, Kp: np.ndarray, wrist_tol: float, reason: str, method: str,
                 family_joints):
    """The single-pose call of a closed form: ``one(T (1, 4, 4) plain, tol: float)``, the
    result of :func:`solve_pieper_compiled` (or :func:`solve_three_parallel_compiled`) with
    ``shape=()``, ``checked=False``, or None as it (the caller then takes the full path).
    ``kernel``: a single-pose kernel (:mod:`kinestat.serial.analytic._cf_single`), called
    through its compiled entry point once its first call has recorded it (see
    :func:`~kinestat.serial.analytic._common.call_compiled`). The per-model arguments are bound
    once and the outputs made in the result's shapes: a single call is a few µs, so its
    Python steps matter."""
    entry = _ENTRY.get((kernel, None))
    single = IKAllResult.single
    empty = np.empty

    def one(T, tol):
        nonlocal entry
        q, valid, pos, rot = empty(_S86), empty(8, dtype=bool), empty(8), empty(8)
        sing, sign, fam = empty(8, dtype=bool), empty(8), empty(8)
        if entry is not None:
            c = entry(Kp, T, tol, wrist_tol, q, valid, pos, rot, sing, sign, fam)
        else:
            c = call_compiled(kernel, Kp, T, tol, wrist_tol, q, valid, pos, rot, sing, sign, fam)
            entry = _ENTRY.get((kernel, None))
        if c < 0:
            return None
        return single(q, valid, pos, rot, sing, sign, fam, family_joints, c,
                      "" if c else reason, method, tol)
    return one


_S86 = (8, 6)


def angles_from_pairs(c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The angles in [-π, π) of the cosines ``c`` and sines ``s`` a batch kernel stored (NaN
    stays NaN), written over ``c``: one vectorised ``arctan2`` pass (NumPy's SIMD loop, within
    an ulp of libm) in place of a libm call per angle in the kernel."""
    np.arctan2(s, c, out=c)
    np.subtract(c, 2.0 * math.pi, out=c, where=c >= math.pi)
    return c


#: poses per batch-kernel call: the sines of their slots (1.5 MB) are scratch kept per thread,
#: so that a batch allocates no more than its outputs (a fresh scratch per call made the C
#: library hand memory back and forth to the system: page faults costing ~0.4 µs a pose)
_CHUNK = 4096
_SCRATCH = threading.local()


def _run_batch(batch, Kp, T: np.ndarray, tol: float, wrist_tol: float, newton, q: np.ndarray,
               outs: tuple) -> None:
    """The parallel kernel ``batch`` on the poses ``T``, in chunks of :data:`_CHUNK`: the
    cosines into ``q``, the sines into this thread's scratch, then the angles
    (:func:`angles_from_pairs`); ``outs``: the other outputs (leading axis N)."""
    s = getattr(_SCRATCH, "sines", None)
    if s is None:
        s = _SCRATCH.sines = np.empty((_CHUNK, 8, 6))
    N = T.shape[0]
    for a in range(0, N, _CHUNK):
        b = min(a + _CHUNK, N)
        sa = s[:b - a]
        batch(Kp, T[a:b], tol, wrist_tol, 1e-6, newton, q[a:b], sa,
              *(o[a:b] for o in outs))
        angles_from_pairs(q[a:b], sa)


def _run_serial(serial, args: tuple, T: np.ndarray, plain: bool | None, newton) -> None:
    """A serial kernel on ``args``, through :func:`~kinestat.serial.analytic._common.
    call_compiled` (variant ``newton``) when the poses ``T`` are plain."""
    if plain_poses(T) if plain is None else plain:
        call_compiled(serial, *args, variant=newton)
    else:
        serial(*args)


def _newton(N: int, checked: bool) -> int | None:
    """The kernels' Newton steps for a candidate that misses tol: none (the pose is handed
    back) on a few unchecked poses, else two."""
    return None if not checked and N < _PARALLEL_MIN else _NEWTON_STEPS


def _unchecked(cnt: np.ndarray) -> bool:
    """Some pose's count is negative: the kernel found it not orthonormal to rounding, or
    handed it back for Newton steps."""
    return cnt[0] < 0 if cnt.shape[0] == 1 else cnt.shape[0] > 1 and cnt.min() < 0


def _cf_kernels():
    K = sys.modules.get("kinestat.serial.analytic._cf_kernels")
    if K is None:
        from kinestat.serial.analytic import _cf_kernels as K  # lazy: Numba start-up
    return K


def _cf_single():
    K = sys.modules.get("kinestat.serial.analytic._cf_single")
    if K is None:
        from kinestat.serial.analytic import _cf_single as K  # lazy: Numba start-up
    return K


def _offset_kernels():
    K = sys.modules.get("kinestat.serial.analytic._offset_kernels")
    if K is None:
        from kinestat.serial.analytic import _offset_kernels as K  # lazy: Numba start-up
    return K


def _batch_kernels(offset: bool):
    """The module of the batch kernels (offset shoulder or not), imported on first use: a
    single call sets none of them up."""
    if offset:
        from kinestat.serial.analytic import _offset_batch as B  # lazy: batches only
    else:
        from kinestat.serial.analytic import _cf_batch as B  # lazy: batches only
    return B


def _pieper_args(model: ChainModel, data: dict, K) -> np.ndarray:
    """The spherical-wrist kernel's packed pose-independent data (``K``: its kernel module),
    kept with the model's cached geometry."""
    Kp = data.get("kernel_args")
    if Kp is None:
        ax = data["axes"]
        x6 = data.get("x6")  # a unit vector normal to axis 6 (a caller's, or any)
        x6 = _perp(ax.w[5]) if x6 is None else x6
        Kp = data["kernel_args"] = _offset_pack.pack(
            model, ax, data["wrist"], x6) if data["shoulder"] is None else K.pack(
            model.constants, np.linalg.inv(ax.T0), ax.w, ax.r, data["wrist"], data["shoulder"],
            x6)
    return Kp


def pieper_parts(model: ChainModel, data: dict, wrist_tol: float = _WRIST_TOL):
    """``(entry, packed data, wrist_tol, reason)``: what a caller that maps the pose and the
    joints around the spherical-wrist kernel's single call needs (a pieper ``model`` and its
    ``data`` from :func:`~kinestat.serial.analytic.geometry.classify`; ``entry``: the compiled
    entry of its :mod:`~kinestat.serial.analytic._cf_single` kernel), or None while that entry
    point is not recorded (no single call of its kind has run yet)."""
    parts = data.get("one_parts")
    if parts is not None:
        return parts
    offset = data["shoulder"] is None
    K = _offset_kernels() if offset else _cf_kernels()
    entry = _ENTRY.get((_single_kernel(offset), None))
    if entry is None:
        return None
    parts = data["one_parts"] = (entry, _pieper_args(model, data, K), float(wrist_tol),
                                 _offset_pack.REASON if offset else _REASON_PIEPER)
    return parts


def _single_kernel(offset: bool):
    """The spherical-wrist single-pose kernel (offset shoulder or not)."""
    if offset:
        return _offset_kernels().offset_one
    return _cf_single().pieper_one


def _single(data: dict, kernel, Kp, reason: str, method: str, family_joints, T: np.ndarray,
            tol: float):
    """One plain pose, unchecked: the model's bound single call (bound here on first use)."""
    one = data.get("one")
    if one is None:
        one = data["one"] = _bind_single(kernel, Kp, _WRIST_TOL, reason, method, family_joints)
    return one(T, float(tol))


def solve_pieper_compiled(model: ChainModel, T: np.ndarray, data: dict, *, tol: float = 1e-9,
                          wrist_tol: float = _WRIST_TOL, shape: tuple[int, ...] | None = None,
                          plain: bool | None = None, checked: bool = True) -> IKAllResult | None:
    """:func:`solve_pieper` by the compiled kernel (same slots, valid ones first); ``shape``:
    the batch shape of the result (default ``(N,)``); ``plain``: the caller has checked
    :func:`~kinestat.serial.analytic._common.plain_poses` (None: check here).
    ``checked=False``: the caller has not checked the poses, the kernel does, and with fewer
    than ``_PARALLEL_MIN`` poses it runs without Newton steps (a kernel with less code to load);
    the result is then None when some pose is not a rigid transform orthonormal to rounding or
    one of its candidates needs Newton steps: the caller checks the poses, projects them and
    calls again, checked."""
    offset = data["shoulder"] is None
    K = _offset_kernels() if offset else _cf_kernels()
    N = T.shape[0]
    if shape == () and N == 1 and not checked and wrist_tol == _WRIST_TOL and \
            (plain_poses(T) if plain is None else plain):
        return _single(data, _single_kernel(offset), _pieper_args(model, data, K),
                       _offset_pack.REASON if offset else _REASON_PIEPER, "pieper", (3, 5), T,
                       tol)
    q, valid, pos, rot, cnt = _outputs(N, 8)
    sing = np.empty((N, 8), dtype=bool)
    sign = np.empty((N, 8))
    fam = np.empty((N, 8))
    Kp = _pieper_args(model, data, K)
    newton = _newton(N, checked)
    B = _batch_kernels(offset)
    serial = B.offset_serial if offset else B.pieper_serial
    if N >= _PARALLEL_MIN:  # over the cores, the angles by one arctan2 pass after the kernel
        _run_batch(B.offset_batch if offset else B.pieper_batch, Kp, T, float(tol),
                   float(wrist_tol), newton, q, (valid, pos, rot, sing, sign, fam, cnt))
    else:
        _run_serial(serial, (Kp, T, float(tol), float(wrist_tol), 1e-6, newton, q, valid, pos,
                             rot, sing, sign, fam, cnt), T, plain, newton)
    reason = _offset_pack.REASON if offset else _REASON_PIEPER
    if _unchecked(cnt):
        return None
    if shape == ():
        return IKAllResult.build_one(q, valid, pos, rot, sing, sign, fam, (3, 5), cnt,
                                     reason if cnt[0] == 0 else "", "pieper", tol)
    return IKAllResult.build((N,) if shape is None else shape, q=q, valid=valid,
                             position_error=pos, rotation_error=rot, singular=sing,
                             family_sign=sign, family_value=fam, family_joints=(3, 5),
                             n_solutions=cnt,
                             reason=reasons(cnt, reason), method="pieper", tol=tol)


def solve_three_parallel_compiled(model: ChainModel, T: np.ndarray, data: dict, *,
                                  tol: float = 1e-9, wrist_tol: float = _WRIST_TOL,
                                  shape: tuple[int, ...] | None = None,
                                  plain: bool | None = None,
                                  checked: bool = True) -> IKAllResult | None:
    """:func:`solve_three_parallel` by the compiled kernel, with the wrist-singular families
    (:func:`kinestat.serial.analytic.families.add_wrist_families`) added; ``shape``, ``plain``
    as for :func:`solve_pieper_compiled`, as is the None return."""
    K = _cf_kernels()
    N = T.shape[0]
    Kp = data.get("kernel_args")
    if Kp is None:
        ax = data["axes"]
        h = ax.w[1]
        sg = np.array([float(np.sign(ax.w[i] @ h)) for i in (1, 2, 3)])
        Kp = data["kernel_args"] = K.pack(model.constants, np.linalg.inv(ax.T0), ax.w, ax.r,
                                          data["p56"], _perp(h), sg)
    if shape == () and N == 1 and not checked and wrist_tol == _WRIST_TOL and \
            (plain_poses(T) if plain is None else plain):
        return _single(data, _cf_single().three_parallel_one, Kp, _REASON_3P, "three-parallel",
                       None, T, tol)
    q, valid, pos, rot, cnt = _outputs(N, 8)
    near = np.empty(N, dtype=bool)
    newton = _newton(N, checked)
    B = _batch_kernels(False)
    if N >= _PARALLEL_MIN:  # as solve_pieper_compiled
        _run_batch(B.three_parallel_batch, Kp, T, float(tol), float(wrist_tol), newton, q,
                   (valid, pos, rot, cnt, near))
    else:
        _run_serial(B.three_parallel_serial, (Kp, T, float(tol), float(wrist_tol), 1e-6,
                                              newton, q, valid, pos, rot, cnt, near),
                    T, plain, newton)
    if _unchecked(cnt):
        return None
    if shape == () and not near[0]:  # one pose away from the wrist-singular set
        return IKAllResult.build_one(q, valid, pos, rot, np.zeros((1, 8), dtype=bool),
                                     np.zeros((1, 8)), nan_array((1, 8)), None, cnt,
                                     _REASON_3P if cnt[0] == 0 else "", "three-parallel", tol)
    fields = dict(q=q, valid=valid, position_error=pos, rotation_error=rot,
                  singular=np.zeros((N, 8), dtype=bool), family_sign=np.zeros((N, 8)),
                  family_value=nan_array((N, 8)), family_joints=None, n_solutions=cnt,
                  reason=reasons(cnt, _REASON_3P), method="three-parallel", tol=tol)
    where = np.flatnonzero(near) if N != 1 else (np.zeros(1, dtype=np.intp) if near[0] else None)
    if where is not None and where.size:
        from kinestat.serial.analytic.families import add_wrist_families  # lazy: rarely needed

        res = add_wrist_families(model, T, data, IKAllResult.build((N,), **fields), near=where)
        fields = {f: getattr(res, f) for f in fields} | {"family_curve": res.family_curve}
    return IKAllResult.build((N,) if shape is None else shape, **fields)
