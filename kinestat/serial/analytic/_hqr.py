"""Eigenvalues of a small dense real matrix, compiled: balancing, reduction to Hessenberg form
by stabilised elimination, and the Francis double-shift QR iteration (Wilkinson & Reinsch,
*Handbook for Automatic Computation II*, 1971: ``balance``, ``elmhes``, ``hqr``).

LAPACK's dgeev does the same (Householder instead of elimination) but, on the 16x16 matrix
of the general-6R kernel, spends most of its time in per-call overheads (workspace query,
the BLAS calls of each reflector); this loop code takes about half its time. The kernel falls
back on dgeev where the iteration does not converge (:func:`eigvals` returns False).
"""

from __future__ import annotations

import math

import numba as nb

from kinestat.serial._numba_options import INLINE as _INLINE
from kinestat.serial._numba_options import OPTS as _OPTS

__all__ = ["eigvals", "MAX_ITERATIONS"]

#: QR sweeps allowed per eigenvalue (exceptional shifts at 10 and 20)
MAX_ITERATIONS = 60
_RADIX = 2.0


@nb.njit(**_OPTS)
def _balance(a, n):
    """Scale rows and columns of ``a[:n, :n]`` in place by powers of 2 (a diagonal similarity)
    until each row and its column have comparable norms."""
    sq = _RADIX * _RADIX
    done = False
    while not done:
        done = True
        for i in range(n):
            r = 0.0
            c = 0.0
            for j in range(n):
                if j != i:
                    c += abs(a[j, i])
                    r += abs(a[i, j])
            if c != 0.0 and r != 0.0:
                g = r / _RADIX
                f = 1.0
                s = c + r
                while c < g:
                    f *= _RADIX
                    c *= sq
                g = r * _RADIX
                while c > g:
                    f /= _RADIX
                    c /= sq
                if (c + r) / f < 0.95 * s:
                    done = False
                    g = 1.0 / f
                    for j in range(n):
                        a[i, j] *= g
                    for j in range(n):
                        a[j, i] *= f


@nb.njit(**_OPTS)
def _hessenberg(a, n):
    """Reduce ``a[:n, :n]`` to upper Hessenberg form in place by Gaussian elimination with
    pivoting (similarity transformations)."""
    for m in range(1, n - 1):
        x = 0.0
        i = m
        for j in range(m, n):
            if abs(a[j, m - 1]) > abs(x):
                x = a[j, m - 1]
                i = j
        if i != m:
            for j in range(m - 1, n):
                a[i, j], a[m, j] = a[m, j], a[i, j]
            for j in range(n):
                a[j, i], a[j, m] = a[j, m], a[j, i]
        if x != 0.0:
            for i in range(m + 1, n):
                y = a[i, m - 1]
                if y != 0.0:
                    y /= x
                    a[i, m - 1] = 0.0
                    for j in range(m, n):
                        a[i, j] -= y * a[m, j]
                    for j in range(n):
                        a[j, m] += y * a[j, i]


@nb.njit(**_OPTS)
def _sign(a, b):
    return abs(a) if b >= 0.0 else -abs(a)


@nb.njit(**_INLINE)
def _sweep_step(a, k, l, m, nn, p, q, r):  # noqa: E741 - l as in _hqr
    """Step k of the double-shift sweep on rows ``l..nn``: the reflector of ``(p, q, r)``
    (the shift's first column at k = m, the bulge below the subdiagonal after it; r = 0 at
    the last step) applied to rows k..k+2 and columns k..k+2 of the active block.

    The latency of one step (a square root and two reciprocals) bounds the sweep: the bulge is
    scaled only where its squares could overflow or underflow, reciprocals are multiplied,
    and the column update runs bottom-up so that the next bulge is ready first."""
    x = 1.0
    if k != m:
        x = abs(p) + abs(q) + abs(r)
        if x != 0.0 and not 1e-100 < x < 1e100:
            g = 1.0 / x
            p *= g
            q *= g
            r *= g
        else:
            x = 1.0
    s = _sign(math.sqrt(p * p + q * q + r * r), p)
    if s == 0.0:
        return
    if k == m:
        if l != m:
            a[k, k - 1] = -a[k, k - 1]
    else:
        a[k, k - 1] = -s * x
    p += s
    g = 1.0 / s
    x = p * g
    y = q * g
    z = r * g
    g = 1.0 / p
    q *= g
    r *= g
    if k == nn - 1:  # a 2-vector reflector
        for j in range(k, nn + 1):
            p = a[k, j] + q * a[k + 1, j]
            a[k + 1, j] -= p * y
            a[k, j] -= p * x
        for i in range(nn, l - 1, -1):
            p = x * a[i, k] + y * a[i, k + 1]
            a[i, k + 1] -= p * q
            a[i, k] -= p
        return
    for j in range(k, nn + 1):
        p = a[k, j] + q * a[k + 1, j] + r * a[k + 2, j]
        a[k + 2, j] -= p * z
        a[k + 1, j] -= p * y
        a[k, j] -= p * x
    for i in range(min(nn, k + 3), l - 1, -1):
        p = x * a[i, k] + y * a[i, k + 1] + z * a[i, k + 2]
        a[i, k + 2] -= p * r
        a[i, k + 1] -= p * q
        a[i, k] -= p


@nb.njit(**_OPTS)
def _hqr(a, n, wr, wi):
    """Eigenvalues of the upper Hessenberg ``a[:n, :n]`` (destroyed) into ``wr[:n]``,
    ``wi[:n]``; False if some eigenvalue took more than ``MAX_ITERATIONS`` sweeps."""
    anorm = 0.0
    for i in range(n):
        for j in range(max(i - 1, 0), n):
            anorm += abs(a[i, j])
    nn = n - 1
    t = 0.0
    while nn >= 0:
        its = 0
        while True:
            l = nn  # noqa: E741 - the active block's first row
            while l >= 1:
                s = abs(a[l - 1, l - 1]) + abs(a[l, l])
                if s == 0.0:
                    s = anorm
                if abs(a[l, l - 1]) + s == s:
                    a[l, l - 1] = 0.0
                    break
                l -= 1  # noqa: E741
            x = a[nn, nn]
            if l == nn:  # one real root
                wr[nn] = x + t
                wi[nn] = 0.0
                nn -= 1
                break
            y = a[nn - 1, nn - 1]
            w = a[nn, nn - 1] * a[nn - 1, nn]
            if l == nn - 1:  # a 2x2 block: two roots
                p = 0.5 * (y - x)
                q = p * p + w
                z = math.sqrt(abs(q))
                x += t
                if q >= 0.0:
                    z = p + _sign(z, p)
                    wr[nn - 1] = wr[nn] = x + z
                    if z != 0.0:
                        wr[nn] = x - w / z
                    wi[nn - 1] = wi[nn] = 0.0
                else:
                    wr[nn - 1] = wr[nn] = x + p
                    wi[nn - 1] = -z
                    wi[nn] = z
                nn -= 2
                break
            if its == MAX_ITERATIONS:
                return False
            if its == 10 or its == 20:  # exceptional shift
                t += x
                for i in range(nn + 1):
                    a[i, i] -= x
                s = abs(a[nn, nn - 1]) + abs(a[nn - 1, nn - 2])
                x = y = 0.75 * s
                w = -0.4375 * s * s
            its += 1
            m = nn - 2
            p = q = r = z = 0.0
            while m >= l:  # two consecutive small subdiagonal elements
                z = a[m, m]
                r = x - z
                s = y - z
                p = (r * s - w) / a[m + 1, m] + a[m, m + 1]
                q = a[m + 1, m + 1] - z - r - s
                r = a[m + 2, m + 1]
                s = abs(p) + abs(q) + abs(r)
                p /= s
                q /= s
                r /= s
                if m == l:
                    break
                u = abs(a[m, m - 1]) * (abs(q) + abs(r))
                v = abs(p) * (abs(a[m - 1, m - 1]) + abs(z) + abs(a[m + 1, m + 1]))
                if u + v == v:
                    break
                m -= 1
            for i in range(m + 2, nn + 1):
                a[i, i - 2] = 0.0
                if i != m + 2:
                    a[i, i - 3] = 0.0
            for k in range(m, nn):  # the double-shift QR sweep on rows l..nn
                _sweep_step(a, k, l, m, nn, p, q, r)
                if k + 1 < nn:  # the bulge: the next step's reflector
                    p = a[k + 1, k]
                    q = a[k + 2, k]
                    r = a[k + 3, k] if k + 1 != nn - 1 else 0.0
    return True


@nb.njit(**_OPTS)
def eigvals(a, n, wr, wi):
    """Eigenvalues of ``a[:n, :n]`` (destroyed) into ``wr[:n]``, ``wi[:n]`` (complex pairs
    with the positive imaginary part second); False when the QR iteration did not converge
    (the outputs are then incomplete)."""
    for i in range(n):
        for j in range(n):
            if not math.isfinite(a[i, j]):
                return False
    _balance(a, n)
    _hessenberg(a, n)
    return _hqr(a, n, wr, wi)
