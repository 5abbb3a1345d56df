"""Sine and cosine of one angle together, in a form the compiler vectorizes (Numba, inlined).

The pip builds of llvmlite have no Intel SVML, so ``math.sin``/``math.cos`` in a loop stay one
libm call per value (~20 ns for the pair). :func:`sincos` is branch-free arithmetic on
``|x| < 2**19``: the quadrant ``k = round(x / (π/2))``, the reduced angle ``r = x − k π/2``
(Cody–Waite: π/2 split in three parts, the first two of 33 bits so that ``k`` times them is
exact), and the Taylor series of ``sin r`` to ``r**15`` and of ``cos r`` to ``r**16`` on
``|r| ≤ π/4``, whose truncation is below 10^-16 there. It agrees with the C library within
2 units in the last place (the tests check it against ``np.sin``/``np.cos``); larger or
non-finite angles go to ``math.sin``/``math.cos``.

The kernels of :mod:`kinestat.serial._kernels` use it for every joint angle, one configuration
at a time and over blocks of configurations (where LLVM turns the loop into SIMD code).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numba as nb
import numpy as np

from kinestat.serial._numba_options import INLINE as _INLINE

__all__ = ["sincos", "sincos_block", "PIO2_1", "PIO2_2", "PIO2_3", "LARGE"]

#: π to 60 digits, split below into three doubles
_PI = Fraction("3.14159265358979323846264338327950288419716939937510582097494459")


def _leading(x: Fraction, bits: int) -> Fraction:
    """``x`` rounded to ``bits`` significant bits."""
    scale = Fraction(2) ** (bits - math.frexp(float(x))[1])
    return Fraction(round(x * scale)) / scale


_HALF = _PI / 2
_P1 = _leading(_HALF, 33)
_P2 = _leading(_HALF - _P1, 33)
#: π/2 = PIO2_1 + PIO2_2 + PIO2_3 (+ 2**-140 or so); k·PIO2_1 and k·PIO2_2 are exact for
#: |k| < 2**20
PIO2_1, PIO2_2, PIO2_3 = float(_P1), float(_P2), float(_HALF - _P1 - _P2)
_TWO_OVER_PI = float(1 / _HALF)
#: angles at or beyond this (and non-finite ones) go to the C library
LARGE = 2.0 ** 19

# Taylor coefficients (−1)^j / (2j+1)! and (−1)^j / (2j)!
_S3, _S5, _S7 = -1 / 6, 1 / 120, -1 / 5040
_S9, _S11, _S13, _S15 = 1 / 362880, -1 / 39916800, 1 / 6227020800, -1 / 1307674368000
_C4, _C6, _C8 = 1 / 24, -1 / 720, 1 / 40320
_C10, _C12, _C14, _C16 = -1 / 3628800, 1 / 479001600, -1 / 87178291200, 1 / 20922789888000


@nb.njit(**_INLINE)
def _reduced(x):
    """``(sin x, cos x)`` for ``|x| < LARGE`` without a branch."""
    k = math.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3
    z = r * r
    # the series in z = r² by Estrin's scheme (pairs, then powers z², z⁴): a third of Horner's
    # chain of dependent operations, which bounds a single call
    z2 = z * z
    z4 = z2 * z2
    s = r + r * z * ((_S3 + _S5 * z) + z2 * (_S7 + _S9 * z)
                     + z4 * ((_S11 + _S13 * z) + z2 * _S15))
    c = (1.0 - 0.5 * z) + z2 * ((_C4 + _C6 * z) + z2 * (_C8 + _C10 * z)
                                + z4 * ((_C12 + _C14 * z) + z2 * _C16))
    # sin x = a sin r + b cos r, cos x = a cos r − b sin r with (a, b) = (1, 0), (0, 1),
    # (−1, 0), (0, −1) by quadrant: exact (products by 0 and ±1), and no branch for a random
    # angle to mispredict
    quadrant = np.int64(k) & 3
    odd = quadrant & 1
    sign = 1 - (quadrant & 2)
    a = float((1 - odd) * sign)
    b = float(odd * sign)
    return a * s + b * c, a * c - b * s


@nb.njit(**_INLINE)
def sincos(x):
    """``(sin x, cos x)`` of one angle."""
    if abs(x) < LARGE:
        return _reduced(x)
    return math.sin(x), math.cos(x)


@nb.njit(**_INLINE)
def sincos_block(x, s, c, m):
    """``s[:m], c[:m] = sin(x[:m]), cos(x[:m])``: one vectorized pass, then the C library for
    the rare angles at or beyond :data:`LARGE`."""
    for b in range(m):
        s[b], c[b] = _reduced(x[b])
    for b in range(m):
        if not abs(x[b]) < LARGE:
            s[b] = math.sin(x[b])
            c[b] = math.cos(x[b])

