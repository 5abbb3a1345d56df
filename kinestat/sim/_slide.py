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
