"""The sliding contact's fallback solver (:mod:`kinestat.sim.contact`)."""

from __future__ import annotations

import numpy as np

from kinestat.errors import UnreachableError


def fd_jacobian(resid, d2: np.ndarray, X: np.ndarray, r: np.ndarray,
                h: float = 1e-7) -> np.ndarray:
    """Forward-difference Jacobian (2, 2) of the slide residual ``resid(d2, X)[0]`` at ``d2``,
    where it is ``r``."""
    J = np.zeros((2, 2))
    for k in range(2):
        dk = d2.copy()
        dk[k] += h
        J[:, k] = (resid(dk, X)[0] - r) / h
    return J


def damped_slide(resid, d2: np.ndarray, Xg: np.ndarray, tol: float, iters: int = 60):
    """The sliding contact's 2-D Newton with backtracking, the fallback when the plain Newton of
    ``kinestat.sim.contact._stick_or_slip`` wanders: from the secant's point ``d2`` each step is
    halved until the residual's largest component falls, until it is at most ``tol``.
    ``resid(d2, X)`` returns ``(r, X_new, ...)``. Returns the best ``(d2, X)`` seen."""
    r, Xs = resid(d2, Xg)[:2]
    best = float(np.max(np.abs(r)))
    for _ in range(iters):
        if best <= tol:
            break
        J = fd_jacobian(resid, d2, Xs, r)
        try:
            step = np.linalg.solve(J, r)
        except np.linalg.LinAlgError:
            break
        t = 1.0
        for _ in range(12):
            cand = d2 - t * step
            try:
                rc, Xc = resid(cand, Xs)[:2]
            except UnreachableError:  # no sticking equilibrium at that anchor: shorter
                t *= 0.5
                continue
            if float(np.max(np.abs(rc))) < best:
                d2, r, Xs, best = cand, rc, Xc, float(np.max(np.abs(rc)))
                break
            t *= 0.5
        else:
            break
    return d2, Xs


def snap_slide(tangential, mu: float, Xg: np.ndarray, step: float = 0.05,
               max_length: float = 40.0):
    """Where a slip with no nearby equilibrium comes to rest: the anchor marched along the
    tangential force's direction in steps of ``step`` mm until the force is back inside the
    friction cone, then bisected onto the cone's edge; the fallback when both Newtons of
    ``kinestat.sim.contact._stick_or_slip`` fail.

    Where the top's tangential stiffness at the tip is negative along the slip (a loaded,
    tilted top: the platform pushes the tip on as it slides) the residual has no root near the
    anchor, and the tip snaps on until the springs hold it again; quasi-statically that is
    the first point of the path where ``|f_t| ≤ μ f_n``, the tip then sticking there.
    ``tangential(d2, X)`` returns ``(f_t (2,), f_n, X_new)`` at the in-plane displacement
    ``d2`` of the anchor (raising :class:`UnreachableError` where no sticking equilibrium
    exists). Returns ``(d2, X)``, or None when the march finds no rest within ``max_length``
    or the contact pulls (``f_n < 0``)."""
    d = np.zeros(2)
    ft, fn, X = tangential(d, Xg)
    h = step
    while float(np.hypot(*d)) < max_length and h > 1e-6:
        nt = float(np.hypot(*ft))
        if fn < 0.0:
            return None
        if nt <= mu * fn:
            break
        cand = d - h * ft / nt  # the tip slides along the tangential force it cannot hold
        try:
            ft_c, fn_c, X_c = tangential(cand, X)
        except UnreachableError:
            h *= 0.5
            continue
        if fn_c >= 0.0 and float(np.hypot(*ft_c)) <= mu * fn_c:  # back in the cone: bisect
            lo, hi, Xh = d, cand, X_c
            for _ in range(40):
                mid = 0.5 * (lo + hi)
                ft_m, fn_m, X_m = tangential(mid, X)
                if float(np.hypot(*ft_m)) <= mu * fn_m:
                    hi, Xh = mid, X_m
                else:
                    lo = mid
            return hi, Xh
        d, ft, fn, X = cand, ft_c, fn_c, X_c
    else:
        return None
    return d, X
