"""Redundant arms (7 joints and more) with joints locked: every solution of the 6-joint chain
that remains, and the self-motion sampled over a locked joint's range.

A locked joint j at value v is folded into the constant transforms around it:
``C(j) · J_j(v) · C(j+1)`` becomes one constant (``J_j`` the joint's motion: a turn about z, a
slide along z, or both for a screw joint), which leaves a chain of n − 1 joints; once six joints
remain, :func:`kinestat.serial.analytic.ik_all` solves it like any 6-joint arm (its geometry
class decides the method) and the locked values are put back into every solution.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from kinestat.errors import InputError, ModelError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic.result import IKAllResult

__all__ = ["fold", "expand", "plan", "LockedPlan", "SelfMotion", "self_motion_values"]


def _joint_motion(kind: str, pitch: float, v: float) -> np.ndarray:
    c, s = math.cos(v), math.sin(v)
    M = np.eye(4)
    if kind != "prismatic":
        M[:2, :2] = [[c, -s], [s, c]]
    M[2, 3] = v if kind == "prismatic" else (pitch * v if kind == "screw" else 0.0)
    return M


def check_locked(model: ChainModel, locked) -> tuple[tuple[int, float], ...]:
    """``locked`` as sorted ``(joint, value)`` pairs (0-based joints, radians or length), checked:
    known joints, finite values, and six joints left."""
    if not isinstance(locked, dict):
        raise InputError(f"ik_all: locked must be a dict {{joint index: value}}, got "
                         f"{type(locked).__name__}")
    pairs = []
    for j, v in locked.items():
        if isinstance(j, bool) or not isinstance(j, (int, np.integer)) or not 0 <= j < model.n:
            raise InputError(f"ik_all: locked joint {j!r} is not a joint index of model "
                             f"{model.name!r} (0 to {model.n - 1})")
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise InputError(f"ik_all: the value of locked joint {j} is not a number: "
                             f"{v!r}") from None
        if not math.isfinite(v):
            raise InputError(f"ik_all: the value of locked joint {j} is not finite: {v}")
        pairs.append((int(j), v))
    if model.n - len(pairs) != 6:
        raise ModelError(f"ik_all: model {model.name!r} has {model.n} joints and {len(pairs)} "
                         f"locked; all-solutions IK needs exactly 6 free joints")
    return tuple(sorted(pairs))


@lru_cache(maxsize=256)
def fold(model: ChainModel, locked: tuple[tuple[int, float], ...]) -> ChainModel:
    """The chain of the free joints with the ``locked`` ``(joint, value)`` pairs folded into
    the constants (cached: a model and its locked values give the same object)."""
    C = list(model.constants)  # read-only views: the products below are new arrays
    joints = list(model.joints)
    for j, v in sorted(locked, reverse=True):
        jt = model.joints[j]
        C[j] = C[j] @ _joint_motion(jt.kind, jt.pitch, v) @ C[j + 1]
        del C[j + 1]
        del joints[j]
    free = [i for i in range(model.n) if i not in dict(locked)]
    label = ", ".join(f"{model.joints[j].name or j + 1}={v:g}" for j, v in locked)
    return ChainModel(name=f"{model.name} [{label}]", joints=tuple(joints),
                      constants=np.array(C), length_unit=model.length_unit,
                      q_home=np.asarray(model.q_home)[free])


class _LockedCurve:
    """A wrist-curve family of the folded chain, in the full chain's joint numbering."""

    def __init__(self, curve, free: np.ndarray, locked: tuple[tuple[int, float], ...],
                 n: int) -> None:
        self._curve, self._free, self._locked, self._n = curve, free, locked, n
        self.free_joint = int(free[curve.free_joint])
        self.joints = tuple(int(free[i]) for i in curve.joints)
        self.description = curve.description

    def members(self, n: int, k: int, t):
        q6, ok = self._curve.members(n, k, t)
        return _insert(q6, self._free, self._locked, self._n), ok


def _insert(q6: np.ndarray, free: np.ndarray, locked, n: int) -> np.ndarray:
    q = np.empty(q6.shape[:-1] + (n,))
    q[..., free] = q6
    for j, v in locked:
        q[..., j] = np.where(np.isnan(q6[..., 0]), np.nan, v)
    return q


class LockedPlan:
    """A model with its locked ``(joint, value)`` pairs: the folded 6-joint chain ``six``
    (solved by :func:`~kinestat.serial.analytic.ik_all`) and :meth:`expand`, which puts the
    locked values back. Built once per (model, locked values) by :func:`plan`."""

    __slots__ = ("model", "pairs", "six", "free", "_free_array", "_one", "_take")

    def __init__(self, model: ChainModel, pairs: tuple[tuple[int, float], ...]) -> None:
        self.model, self.pairs = model, pairs
        self.six = fold(model, pairs)
        locked_idx = {j for j, _ in pairs}
        self.free = tuple(i for i in range(model.n) if i not in locked_idx)
        self._free_array = np.array(self.free)
        self._one = pairs[0] if len(pairs) == 1 else None
        self._take = np.array([self.free.index(i) if i in self.free else 0
                               for i in range(model.n)])

    def _q(self, q6: np.ndarray) -> np.ndarray:
        if self._one is None:
            return _insert(q6, self._free_array, self.pairs, self.model.n)
        # one locked joint: one take (column j a copy of column 0), then 0 · x + v in place:
        # v, or NaN where the slot is empty (fewer steps: a single call is a few µs)
        q = q6.take(self._take, axis=-1)
        col = q[..., self._one[0]]
        col *= 0.0
        col += self._one[1]
        return q

    def expand(self, res: IKAllResult) -> IKAllResult:
        """The folded chain's result ``res`` in the full chain's joints (locked values put
        back)."""
        fields = dict(res.__dict__)
        fields["q"] = self._q(res.q)
        fj = res.family_joints
        if fj is not None:
            fields["family_joints"] = tuple(self.free[i] for i in fj)
        if res.family_curve is not None:
            fields["family_curve"] = _LockedCurve(res.family_curve, self._free_array,
                                                  self.pairs, self.model.n)
        obj = object.__new__(IKAllResult)
        obj.__dict__.update(fields)
        return obj


_PLANS: dict = {}
_PLANS_MAX = 256  # a self-motion sampled at up to this many values stays cached


def plan(model: ChainModel, locked) -> LockedPlan:
    """The :class:`LockedPlan` of ``model`` with the ``locked`` ``{joint: value}`` (checked by
    :func:`check_locked` on first use; cached per model and values, the oldest dropped
    beyond ``_PLANS_MAX``)."""
    if len(locked) == 1:  # a dict of one int joint and a float value: look up directly
        (j, v), = locked.items()
        if type(j) is int and type(v) is float:
            hit = _PLANS.get((model, j, v))
            if hit is not None:
                return hit
    pairs = check_locked(model, locked)
    key = (model, *pairs[0]) if len(pairs) == 1 else (model, pairs)
    hit = _PLANS.get(key)
    if hit is None:
        hit = LockedPlan(model, pairs)
        if len(_PLANS) >= _PLANS_MAX:
            try:  # the oldest; another thread may have dropped it first
                _PLANS.pop(next(iter(_PLANS)), None)
            except (RuntimeError, StopIteration):
                pass
        _PLANS[key] = hit
    return hit


def expand(model: ChainModel, locked: tuple[tuple[int, float], ...],
           res: IKAllResult) -> IKAllResult:
    """The folded chain's result ``res`` in the full chain's joints (locked values put back)."""
    return plan(model, dict(locked)).expand(res)


def self_motion_values(model: ChainModel, joint: int, n: int) -> np.ndarray:
    """``n`` values of ``joint`` spread over its limits (both ends included); a revolute joint
    without finite limits: ``n`` values over one turn [-π, π)."""
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 1:
        raise InputError(f"self-motion: the number of samples must be a positive integer, "
                         f"got {n!r}")
    if not 0 <= joint < model.n:
        raise InputError(f"self-motion: joint {joint!r} is not a joint index of model "
                         f"{model.name!r} (0 to {model.n - 1})")
    lo, hi = float(model.lower[joint]), float(model.upper[joint])
    if math.isfinite(lo) and math.isfinite(hi):
        return np.linspace(lo, hi, n) if n > 1 else np.array([0.5 * (lo + hi)])
    if model.prismatic[joint]:
        raise InputError(f"self-motion: prismatic joint {joint} of model {model.name!r} has no "
                         f"finite limits to sample")
    return np.linspace(-math.pi, math.pi, n, endpoint=False)


@dataclass(frozen=True, eq=False)
class SelfMotion:
    """The solutions along a self-motion: ``joint`` (0-based) locked at each of ``values``
    ``(S,)``; ``results[s]`` every solution (families included) with ``joint = values[s]``."""

    joint: int
    values: np.ndarray
    results: tuple[IKAllResult, ...]

    def solutions(self, index: tuple[int, ...] = ()) -> tuple[np.ndarray, np.ndarray]:
        """Every valid solution ``(M, n)`` of pose ``index`` over the samples, and the sample
        each comes from ``(M,)``."""
        qs = [r.solutions(index) for r in self.results]
        which = np.concatenate([np.full(len(q), s) for s, q in enumerate(qs)]).astype(int)
        return np.concatenate(qs, axis=0), which
