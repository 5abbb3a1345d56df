"""One result type for every all-solutions IK solver.

Every analytic solver (closed forms by subproblems, the general 6R eigenvalue method) returns an
:class:`IKAllResult`: ``K`` solution slots per pose, a validity mask, per-solution residuals
(checked by forward kinematics) and, for slots on a singular set, the one-parameter family the
slot stands for (e.g. a spherical wrist with its 4th and 6th axes aligned: only
``q_j + σ q_k`` is fixed). The one selection step among the solutions is
:func:`kinestat.serial.analytic.selection.select_nearest`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError

__all__ = ["IKAllResult"]


@dataclass(frozen=True, eq=False, init=False)  # __init__ below: see there
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

    def __init__(self, q, valid, position_error, rotation_error, singular, family_sign,
                 family_value, family_joints, n_solutions, reason, method, tol,
                 family_curve=None) -> None:
        # the dataclass's own __init__, written out: generating it is a third of a millisecond
        # of a first ik_all call (the fields above, in their order; frozen: set in one step)
        self.__dict__.update(
            q=q, valid=valid, position_error=position_error, rotation_error=rotation_error,
            singular=singular, family_sign=family_sign, family_value=family_value,
            family_joints=family_joints, n_solutions=n_solutions, reason=reason,
            method=method, tol=tol, family_curve=family_curve)

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

    @classmethod
    def single(cls, q, valid, position_error, rotation_error, singular, family_sign,
               family_value, family_joints, n_solutions, reason, method, tol) -> IKAllResult:
        """:meth:`build_one` from arrays already in a one-pose result's shapes (``q (K, n)``,
        ``(K,)``, ``n_solutions`` an int); ``reason``: the pose's string. The 0-d arrays of
        ``n_solutions`` and ``reason`` are shared by the results with the same value,
        read-only (as Python's small ints: a single call is a few µs, and a fresh 0-d array
        is 0.15 µs of it)."""
        obj = object.__new__(cls)
        obj.__dict__.update(
            q=q, valid=valid, position_error=position_error, rotation_error=rotation_error,
            singular=singular, family_sign=family_sign, family_value=family_value,
            family_joints=family_joints, n_solutions=_COUNTS[n_solutions],
            reason=_reason(reason), method=method, tol=tol,
            family_curve=None)
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


def _read_only(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


#: the 0-d counts of :meth:`IKAllResult.single` (K ≤ 16 slots)
_COUNTS = tuple(_read_only(np.array(i, dtype=np.int64)) for i in range(17))
_REASONS: dict[str, np.ndarray] = {}


def _reason(text: str) -> np.ndarray:
    """The read-only 0-d object array of ``text`` (:meth:`IKAllResult.single`), kept."""
    a = _REASONS.get(text)
    if a is None:
        a = _read_only(np.array(text, dtype=object))
        if len(_REASONS) < 64:
            _REASONS[text] = a
    return a


def __getattr__(name: str):
    """The selection step's names, here before they had their module
    (:mod:`kinestat.serial.analytic.selection`, loaded on first use: a first ``ik_all`` call
    does not pay for them)."""
    if name in ("Selection", "select_nearest", "wrap_to_limits"):
        from kinestat.serial.analytic import selection  # lazy: first-call time

        return getattr(selection, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
