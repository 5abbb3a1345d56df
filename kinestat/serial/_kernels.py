"""Compiled kernels (Numba) for forward kinematics and the Jacobian of serial chains.

They compute exactly what the NumPy references :func:`kinestat.serial._reference.fk_reference`
and :func:`kinestat.serial._reference.jacobian_reference` compute, without temporaries: the running
transform is held in twelve scalars, ``T · Z(q)`` touches only the columns it changes and
``T · C`` is an affine product. Batches are split over the cores with ``prange``.

Compiled on first use and cached on disk (``cache=True``, in ``__pycache__``): the first call in
a fresh checkout compiles for a few seconds, later processes load the cache.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba.extending import intrinsic

from kinestat.mechanism.joints import JointKind
from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial._sincos import sincos, sincos_block

#: joint kind codes as plain ints (Numba freezes them at compile time)
PRISMATIC = int(JointKind.PRISMATIC)
SCREW = int(JointKind.SCREW)
#: what the single-configuration kernels return: done, q not finite, q not of the chain's length
DONE, NOT_FINITE, WRONG_LENGTH = 0, 1, 2
#: the single-configuration kernels keep the GIL (they run for less than a microsecond, and
#: releasing and taking it back would add a tenth to a call) and run without Numba's reference
#: counting (they allocate nothing): an array argument then reaches them without a reference
#: -counted wrapper made and freed on every call, a tenth of a call less
_ONE = {**_OPTS, "nogil": False, "_nrt": False}



@nb.njit(**_INLINE)
def _turn(c, s, t):
    """``t · Rz`` for the rotation about z with cosine c and sine s (12 values, row-major 3x4:
    only the first two columns change)."""
    r00, r01, r02, p0, r10, r11, r12, p1, r20, r21, r22, p2 = t
    return (c * r00 + s * r01, c * r01 - s * r00, r02, p0,
            c * r10 + s * r11, c * r11 - s * r10, r12, p1,
            c * r20 + s * r21, c * r21 - s * r20, r22, p2)


@nb.njit(**_INLINE)
def _affine(C, t):
    """``t · C`` for the running transform ``t`` (12 values) and a rigid ``C (4, 4)``."""
    r00, r01, r02, p0, r10, r11, r12, p1, r20, r21, r22, p2 = t
    n00 = r00 * C[0, 0] + r01 * C[1, 0] + r02 * C[2, 0]
    n01 = r00 * C[0, 1] + r01 * C[1, 1] + r02 * C[2, 1]
    n02 = r00 * C[0, 2] + r01 * C[1, 2] + r02 * C[2, 2]
    n03 = r00 * C[0, 3] + r01 * C[1, 3] + r02 * C[2, 3] + p0
    n10 = r10 * C[0, 0] + r11 * C[1, 0] + r12 * C[2, 0]
    n11 = r10 * C[0, 1] + r11 * C[1, 1] + r12 * C[2, 1]
    n12 = r10 * C[0, 2] + r11 * C[1, 2] + r12 * C[2, 2]
    n13 = r10 * C[0, 3] + r11 * C[1, 3] + r12 * C[2, 3] + p1
    n20 = r20 * C[0, 0] + r21 * C[1, 0] + r22 * C[2, 0]
    n21 = r20 * C[0, 1] + r21 * C[1, 1] + r22 * C[2, 1]
    n22 = r20 * C[0, 2] + r21 * C[1, 2] + r22 * C[2, 2]
    n23 = r20 * C[0, 3] + r21 * C[1, 3] + r22 * C[2, 3] + p2
    return (n00, n01, n02, n03, n10, n11, n12, n13, n20, n21, n22, n23)


@nb.njit(**_INLINE)
def _step(C, kind, h, qi, t):
    """Apply ``Z(qi) · C`` to the running transform ``t`` (12 values, row-major 3x4)."""
    if kind != PRISMATIC:
        si, ci = sincos(qi)
        t = _turn(ci, si, t)
        if kind == SCREW:
            d = h * qi
            t = (t[0], t[1], t[2], t[3] + d * t[2], t[4], t[5], t[6], t[7] + d * t[6],
                 t[8], t[9], t[10], t[11] + d * t[10])
    else:
        t = (t[0], t[1], t[2], t[3] + qi * t[2], t[4], t[5], t[6], t[7] + qi * t[6],
             t[8], t[9], t[10], t[11] + qi * t[10])
    return _affine(C, t)


@nb.njit(**_INLINE)
def _start(C0):
    return (C0[0, 0], C0[0, 1], C0[0, 2], C0[0, 3], C0[1, 0], C0[1, 1], C0[1, 2], C0[1, 3],
            C0[2, 0], C0[2, 1], C0[2, 2], C0[2, 3])


@nb.njit(**_INLINE)
def _store(t, out):
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = t[0], t[1], t[2], t[3]
    out[1, 0], out[1, 1], out[1, 2], out[1, 3] = t[4], t[5], t[6], t[7]
    out[2, 0], out[2, 1], out[2, 2], out[2, 3] = t[8], t[9], t[10], t[11]
    out[3, 0], out[3, 1], out[3, 2], out[3, 3] = 0.0, 0.0, 0.0, 1.0


@nb.njit(**_INLINE)
def _row_finite(Q, k, n):
    """True when row ``k`` of ``Q`` holds only finite values."""
    for i in range(n):
        if not math.isfinite(Q[k, i]):
            return False
    return True


@intrinsic
def _f64_pointer(typingctx, address):
    """The ``float64*`` at the integer ``address``."""
    sig = nb.types.CPointer(nb.float64)(nb.types.intp)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], context.get_value_type(signature.return_type))

    return sig, codegen


@nb.njit(**_INLINE)
def _packed_at(address):
    """The packed chain at ``address`` (``KernelData.address``: ``n``, then the ``16 (n+1)``
    constants, the ``n`` kinds and the ``n`` pitches) as ``(n, P)``, ``P`` a pointer to the
    values after ``n`` (indexed as an array, unchecked). An address costs the entry point less
    than one more array to take from Python."""
    a = np.intp(address)
    return int(_f64_pointer(a)[0]), _f64_pointer(a + 8)


@nb.njit(**_INLINE)
def _refused(n, q):
    """:data:`WRONG_LENGTH` when ``q`` is not as long as the chain (``n`` joints),
    :data:`NOT_FINITE` when it holds a value that is not finite, else :data:`DONE`."""
    if q.shape[0] != n:
        return WRONG_LENGTH
    for i in range(n):
        if not math.isfinite(q[i]):
            return NOT_FINITE
    return DONE


@nb.njit(**_INLINE)
def _affine_at(P, o, t):
    """:func:`_affine` with ``C`` the rigid transform at ``P[o:o+16]`` (row-major)."""
    r00, r01, r02, p0, r10, r11, r12, p1, r20, r21, r22, p2 = t
    c00, c01, c02, c03 = P[o], P[o + 1], P[o + 2], P[o + 3]
    c10, c11, c12, c13 = P[o + 4], P[o + 5], P[o + 6], P[o + 7]
    c20, c21, c22, c23 = P[o + 8], P[o + 9], P[o + 10], P[o + 11]
    return (r00 * c00 + r01 * c10 + r02 * c20, r00 * c01 + r01 * c11 + r02 * c21,
            r00 * c02 + r01 * c12 + r02 * c22, r00 * c03 + r01 * c13 + r02 * c23 + p0,
            r10 * c00 + r11 * c10 + r12 * c20, r10 * c01 + r11 * c11 + r12 * c21,
            r10 * c02 + r11 * c12 + r12 * c22, r10 * c03 + r11 * c13 + r12 * c23 + p1,
            r20 * c00 + r21 * c10 + r22 * c20, r20 * c01 + r21 * c11 + r22 * c21,
            r20 * c02 + r21 * c12 + r22 * c22, r20 * c03 + r21 * c13 + r22 * c23 + p2)


@nb.njit(**_INLINE)
def _packed_step(P, i, n, s, c, qi, t):
    """:func:`_step` of joint ``i`` of the packed chain ``P`` with ``sin qi, cos qi = s, c``."""
    o = 16 * (n + 1)
    kind = int(P[o + i])
    if kind != PRISMATIC:
        t = _turn(c, s, t)
        if kind == SCREW:
            d = P[o + n + i] * qi
            t = (t[0], t[1], t[2], t[3] + d * t[2], t[4], t[5], t[6], t[7] + d * t[6],
                 t[8], t[9], t[10], t[11] + d * t[10])
    else:
        t = (t[0], t[1], t[2], t[3] + qi * t[2], t[4], t[5], t[6], t[7] + qi * t[6],
             t[8], t[9], t[10], t[11] + qi * t[10])
    return _affine_at(P, 16 * (i + 1), t)


@nb.njit(**_INLINE)
def _next_sincos(q, i):
    """``(sin, cos)`` of ``q[i]``, ``(0, 1)`` past the end: the kernels take the pair of the
    next joint while the running transform goes through this one (the two overlap)."""
    if i < q.shape[0]:
        return sincos(q[i])
    return 0.0, 1.0


@nb.njit(**_ONE)
def fk_one(address, q, out):
    """End pose of one configuration of the packed chain at ``address`` into ``out (4, 4)`` (the
    caller's: an array made in the kernel costs more to hand to Python than to fill); returns
    :data:`DONE`, :data:`NOT_FINITE` or :data:`WRONG_LENGTH` (``out`` untouched)."""
    n, P = _packed_at(address)
    refused = _refused(n, q)
    if refused:
        return refused
    t = (P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7], P[8], P[9], P[10], P[11])
    s, c = _next_sincos(q, 0)
    for i in range(n):
        si, ci = s, c
        s, c = _next_sincos(q, i + 1)
        t = _packed_step(P, i, n, si, ci, q[i], t)
    _store(t, out)
    return DONE


@nb.njit(**_INLINE)
def _jac_column(t, kind, h, J, j):
    ux, uy, uz = t[2], t[6], t[10]
    px, py, pz = t[3], t[7], t[11]
    if kind == PRISMATIC:
        J[0, j] = 0.0
        J[1, j] = 0.0
        J[2, j] = 0.0
        J[3, j] = ux
        J[4, j] = uy
        J[5, j] = uz
    else:
        J[0, j] = ux
        J[1, j] = uy
        J[2, j] = uz
        # h u - u x p = h u + p x u
        J[3, j] = h * ux + py * uz - pz * uy
        J[4, j] = h * uy + pz * ux - px * uz
        J[5, j] = h * uz + px * uy - py * ux


@nb.njit(**_ONE)
def jacobian_one(address, q, J):
    """Space Jacobian of one configuration of the packed chain at ``address`` into ``J (6, n)``;
    returns :data:`DONE`, :data:`NOT_FINITE` or :data:`WRONG_LENGTH` (``J`` untouched)."""
    n, P = _packed_at(address)
    refused = _refused(n, q)
    if refused:
        return refused
    o = 16 * (n + 1)
    t = (P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7], P[8], P[9], P[10], P[11])
    s, c = _next_sincos(q, 0)
    for i in range(n):
        si, ci = s, c
        s, c = _next_sincos(q, i + 1)
        _jac_column(t, int(P[o + i]), P[o + n + i], J, i)
        t = _packed_step(P, i, n, si, ci, q[i], t)
    return DONE


#: a callee compiled once for its callers (the serial and the parallel batch kernels), not
#: inlined into each: half the compile time
_CALLEE = {**_OPTS, "cache": False}
#: configurations per block of the batch kernel: its running transforms (12 rows of BLOCK)
#: and angles stay in the first-level cache
BLOCK = 128
_MAX = 1.7976931348623157e308


@nb.njit(**_INLINE)
def _block_start(C0, t, m):
    for r in range(3):
        for col in range(4):
            v = C0[r, col]
            for b in range(m):
                t[4 * r + col, b] = v


@nb.njit(**_INLINE)
def _block_angles(Q, k0, i, x, m):
    """``x[:m] = Q[k0:k0+m, i]``; returns how many of them are not finite."""
    bad = 0
    for b in range(m):
        v = Q[k0 + b, i]
        x[b] = v
        bad += not abs(v) <= _MAX
    return bad


@nb.njit(**_INLINE)
def _bad_rows(Q, k0, m):
    """How many of the rows ``Q[k0:k0+m]`` hold a value that is not finite."""
    bad = 0
    for b in range(m):
        bad += not _row_finite(Q, k0 + b, Q.shape[1])
    return bad


@nb.njit(**_INLINE)
def _block_slide(t, h, x, m):
    """``t · Tz(h x)`` for every configuration of the block."""
    for r in range(3):
        z = t[4 * r + 2]
        p = t[4 * r + 3]
        for b in range(m):
            p[b] += h * x[b] * z[b]


@nb.njit(**_INLINE)
def _block_turn_affine(C, t, s, c, m):
    """``t · Rz · C`` for every configuration of the block: the arithmetic of :func:`_turn` then
    :func:`_affine`, row by row (``s = 0, c = 1`` gives ``t · C``, equal to it but for the sign
    of a zero)."""
    c00, c01, c02, c03 = C[0, 0], C[0, 1], C[0, 2], C[0, 3]
    c10, c11, c12, c13 = C[1, 0], C[1, 1], C[1, 2], C[1, 3]
    c20, c21, c22, c23 = C[2, 0], C[2, 1], C[2, 2], C[2, 3]
    for r in range(3):
        t0 = t[4 * r]
        t1 = t[4 * r + 1]
        t2 = t[4 * r + 2]
        t3 = t[4 * r + 3]
        for b in range(m):
            r0 = t0[b]
            r1 = t1[b]
            a0 = c[b] * r0 + s[b] * r1
            a1 = c[b] * r1 - s[b] * r0
            a2 = t2[b]
            t0[b] = a0 * c00 + a1 * c10 + a2 * c20
            t1[b] = a0 * c01 + a1 * c11 + a2 * c21
            t2[b] = a0 * c02 + a1 * c12 + a2 * c22
            t3[b] = a0 * c03 + a1 * c13 + a2 * c23 + t3[b]


@nb.njit(**_INLINE)
def _block_store(t, T_out, k0, m):
    for b in range(m):
        o = T_out[k0 + b]
        for r in range(3):
            for col in range(4):
                o[r, col] = t[4 * r + col, b]
        o[3, 0] = 0.0
        o[3, 1] = 0.0
        o[3, 2] = 0.0
        o[3, 3] = 1.0


@nb.njit(**_INLINE)
def _block_columns(t, kind, h, J_out, k0, m, j):
    """Column ``j`` of the Jacobians of the block (:func:`_jac_column`'s arithmetic)."""
    ux, uy, uz, px, py, pz = t[2], t[6], t[10], t[3], t[7], t[11]
    if kind == PRISMATIC:
        for b in range(m):
            J = J_out[k0 + b]
            J[0, j] = 0.0
            J[1, j] = 0.0
            J[2, j] = 0.0
            J[3, j] = ux[b]
            J[4, j] = uy[b]
            J[5, j] = uz[b]
    else:
        for b in range(m):
            J = J_out[k0 + b]
            J[0, j] = ux[b]
            J[1, j] = uy[b]
            J[2, j] = uz[b]
            J[3, j] = h * ux[b] + py[b] * uz[b] - pz[b] * uy[b]
            J[4, j] = h * uy[b] + pz[b] * ux[b] - px[b] * uz[b]
            J[5, j] = h * uz[b] + px[b] * uy[b] - py[b] * ux[b]


@nb.njit(**_CALLEE)
def _chain_block(C, kinds, pitch, Q, T_out, J_out, want_J, blk):
    """Block ``blk`` of :func:`_chain_batch` (its rows ``BLOCK·blk`` on); returns the number of
    its non-finite rows."""
    k0 = blk * BLOCK
    m = min(BLOCK, Q.shape[0] - k0)
    t = np.empty((12, BLOCK))
    x = np.empty(BLOCK)
    s = np.empty(BLOCK)
    c = np.empty(BLOCK)
    _block_start(C[0], t, m)
    nonfinite = 0
    for i in range(kinds.shape[0]):
        kind = kinds[i]
        if want_J:
            _block_columns(t, kind, pitch[i], J_out, k0, m, i)
        nonfinite += _block_angles(Q, k0, i, x, m)
        if kind == PRISMATIC:
            s[:m] = 0.0
            c[:m] = 1.0
        else:
            sincos_block(x, s, c, m)
        if kind == PRISMATIC or kind == SCREW:
            _block_slide(t, 1.0 if kind == PRISMATIC else pitch[i], x, m)
        _block_turn_affine(C[i + 1], t, s, c, m)
    _block_store(t, T_out, k0, m)
    return _bad_rows(Q, k0, m) if nonfinite else 0


@nb.njit(parallel=True, **_OPTS)
def _chain_batch(C, kinds, pitch, Q, T_out, J_out, want_J):
    """End poses of ``Q (N, n)`` into ``T_out (N, 4, 4)`` and, when ``want_J``, the Jacobians
    into ``J_out (N, 6, n)`` (one pass); returns the number of non-finite rows.

    Blocks of :data:`BLOCK` configurations, one per iteration over the cores; within a block
    every step is a loop over its configurations (structure of arrays: the sines and cosines of
    joint i, then ``T · Z(q_i) · C_i``), which the compiler turns into SIMD code. The results
    are bit for bit those of :func:`fk_one` and :func:`jacobian_one`."""
    bad = 0
    for blk in nb.prange((Q.shape[0] + BLOCK - 1) // BLOCK):
        bad += _chain_block(C, kinds, pitch, Q, T_out, J_out, want_J, blk)
    return bad


@nb.njit(**_OPTS)
def _chain_batch_serial(C, kinds, pitch, Q, T_out, J_out, want_J):
    """:func:`_chain_batch` on one thread (a batch of a few blocks: no thread start-up)."""
    bad = 0
    for blk in range((Q.shape[0] + BLOCK - 1) // BLOCK):
        bad += _chain_block(C, kinds, pitch, Q, T_out, J_out, want_J, blk)
    return bad


def _run(C, kinds, pitch, Q, T_out, J_out, want_J):
    run = _chain_batch if Q.shape[0] >= _PARALLEL_MIN else _chain_batch_serial
    return run(C, kinds, pitch, Q, T_out, J_out, want_J)


#: smaller batches run on one thread (starting the workers costs more than they save)
_PARALLEL_MIN = 4 * BLOCK
_NO_J = np.empty((0, 6, 0))


def fk_batch(C, kinds, pitch, Q, out):
    """End poses of ``Q (N, n)`` into ``out (N, 4, 4)``; returns the number of non-finite rows."""
    return _run(C, kinds, pitch, Q, out, _NO_J, False)


def jacobian_batch(C, kinds, pitch, Q, out):
    """Jacobians of ``Q (N, n)`` into ``out (N, 6, n)``; returns the number of non-finite rows."""
    return _run(C, kinds, pitch, Q, np.empty((Q.shape[0], 4, 4)), out, True)


def fk_jacobian_batch(C, kinds, pitch, Q, T_out, J_out):
    """End poses and Jacobians together (one pass) for ``Q (N, n)``."""
    return _run(C, kinds, pitch, Q, T_out, J_out, True)


_ENTRY: dict[str, object] = {}


def single_entry(name: str):
    """The compiled entry point of ``fk_one`` or ``jacobian_one`` for (address of a packed
    chain: ``KernelData.address``, q: float64 vector of any stride, out: C-contiguous 2-D
    float64), bypassing Numba's per-call type dispatch (the one specialisation they are
    compiled for).

    Callers must pass exactly those types (an address from a live ``KernelData``, ``q`` a 1-D
    float64 ndarray, ``out`` from ``np.empty``): the entry point checks no type, only ``q``'s
    length and values.
    """
    ep = _ENTRY.get(name)
    if ep is None:
        vec = nb.types.Array(nb.float64, 1, "A")
        out = nb.types.Array(nb.float64, 2, "C")
        ep = _ENTRY[name] = globals()[name].compile((nb.float64, vec, out))
    return ep
