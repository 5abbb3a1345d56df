"""One result type for every all-solutions IK solver, and one selection step.

Every analytic solver (closed forms by subproblems, the general 6R eigenvalue method) returns an
:class:`IKAllResult`: ``K`` solution slots per pose, a validity mask, per-solution residuals
(checked by forward kinematics) and, for slots on a singular set, the one-parameter family the
slot stands for (e.g. a spherical wrist with its 4th and 6th axes aligned: only
``q_j + σ q_k`` is fixed). :func:`select_nearest` is the one selection step (nearest the current
configuration within the joint limits, revolute joints wrapped by 2π into the limits) shared by
the CLI, guidance and the controller.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel

__all__ = ["IKAllResult", "Selection", "select_nearest", "wrap_to_limits"]

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, eq=False)
class IKAllResult:
    """All inverse-kinematics solutions for a batch of poses ``B`` (any shape).

    Attributes:
        q: ``(*B, K, n)`` joint values (radians for revolute joints, each in [-π, π)); NaN in
            slots that are not ``valid``. Valid slots come first.
        valid: ``(*B, K)`` the slot holds a solution that reproduces the pose within ``tol``.
        position_error: ``(*B, K)`` distance between the flange origin of ``fk(q)`` and the
            target's (model length unit); NaN where not valid.
        rotation_error: ``(*B, K)`` rotation angle between ``fk(q)`` and the target (radians).
        singular: ``(*B, K)`` the slot is a one-parameter family: only
            ``q[j] + family_sign · q[k]`` (``(j, k) = family_joints``) is fixed; ``q`` holds
            one member.
        family_sign: ``(*B, K)`` σ = ±1 of the family relation (0 where not singular).
        family_value: ``(*B, K)`` the fixed ``q[j] + σ q[k]`` wrapped to [-π, π) (NaN where
            not singular).
        family_joints: the joint pair ``(j, k)`` (0-based) of the families, or None.
        n_solutions: ``(*B,)`` number of valid slots.
        reason: ``(*B,)`` object array: ``""`` where some solution exists, otherwise why not.
        method: the solver that produced the result (``"pieper"``, ``"raghavan-roth"``...).
        tol: the residual tolerance a valid slot meets (position in the model's length unit
            and rotation in radians).
        family_curve: for families that are not a relation between two joints (the
            wrist-singular families of arms with three parallel axes: four joints move), the
            generator of their members (:class:`kinestat.serial.analytic.families.WristCurve`);
            None otherwise. See :meth:`family_members`.
    """

    q: np.ndarray
    valid: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    singular: np.ndarray
    family_sign: np.ndarray
    family_value: np.ndarray
    family_joints: tuple[int, int] | None
    n_solutions: np.ndarray
    reason: np.ndarray
    method: str
    tol: float
    family_curve: object | None = None

    _BATCHED = ("q", "valid", "position_error", "rotation_error", "singular", "family_sign",
                "family_value", "n_solutions", "reason")

    @classmethod
    def build(cls, shape: tuple[int, ...], **fields) -> IKAllResult:
        """The result from flat ``(N, ...)`` arrays, reshaped (views) to the batch ``shape``.

        The compiled solvers' constructor: it sets the fields in one step instead of one frozen
        ``__setattr__`` each (a single-pose call is a few µs, so that matters); the fields are
        the dataclass's, ``family_curve`` optional.
        """
        if shape == ():  # one pose: index the leading axis of length 1 (a view, cheaper)
            for f in cls._BATCHED:
                fields[f] = fields[f][0, ...]  # 0-d arrays stay arrays
        elif len(shape) != 1:
            for f in cls._BATCHED:
                a = fields[f]
                fields[f] = a.reshape(shape + a.shape[1:])
        fields.setdefault("family_curve", None)
        obj = object.__new__(cls)
        obj.__dict__.update(fields)
        return obj

    @classmethod
    def build_one(cls, q, valid, position_error, rotation_error, singular, family_sign,
                  family_value, family_joints, n_solutions, reason, method, tol,
                  family_curve=None) -> IKAllResult:
        """:meth:`build` for one pose (batch shape ``()``) from ``(1, ...)`` arrays, positional:
        a single call's result in one step (the keyword packing and the loop of :meth:`build`
        are a sizeable part of a few-µs call). ``reason``: the pose's string."""
        obj = object.__new__(cls)
        obj.__dict__.update(
            q=q[0], valid=valid[0], position_error=position_error[0],
            rotation_error=rotation_error[0], singular=singular[0], family_sign=family_sign[0],
            family_value=family_value[0], family_joints=family_joints,
            n_solutions=n_solutions[0, ...], reason=np.array(reason, dtype=object),
            method=method, tol=tol,
            family_curve=family_curve)
        return obj

    @property
    def shape(self) -> tuple[int, ...]:
        """The batch shape ``B``."""
        return self.valid.shape[:-1]

    def solutions(self, index: tuple[int, ...] = ()) -> np.ndarray:
        """The valid solutions ``(m, n)`` of one pose (``index`` into the batch shape)."""
        return self.q[index][self.valid[index]]

    def family_members(self, index: tuple[int, ...], k: int, t) -> np.ndarray:
        """Members ``(m, n)`` of the singular family in slot ``k`` of pose ``index`` for free
        parameter values ``t (m,)``: for a two-joint family ``q[j] + σ q[k]`` fixed, ``q[j]``
        moves by ``t`` from the slot's member; for a :attr:`family_curve`, ``t`` is the value of
        its free joint (NaN rows where no member exists)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if not self.singular[index][k]:
            raise InputError(f"slot {k} of pose {index} is not a singular family")
        if self.family_joints is not None:
            j, kk = self.family_joints
            q = np.repeat(self.q[index][k][None, :], t.size, axis=0)
            q[:, j] += t
            q[:, kk] -= self.family_sign[index][k] * t
            return q
        flat = int(np.ravel_multi_index(index, self.shape)) if self.shape else 0
        return self.family_curve.members(flat, k, t)[0]


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
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
    lo = model.lower if lower is None else np.asarray(lower, dtype=float)
    hi = model.upper if upper is None else np.asarray(upper, dtype=float)
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
