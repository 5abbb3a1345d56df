"""QZ eigenvalues of the Raghavan–Roth matrix quadratic for the compiled general-6R kernel, and
the test that decides on which poses the kernel uses them.

The kernel's first pass (:mod:`kinestat.serial.analytic._rr_kernels`) takes the eigenvalues of
the standard companion ``[0 I; −A2⁻¹A0 −A2⁻¹A1]`` (LAPACK dgeev). That is cheap but not
backward stable in the coefficients A0, A1, A2: with A2 conditioned 1e6–1e8 (every pose of the
Kinova Jaco2-type arm) its real roots come out up to 1e-1 off, and roots 1e-2 apart as complex
pairs. The generalised eigenvalues of the companion pencil
``([0 I; −A0 −A1], diag(I, A2))`` by the QZ algorithm (LAPACK dggev, Moler & Stewart 1973) are
backward stable in A0, A1, A2 (no A2⁻¹ is formed): on those poses 1e-8 to 1e-11, at about 1.5x
the cost of dgeev. The kernel reruns the roots with these eigenvalues on the poses its first
pass marks as suspect (and where the companion is unusable).

dggev is taken from SciPy's ``cython_lapack`` and registered with LLVM under a fixed symbol
name at import, so the kernels that call it stay cacheable on disk (a ctypes pointer would
make them uncacheable). ``cython_lapack`` uses 32-bit LAPACK integers.
"""

from __future__ import annotations

import math

import llvmlite.binding as llvm
import numba as nb
import numpy as np
from numba import types
from numba.extending import get_cython_function_address

from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS

__all__ = ["LWORK", "NEAR_REAL", "PIVOT_SUSPECT", "qz_scratch", "pencil_eigvals_qz", "nearly_real",
           "suspect"]

_SYMBOL = "kinestat_lapack_dggev"
llvm.add_symbol(_SYMBOL, get_cython_function_address("scipy.linalg.cython_lapack", "dggev"))
_dggev = types.ExternalFunction(_SYMBOL, types.void(*([types.voidptr] * 17)))

#: dggev's workspace (it needs at least 8n = 192 for n = 24; more lets it block)
LWORK = 1024
_N = 24
#: the QZ pass runs where a complex eigenvalue has ``|Im x| ≤ NEAR_REAL √err (1 + |x|)``
#: (:func:`suspect`); on 30 near-fold Jaco2 poses where the companion lost roots and no root
#: was lost visibly, ``|Im x| / ((1 + |x|) √err)`` was at most 0.13 (3.3 with err floored;
#: 2026-12-02, docs/ik-all.md)
NEAR_REAL = 10.0
#: ... or where the companion's leading coefficient has a smaller relative pivot
PIVOT_SUSPECT = 1e-4


@nb.njit(**_OPTS)
def qz_scratch():
    """Work arrays of :func:`pencil_eigvals_qz`: the pencil ``(2, 24, 24)``, beta ``(24,)``,
    the workspace ``(LWORK,)`` and LAPACK's integer and character arguments."""
    ints = np.empty(4, dtype=np.int32)
    ints[0] = _N  # n = lda = ldb
    ints[1] = 1  # ldvl = ldvr
    ints[2] = LWORK
    jobs = np.empty(1, dtype=np.uint8)
    jobs[0] = ord("N")
    return np.empty((2, _N, _N)), np.empty(_N), np.empty(LWORK), ints, jobs, np.empty(1)


@nb.njit(**_OPTS)
def pencil_eigvals_qz(A, wr, wi, S):
    """Eigenvalues (into wr, wi; NaN where infinite) of ``A2 x² + A1 x + A0`` (``A (3, 12,
    12)``) as the generalised eigenvalues of ``([0 I; −A0 −A1], diag(I, A2))`` by QZ (LAPACK
    dggev). The pencil is stored row-major, i.e. LAPACK sees its transpose: same eigenvalues.
    ``S``: :func:`qz_scratch`. Returns False when dggev reports a failure."""
    P, beta, work, ints, jobs, dummy = S
    a, b = P[0], P[1]
    a[:, :] = 0.0
    b[:, :] = 0.0
    for i in range(12):
        a[i, 12 + i] = 1.0
        b[i, i] = 1.0
        for j in range(12):
            a[12 + i, j] = -A[0, i, j]
            a[12 + i, 12 + j] = -A[1, i, j]
            b[12 + i, 12 + j] = A[2, i, j]
    ints[3] = 0
    _dggev(jobs.ctypes, jobs.ctypes, ints.ctypes, a.ctypes, ints.ctypes, b.ctypes, ints.ctypes,
           wr.ctypes, wi.ctypes, beta.ctypes, dummy.ctypes, ints[1:].ctypes, dummy.ctypes,
           ints[1:].ctypes, work.ctypes, ints[2:].ctypes, ints[3:].ctypes)
    if ints[3] != 0:
        return False
    big = 0.0
    for k in range(_N):
        big = max(big, abs(beta[k]))
    for k in range(_N):
        if not abs(beta[k]) > 1e-14 * big:  # an infinite eigenvalue (A2 singular)
            wr[k] = np.nan
            wi[k] = np.nan
        else:
            wr[k] /= beta[k]
            wi[k] /= beta[k]
    return True


@nb.njit(**_OPTS)
def nearly_real(wr, wi):
    """The smallest ``|Im x| / (1 + |x|)`` of the non-real eigenvalues (inf if none)."""
    near = np.inf
    for k in range(24):
        if abs(wi[k]) > 1e-6 * (1.0 + abs(wr[k])):
            modulus = math.sqrt(wr[k] * wr[k] + wi[k] * wi[k])  # no hypot call: a threshold
            near = min(near, abs(wi[k]) / (1.0 + modulus))
    return near


@nb.njit(**_INLINE)
def suspect(tried, lost, near, err, pivot):
    """Whether the companion pass may have missed real roots (then the QZ pass runs):

    - a real eigenvalue gave no new verified solution (not verified, or a repeat: two
      eigenvalues of one cluster polished onto the same root);
    - an odd number of real eigenvalues (the degree-16 polynomial has an even number of real
      roots counted with multiplicity);
    - a complex eigenvalue ``|Im x| / (1 + |x|) ≤ 10 √err``: within the split that the
      observed accuracy ``err`` of the pose's real eigenvalues gives a double root (a
      perturbation η moves a double root by O(√η), a simple one by O(η)), so possibly a real
      pair the companion turned complex; ``err`` is floored at 1e-12;
    - the companion's leading coefficient has a relative pivot below ``PIVOT_SUSPECT`` (its
      error grows like 1/pivot).
    """
    return (lost > 0 or tried % 2 == 1 or near <= NEAR_REAL * math.sqrt(max(err, 1e-12))
            or pivot < PIVOT_SUSPECT)
