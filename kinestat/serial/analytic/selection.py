"""The one selection step of the all-solutions IK: per pose, the solution nearest the current
configuration within the joint limits, revolute joints wrapped by 2π into the limits; shared by
the CLI, guidance and the controller.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.spatial.transforms import as_array

if TYPE_CHECKING:
    from kinestat.serial.analytic.result import IKAllResult

__all__ = ["Selection", "select_nearest", "wrap_to_limits"]

_TWO_PI = 2.0 * math.pi


def wrap_to_limits(q, current, lower, upper, rotates) -> tuple[np.ndarray, np.ndarray]:
    """Shift revolute joint values by multiples of 2π to the value nearest ``current`` in limits.

    All arrays broadcast over the last axis (the joint); ``rotates`` marks the joints whose
    value is an angle (prismatic joints are only checked). Returns ``(wrapped, ok)``, ``ok``
    False for a joint none of whose shifts lies within its limits.

    >>> w, ok = wrap_to_limits([3.0], [-3.0], [-4.0], [0.0], [True])
    >>> round(float(w[0]), 4), bool(ok[0])
    (-3.2832, True)
    """
    q = np.asarray(q, dtype=float)
    c = np.asarray(current, dtype=float)
    rot = np.asarray(rotates, dtype=bool)
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    base = np.where(rot, c + np.mod(q - c + math.pi, _TWO_PI) - math.pi, q)
    ks = np.arange(-3, 4) * _TWO_PI
    cand = base[..., None] + np.where(rot[..., None], ks, 0.0)
    eps = 1e-12
    inside = (cand >= lo[..., None] - eps) & (cand <= hi[..., None] + eps)
    dist = np.where(inside, np.abs(cand - c[..., None]), np.inf)
    idx = np.argmin(dist, axis=-1)[..., None]
    wrapped = np.take_along_axis(cand, idx, axis=-1)[..., 0]
    ok = np.isfinite(np.take_along_axis(dist, idx, axis=-1)[..., 0])
    return np.where(ok, wrapped, base), ok


@dataclass(frozen=True, eq=False)
class Selection:
    """The solution :func:`select_nearest` chose for each pose.

    Attributes:
        q: ``(*B, n)`` joint values to command (wrapped into the limits; NaN where none).
        index: ``(*B,)`` the slot chosen (−1 where no solution lies within the limits).
        ok: ``(*B,)`` a solution within the limits exists.
        motion: ``(*B,)`` the weighted joint motion ``Σ w_i |Δq_i|`` to it (inf where none).
    """

    q: np.ndarray
    index: np.ndarray
    ok: np.ndarray
    motion: np.ndarray


def _family_members(result: IKAllResult, q: np.ndarray, cur: np.ndarray) -> np.ndarray:
    """On singular slots, the family member splitting the free motion evenly between j and k."""
    j, k = result.family_joints
    sig = result.family_sign
    sing = result.singular
    cj, ck = cur[..., j], cur[..., k]
    val = np.where(sing, result.family_value, 0.0)
    err = np.mod(val - (cj + sig * ck) + math.pi, _TWO_PI) - math.pi
    q = q.copy()
    q[..., j] = np.where(sing, cj + err / 2.0, q[..., j])
    q[..., k] = np.where(sing, ck + sig * err / 2.0, q[..., k])
    return q


def select_nearest(model: ChainModel, result: IKAllResult, current=None, *, weights=None,
                   lower=None, upper=None) -> Selection:
    """Pick, per pose, the solution nearest ``current`` whose wrapped values lie within limits.

    Each revolute joint of each solution is shifted by multiples of 2π to the value nearest the
    current one inside its limits (:func:`wrap_to_limits`); on a singular family the free motion
    is split evenly between the two coupled joints. The solution with the least
    ``Σ weights_i |Δq_i|`` wins. ``current`` ``(*B, n)`` or ``(n,)`` defaults to
    ``model.q_home``; limits default to the model's.
    """
    n = model.n
    shape = result.shape
    cur = model.q_home if current is None else np.asarray(current, dtype=float)
    if cur.shape[-1:] != (n,) or not np.all(np.isfinite(cur)):
        raise InputError(f"current configuration must be finite with shape (..., {n})")
    cur = np.broadcast_to(cur, shape + (n,))[..., None, :]
    w = np.ones(n) if weights is None else as_array(weights, shape_tail=(n,), name="weights")
    if np.any(w < 0):
        raise InputError(f"weights must be ≥ 0, got {w.tolist()}")
    lo, hi = (default if given is None else as_array(given, shape_tail=(n,), name=nm, finite=False)
              for given, default, nm in ((lower, model.lower, "lower"),
                                          (upper, model.upper, "upper")))
    if np.any(np.isnan(lo)) or np.any(np.isnan(hi)):
        raise InputError("lower and upper limits must not contain NaN")
    rot = ~model.prismatic
    q = np.where(result.valid[..., None], result.q, 0.0)
    if result.family_joints is not None:
        q = _family_members(result, q, cur)
    wrapped, ok = wrap_to_limits(q, cur, lo, hi, rot)
    cand = np.all(ok, axis=-1) & result.valid
    motion = np.where(cand, np.sum(w * np.abs(wrapped - cur), axis=-1), np.inf)
    best = np.argmin(motion, axis=-1) if motion.shape[-1] else np.zeros(shape, dtype=int)
    any_ok = np.any(cand, axis=-1)
    sel = np.take_along_axis(wrapped, best[..., None, None], axis=-2)[..., 0, :]
    return Selection(
        q=np.where(any_ok[..., None], sel, np.nan),
        index=np.where(any_ok, best, -1),
        ok=any_ok,
        motion=np.where(any_ok, np.take_along_axis(motion, best[..., None], axis=-1)[..., 0],
                        np.inf),
    )
