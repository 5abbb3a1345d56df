"""Plain NumPy references of the compiled serial kernels — private, used by the tests only.

The public functions (:func:`kinestat.fk`, :func:`kinestat.jacobian`, :func:`kinestat.ik`,
:mod:`kinestat.robots.puma762`) always run the compiled kernels. The tests check the kernels
against these straightforward array implementations.
"""

from __future__ import annotations

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial._lm import (
    IKResult,
    _errors,
    _random_q,
    blocked_joints,
    damped_step,
    wrap_joints,
    wrap_rotating,
)
from kinestat.serial._lm_constants import (
    CHECK_EVERY,
    MU_DOWN,
    MU_MIN,
    MU_STALL,
    MU_START,
    MU_UP,
    POLISHED,
    STALL_RATIO,
    WITHIN,
)
from kinestat.serial.chunks import chunk_slices
from kinestat.serial.fk import fk, fk_frames, joint_motion
from kinestat.serial.jacobian import jacobian_from_frames
from kinestat.spatial.se3 import pose_error

__all__ = ["fk_reference", "jacobian_reference", "ik_reference"]


def fk_reference(model: ChainModel, q) -> np.ndarray:
    """NumPy forward kinematics ``(..., 4, 4)`` in chunks (the reference of ``fk``)."""
    q = model.check_q(q)
    lead = q.shape[:-1]
    Q = q.reshape(-1, model.n)
    out = np.empty((Q.shape[0], 4, 4))
    C = model.constants
    for rows in chunk_slices(Q.shape[0]):
        part = Q[rows]
        Z = joint_motion(model, part)
        T = np.broadcast_to(C[0], part.shape[:-1] + (4, 4))
        for i in range(model.n):
            T = T @ Z[:, i] @ C[i + 1]
        out[rows] = T
    return out.reshape(lead + (4, 4))


def jacobian_reference(model: ChainModel, q) -> np.ndarray:
    """NumPy space Jacobian ``(..., 6, n)`` (the reference of ``jacobian``)."""
    return jacobian_from_frames(model, fk_frames(model, q))


def ik_reference(model: ChainModel, Tt: np.ndarray, qs: np.ndarray, shape: tuple, L: float,
                 pos_tol: float, rot_tol: float, max_iter: int, restarts: int, seed,
                 respect_limits: bool) -> IKResult:
    """NumPy reference of :func:`kinestat.serial.ik.ik` (its ``backend="numpy"``) for checked
    targets ``Tt (*B, 4, 4)`` and starts ``qs``: all targets iterate together, in chunks of
    :data:`~kinestat.serial.chunks.CHUNK_ROWS` targets (bounded temporaries)."""
    n = model.n
    qs = qs.reshape(-1, n).astype(float)
    Tt = Tt.reshape(-1, 4, 4)
    N = Tt.shape[0]
    rng = np.random.default_rng(seed)
    parts = [_lm_numpy(model, Tt[rows], qs[rows], L, pos_tol, rot_tol, max_iter, restarts, rng,
                       respect_limits)
             for rows in chunk_slices(max(N, 1))]
    q_out, ok, pos, rot, it_total, attempts = (np.concatenate(a) for a in zip(*parts,
                                                                               strict=True))
    return IKResult(
        q=q_out.reshape(shape + (n,)),
        success=ok.reshape(shape),
        position_error=pos.reshape(shape),
        rotation_error=rot.reshape(shape),
        iterations=it_total.reshape(shape),
        attempts=attempts.reshape(shape),
    )


def _lm_numpy(model: ChainModel, Tt: np.ndarray, qs: np.ndarray, L: float, pos_tol: float,
              rot_tol: float, max_iter: int, restarts: int, rng: np.random.Generator,
              respect_limits: bool):
    """Levenberg–Marquardt with restarts, vectorised over the targets ``Tt (N, 4, 4)``."""
    N = Tt.shape[0]
    if respect_limits:
        project = lambda q, ref: wrap_joints(model, q, ref)  # noqa: E731
    else:
        project = lambda q, ref: q  # noqa: E731

    q = project(qs.copy(), qs)
    mu = np.full(N, MU_START)
    it_total = np.zeros(N, dtype=int)
    it_attempt = np.zeros(N, dtype=int)
    attempts = np.ones(N, dtype=int)
    best_q = q.copy()
    best_cost = np.full(N, np.inf)
    checkpoint = np.full(N, np.inf)
    pos_tol_s = pos_tol / L

    def keep_best(ids, qv, cv):
        better = cv < best_cost[ids]
        best_cost[ids] = np.where(better, cv, best_cost[ids])
        best_q[ids] = np.where(better[:, None], qv, best_q[ids])

    idx = np.arange(N)
    F, e, cost = _errors(model, q, Tt, L)
    keep_best(idx, q, cost)
    while idx.size:
        qa = q[idx]
        # convergence: within half the tolerances (the final verdict is taken again from the
        # forward kinematics), polished until 1000 times smaller or no step improves any more
        pe = np.linalg.norm(e[:, 3:], axis=-1)
        re = np.linalg.norm(e[:, :3], axis=-1)
        within = (pe <= WITHIN * pos_tol_s) & (re <= WITHIN * rot_tol)
        done = (pe <= POLISHED * pos_tol_s) & (re <= POLISHED * rot_tol)
        step = damped_step(model, F, e, mu[idx], L)
        free = blocked_joints(model, qa, step) if respect_limits else None
        if free is not None:  # a joint on a limit the step pushes it beyond: solve without it
            step = damped_step(model, F, e, mu[idx], L, free)
        q_new = project(qa + step, qa)
        F_new, e_new, cost_new = _errors(model, q_new, Tt[idx], L)
        accept = (cost_new < cost) & ~done
        mu[idx] = np.where(accept, np.maximum(mu[idx] / MU_DOWN, MU_MIN), mu[idx] * MU_UP)
        q[idx] = np.where(accept[:, None], q_new, qa)
        F = np.where(accept[:, None, None, None], F_new, F)
        e = np.where(accept[:, None], e_new, e)
        cost = np.where(accept, cost_new, cost)
        keep_best(idx, q[idx], cost)
        it_total[idx] += ~done
        it_attempt[idx] += ~done
        # stalled: damping exploded (no descent), the error did not halve over the last
        # ``CHECK_EVERY`` iterations (stuck against a limit or in a local minimum), or the attempt's
        # budget is spent
        check = (it_attempt[idx] % CHECK_EVERY == 0) & ~done
        slow = check & (cost > STALL_RATIO * checkpoint[idx])
        checkpoint[idx] = np.where(check, cost, checkpoint[idx])
        stalled = ~done & ~within & ((mu[idx] > MU_STALL) | slow | (it_attempt[idx] >= max_iter))
        restart = stalled & (attempts[idx] <= restarts)
        done |= within & (~accept | (it_attempt[idx] >= max_iter))
        finished = done | (stalled & ~restart)
        if np.any(restart):
            r = idx[restart]
            q[r] = project(_random_q(model, rng, r.size, L), qs[r])
            mu[r] = MU_START
            checkpoint[r] = np.inf
            it_attempt[r] = 0
            attempts[r] += 1
            Fr, er, cr = _errors(model, q[r], Tt[r], L)
            F[restart], e[restart], cost[restart] = Fr, er, cr
            keep_best(r, q[r], cr)
        keep = ~finished
        idx = idx[keep]
        F, e, cost = F[keep], e[keep], cost[keep]

    # the answer: the best iterate of each target, judged by its own forward kinematics
    q_out = best_q if respect_limits else wrap_rotating(model, best_q)
    pos, rot = pose_error(fk(model, q_out), Tt)
    ok = (pos <= pos_tol) & (rot <= rot_tol)
    if respect_limits:
        ok &= model.within_limits(q_out)
    return q_out, ok, pos, rot, it_total, attempts
