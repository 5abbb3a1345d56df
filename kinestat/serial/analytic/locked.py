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
import sys
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from kinestat.errors import InputError, ModelError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic._common import _ENTRY, call_compiled, check_poses
from kinestat.serial.analytic.closed_form import _perp, pieper_parts
from kinestat.serial.analytic.geometry import (
    DERIVED,
    PRESET,
    HomeAxes,
    check_independent,
    classify,
    classify_axes,
    home_axes,
)
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
    check_independent(model, held={j for j, _ in pairs})
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
    six = ChainModel(name=f"{model.name} [{label}]", joints=tuple(joints),
                     constants=np.array(C), length_unit=model.length_unit,
                     q_home=np.asarray(model.q_home)[free])
    DERIVED.add(six)
    return six


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


def _inverse(M: np.ndarray) -> np.ndarray:
    Mi = np.eye(4)
    Mi[:3, :3] = M[:3, :3].T
    Mi[:3, 3] = -(M[:3, :3].T @ M[:3, 3])
    return Mi


def _end_map(model: ChainModel, j: int, v: float) -> tuple[np.ndarray | None, np.ndarray | None]:
    """An end joint ``j`` (the first or the last) locked at ``v``: ``(L, R)`` with
    ``fk_v(q) = T`` ⇔ ``fk_0(q) = L · T · R`` (``fk_0``: the chain folded at 0; None for the
    identity). The last: ``T = X · Z(v) · Cn`` and ``fk_0 = X · Cn``, so ``R = Cn⁻¹ Z(−v) Cn``;
    the first: ``L = C0 Z(−v) C0⁻¹``. A revolute joint's ``A Z(−v) B`` (``A B = I``) is
    ``I + (cos v − 1) M1 − sin v M2`` with ``M1 = A (ex exᵀ + ey eyᵀ) B``,
    ``M2 = A (ey exᵀ − ex eyᵀ) B``, kept per joint (:func:`_joint_info`)."""
    if v == 0.0:
        return None, None
    info = _joint_info(model, j)
    if info.M1 is not None:
        M = _I4 + (math.cos(v) - 1.0) * info.M1 - math.sin(v) * info.M2
    else:
        M = info.A @ _joint_motion(info.kind, info.pitch, -v) @ info.B
    return (M, None) if j == 0 else (None, M)


class _JointInfo:
    """What a locked joint ``j`` of a model gives every value: the free joints, the columns
    that put the folded chain's joints back; for an end joint the chain folded at 0 and the
    terms of :func:`_end_map`; for a revolute joint in between of a 7R arm the chain folded
    at 0, its axes and the terms of :func:`_fast_fold`; the general 6R formulation the
    joint's last value took (a hint for the next)."""

    def __init__(self, model: ChainModel, j: int) -> None:
        self.free = tuple(i for i in range(model.n) if i != j)
        self.free_array = np.array(self.free)
        self.take = np.array([self.free.index(i) if i != j else 0 for i in range(model.n)])
        self.end = j in (0, model.n - 1)
        self.six0 = fold(model, ((j, 0.0),)) if self.end else None
        jt = model.joints[j]
        self.kind, self.pitch = jt.kind, jt.pitch
        C = np.asarray(model.constants)
        self.A, self.B = (C[0], _inverse(C[0])) if j == 0 else (_inverse(C[-1]), C[-1])
        self.M1 = self.M2 = None
        if jt.kind == "revolute":
            a, b = self.A, self.B
            self.M1 = np.outer(a[:, 0], b[0]) + np.outer(a[:, 1], b[1])
            self.M2 = np.outer(a[:, 1], b[0]) - np.outer(a[:, 0], b[1])
        self.fused: dict = {}  # invert -> (take, family joints) of the fused single call
        self.form = None  # the general 6R formulation a value of this joint took
        self.general = None  # a joint in between where a general 6R remains: GeneralLock
        self.pending = None  # (chain, value, formulation) the first general 6R value left
        self.G1 = None  # a revolute joint in between of a 7-joint revolute arm: _fast_fold's
        if not self.end and jt.kind == "revolute" and model.n == 7 and \
                all(x.kind == "revolute" for x in model.joints):
            self.ref = fold(model, ((j, 0.0),))
            self.ref_axes = home_axes(self.ref)
            self.Cref = np.array(self.ref.constants)
            self.kinds6 = [x.kind for x in self.ref.joints]
            self.label = f"{model.name} [{jt.name or j + 1}="
            self.N0, self.N1, self.N2 = _turn_terms(C[j], C[j + 1])
            F = C[0]
            for i in range(1, j + 1):
                F = F @ C[i]  # joint j's frame at q = 0
            _, self.G1, self.G2 = _turn_terms(F, _inverse(F))
            # axes 1, 2 before joint j and 4, 5, 6 after it (j = 2, 3): the spherical wrist
            # and the shoulder's meeting are the same at every value, and so is a pieper class
            kind, data = classify(self.ref) if j in (2, 3) else ("general", {})
            self.pieper = data if kind == "pieper" else None
            G0 = np.stack([_I4, self.G1, self.G2]).reshape(3, 16)
            self.terms = np.hstack([np.stack([self.N0, self.N1, self.N2]).reshape(3, 16), G0])
            ax, k = self.ref_axes, 6 - j
            wrist = data["wrist"] if self.pieper is not None else np.zeros(3)
            x6 = _perp(ax.w[5]) if self.pieper is not None else np.zeros(3)
            self.X = np.vstack([np.hstack([ax.w[j:].T, ax.r[j:].T, ax.T0[:3], wrist[:, None],
                                           x6[:, None]]),
                                [0.0] * k + [1.0] * k + [0.0, 0.0, 0.0, 1.0, 1.0, 0.0]])
            rest = np.delete(self.Cref[:, :3, 3], j, axis=0)
            self.scale = max(1.0, float(np.abs(rest).max()))


def _turn_terms(A: np.ndarray, B: np.ndarray):
    """``A Z(v) B = N0 + (cos v − 1) N1 + sin v N2`` (``Z``: a turn about z)."""
    N1 = np.outer(A[:, 0], B[0]) + np.outer(A[:, 1], B[1])
    N2 = np.outer(A[:, 1], B[0]) - np.outer(A[:, 0], B[1])
    return A @ B, N1, N2


def _fast_fold(info: _JointInfo, j: int, v: float) -> ChainModel | None:
    """:func:`fold` of a revolute joint ``j`` in between at ``v``, with its geometry class
    (:data:`~kinestat.serial.analytic.geometry.PRESET`), from the chain folded at 0: the
    folded constant ``Cj Z(v) Cj+1`` and the axes after joint j turned by ``G = Fj Z(v) Fj⁻¹``
    about it (``Fj`` its frame at q = 0) are a few products, where building and classifying
    a new chain is hundreds of µs. The class comes from the turned axes by the same tests
    as :func:`~kinestat.serial.analytic.geometry.classify`, so a value where axes meet or
    line up that do not elsewhere is classified as such; where those tests involve no axis
    pair across joint j (a spherical wrist and the shoulder pair on either side: j = 2, 3),
    the class found once holds for every value and only its points move. None where the
    class is not a closed form (the caller then folds and classifies as for any chain: the
    general 6R costs far more than that)."""
    CG = np.array([1.0, math.cos(v) - 1.0, math.sin(v)]) @ info.terms  # Cj Z Cj+1 and G
    C = info.Cref.copy()
    C[j] = CG[:16].reshape(4, 4)
    Y = CG[16:].reshape(4, 4) @ info.X  # the points and directions after joint j, moved
    k = 6 - j
    ax0 = info.ref_axes
    w, r = ax0.w.copy(), ax0.r.copy()
    w[j:] = Y[:3, :k].T
    r[j:] = Y[:3, k:2 * k].T
    ax = HomeAxes(w, r, Y[:, 2 * k:2 * k + 4],
                  max(info.scale, abs(CG[3]), abs(CG[7]), abs(CG[11])))
    if info.pieper is not None:  # the class holds for every value: its points moved
        kind = "pieper"
        data = {"axes": ax, "wrist": Y[:3, 2 * k + 4], "shoulder": info.pieper["shoulder"],
                "x6": Y[:3, 2 * k + 5]}
    else:
        kind, data = classify_axes(info.kinds6, ax)
    if kind not in ("pieper", "three-parallel"):
        return None
    C.flags.writeable = False
    six = object.__new__(ChainModel)
    six.__dict__.update(info.ref.__dict__)
    six.__dict__.update(constants=C, name=f"{info.label}{v:g}]")
    PRESET[six] = (kind, data)
    DERIVED.add(six)
    return six


@lru_cache(maxsize=64)
def _joint_info(model: ChainModel, j: int) -> _JointInfo:
    return _JointInfo(model, j)


def _general_lock(model: ChainModel, j: int):
    """The :class:`~kinestat.serial.analytic.locked_general.GeneralLock` of a revolute joint
    ``j`` in between of a 7R arm (built on first use)."""
    info = _joint_info(model, j)
    gl = info.general
    if gl is None:
        from kinestat.serial.analytic.locked_general import GeneralLock  # lazy: SciPy

        gl = info.general = GeneralLock(model, j, lambda v: fold(model, ((j, v),)))
    return gl


_S144 = (1, 4, 4)
_I4 = np.eye(4)


def _general6r():
    from kinestat.serial.analytic import general6r  # lazy: start-up (SciPy's LAPACK)

    return general6r


def _locked_kernels():
    from kinestat.serial.analytic import _locked_kernels as K  # lazy: Numba start-up

    return K


def _entries():
    """The compiled entry points of :mod:`~kinestat.serial.analytic._locked_kernels`' two
    steps (see :func:`~kinestat.serial.analytic._common.call_compiled`), recorded by one call
    each on arrays of the types the single call passes."""
    K = _locked_kernels()
    pose = _ENTRY.get((K.pose_in, None))
    if pose is None:
        call_compiled(K.pose_in, np.eye(4)[None], _I4, _I4, True, np.empty(_S144))
        pose = _ENTRY.get((K.pose_in, None))
    joints = _ENTRY.get((K.joints_out, None))
    if joints is None:
        call_compiled(K.joints_out, np.zeros((8, 6)), np.zeros(7, dtype=np.int64), 0, 0.0,
                      np.empty((8, 7)))
        joints = _ENTRY.get((K.joints_out, None))
    return pose, joints


class LockedPlan:
    """A model with its locked ``(joint, value)`` pairs: the folded 6-joint chain ``six``
    (solved by :func:`~kinestat.serial.analytic.ik_all`) for the poses :meth:`poses` gives, and
    :meth:`expand`, which puts the locked values back. Built once per (model, locked values) by
    :func:`plan`.

    One end joint locked (the first or the last): ``six`` is the chain folded at 0 for every
    value, and the value moves into the pose (:func:`_end_map`), so that a new value costs no
    new chain. A joint in between changes the folded chain's geometry: one chain per value.
    """

    __slots__ = ("model", "pairs", "_six", "free", "_free_array", "_one", "_take", "L", "R",
                 "one", "_args")

    def __init__(self, model: ChainModel, pairs: tuple[tuple[int, float], ...],
                 seen: bool = False) -> None:
        self.model, self.pairs = model, pairs
        self.L = self.R = None
        self.one = None  # the bound single call (:meth:`bind_one`)
        self._args = None  # a general 6R's kernel arrays at the value (no chain folded yet)
        self._one = pairs[0] if len(pairs) == 1 else None
        if self._one is not None:
            j, v = self._one
            info = _joint_info(model, j)
            self.free, self._free_array, self._take = info.free, info.free_array, info.take
            self._six = None
            if info.end:
                self._six = info.six0
                self.L, self.R = _end_map(model, j, v)
                return
            gl = info.general
            if info.pending is not None:  # the joint's second value: the first one's 6R kept
                pending, info.pending = info.pending, None
                gl = _general_lock(model, j)
                gl.adopt(*pending)
            args = None if gl is None else gl.arrays(v)
            if args is not None:  # a general 6R: the kernel's arrays at v, the chain on demand
                self._args = args
                self.one = gl.bind(args, v, None if gl.run is not None else
                                   (_entries()[1], info.take, j), seen)
                if self.one is not None:  # new values from now on: :func:`single`
                    if len(_FAST) >= 64:  # as many as _joint_info keeps
                        _FAST.clear()
                    _FAST[model, j] = gl
                return
            six = _fast_fold(info, j, v) if info.G1 is not None else None
            self._six = six
            return
        self._six = fold(model, pairs)
        locked_idx = {j for j, _ in pairs}
        self.free = tuple(i for i in range(model.n) if i not in locked_idx)
        self._free_array = np.array(self.free)
        self._take = np.array([self.free.index(i) if i in self.free else 0
                               for i in range(model.n)])

    @property
    def six(self) -> ChainModel:
        """The folded 6-joint chain (folded on first use where the plan's single call has the
        kernel's arrays without it)."""
        six = self._six
        if six is None:
            six = self._six = fold(self.model, self.pairs)
            j, v = self._one
            info = _joint_info(self.model, j)
            gl = info.general
            if gl is not None and gl.P is not None:  # the arrays from the joint's terms
                gl.preset(six, v, self._args)
            elif info.form is not None:  # the last value's elimination (a hint, checked)
                _general6r().HINTS[six] = info.form
        return six

    def poses(self, T):
        """The poses ``T (..., 4, 4)`` the folded chain ``six`` must reach (checked first when
        they are mapped)."""
        if self.L is None and self.R is None:
            return T
        if not (type(T) is np.ndarray and T.dtype == np.float64 and T.ndim >= 2 and
                T.shape[-2:] == (4, 4)):
            T = check_poses(T)  # raises naming the fault (a float64 (..., 4, 4) array keeps
        # any fault through the rigid map: NaN, a last row other than [0, 0, 0, 1], a
        # rotation not orthonormal; the folded chain's check then names it)
        return self.L @ T if self.L is not None else T @ self.R

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

    def bind_one(self, kind: str, data: dict, rev_data: dict | None):
        """The single-pose call ``one(T (1, 4, 4) plain, tol)`` (kept as :attr:`one`), or None
        while the folded chain has none bound yet. ``data``: the folded chain's plan data,
        ``kind``: its geometry class, ``rev_data``: its reversed chain's plan data when it is
        solved reversed. A spherical-wrist
        closed form runs in one pass: the pose mapped (and inverted for the reversed chain),
        the kernel, the joints put back; other kinds wrap the folded chain's own single call.
        Like it, ``one`` returns None where the caller must take the full path."""
        parts = None
        if kind == "general" and self._one is not None and rev_data is None:
            j, v = self._one
            info = _joint_info(self.model, j)
            if not info.end:  # kept for the joint's next value (a hint, checked there)
                g6 = _general6r()
                searched = self.six not in g6.HINTS
                info.form = g6.formulation(self.six)[0]
                if info.G1 is not None and info.pieper is None and \
                        (info.general is None or info.general.form is None):
                    # and, from the next value on, for every value that is not special
                    info.pending = (self.six, v, g6.formulation(self.six) if searched else None)
            if data.get("one") is not None and self.L is None and self.R is None:
                self.one = self._fused_general()
                if self.one is not None:
                    return self.one
        if kind == "pieper" and self._one is not None:
            parts = pieper_parts(self.six, data) if rev_data is None else \
                pieper_parts(data["reversed"], rev_data)
        if parts is not None:
            self.one = self._fused(parts, rev_data is not None)
            return self.one
        one6 = data.get("one")
        if one6 is None:
            return None
        pose_entry = _entries()[0] if self.L is not None or self.R is not None else None
        L = _I4 if self.L is None else self.L
        R = _I4 if self.R is None else self.R
        expand = self.expand

        def one(T, tol):
            if pose_entry is not None:
                Tm = np.empty(_S144)
                pose_entry(T, L, R, False, Tm)
                T = Tm
            res = one6(T, tol)
            return None if res is None else expand(res)
        self.one = one
        return one

    def _fused_general(self):
        """:meth:`bind_one` for a folded chain solved as a general 6R, one locked joint and
        no pose map: its bound single call with the joints put back in the same call
        (:func:`~kinestat.serial.analytic.general6r.bind_one`'s ``put``); None while the
        entry points are not recorded."""
        cf = sys.modules.get("kinestat.serial.analytic._cf_kernels")
        check = None if cf is None else _ENTRY.get((cf.check_rigid, None))
        j, v = self._one
        return _general6r().bind_one(self.six, check,
                                     put=(_entries()[1], _joint_info(self.model, j).take, j, v))

    def _fused(self, parts: tuple, invert: bool):
        """:meth:`bind_one` for a spherical-wrist kernel's bound parts (entry point, packed
        chain, wrist tolerance, reason), one locked joint; ``invert``: the kernel solves the
        reversed chain."""
        entry, Kp, wrist_tol, reason = parts
        pose_entry, joints_entry = _entries()
        mapped = invert or self.L is not None or self.R is not None
        L = _I4 if self.L is None else self.L
        R = _I4 if self.R is None else self.R
        j, v = self._one
        n = self.model.n
        info = _joint_info(self.model, j)
        got = info.fused.get(invert)
        if got is None:
            # full joint i <- the kernel's joint: the folded chain's, reversed when inverted
            k6 = [5 - k if invert else k for k in range(6)]
            take = np.array([k6[self.free.index(i)] if i in self.free else 0
                             for i in range(n)], dtype=np.int64)
            got = info.fused[invert] = (take, tuple(self.free[k6[k]] for k in (3, 5)))
        take, fj = got
        S86, S8n = (8, 6), (8, n)
        single = IKAllResult.single
        empty = np.empty

        def one(T, tol):
            if mapped:
                Tm = empty(_S144)
                pose_entry(T, L, R, invert, Tm)
            else:
                Tm = T
            q, valid, pos, rot = empty(S86), empty(8, dtype=bool), empty(8), empty(8)
            sing, sign, fam = empty(8, dtype=bool), empty(8), empty(8)
            c = entry(Kp, Tm, tol, wrist_tol, q, valid, pos, rot, sing, sign, fam)
            if c < 0:
                return None
            qn = empty(S8n)
            joints_entry(q, take, j, v, qn)
            return single(qn, valid, pos, rot, sing, sign, fam, fj, c, "" if c else reason,
                          "pieper", tol)
        return one


_PLANS: dict = {}
_PLANS_MAX = 256  # a self-motion sampled at up to this many values stays cached
_SEEN = object()  # in _PLANS: a value :func:`single` has solved once (no plan built)
_FAST: dict = {}  # (model, joint): its GeneralLock once bound (new values without a plan)
_MISS = object()


def single(model: ChainModel, locked, T, tol: float):
    """:func:`~kinestat.serial.analytic.ik_all`'s single call with ``locked`` (``T (1, 4, 4)``
    plain): the result, None where the caller must take the full path, or ``_MISS`` where it
    must take the plan's bound call. A value a general 6R's joint has not had before runs
    without a plan (:meth:`~kinestat.serial.analytic.locked_general.GeneralLock.new_value`);
    a plan is built the second time (:func:`plan`), with the basis of its value."""
    if len(locked) != 1:
        return _MISS
    (j, v), = locked.items()
    key = (model, j, v)
    if type(j) is not int or type(v) is not float or key in _PLANS:
        return _MISS
    gl = _FAST.get((model, j))
    if gl is None or not math.isfinite(v):  # j: a joint of the model (a key of _FAST)
        return _MISS
    res = gl.new_value(T, tol, v)
    if res is False:  # a special value: the plan's path
        return _MISS
    _keep(key, _SEEN)
    return res


def _keep(key, value) -> None:
    if len(_PLANS) >= _PLANS_MAX:
        try:  # the oldest; another thread may have dropped it first
            _PLANS.pop(next(iter(_PLANS)), None)
        except (RuntimeError, StopIteration):
            pass
    _PLANS[key] = value


def plan(model: ChainModel, locked) -> LockedPlan:
    """The :class:`LockedPlan` of ``model`` with the ``locked`` ``{joint: value}`` (checked by
    :func:`check_locked` on first use; cached per model and values, the oldest dropped
    beyond ``_PLANS_MAX``)."""
    if len(locked) == 1:  # a dict of one int joint and a float value: look up directly
        (j, v), = locked.items()
        if type(j) is int and type(v) is float:
            hit = _PLANS.get((model, j, v))
            if hit is not None and hit is not _SEEN:
                return hit
    pairs = check_locked(model, locked)
    key = (model, *pairs[0]) if len(pairs) == 1 else (model, pairs)
    hit = _PLANS.get(key)
    if hit is None or hit is _SEEN:
        hit = LockedPlan(model, pairs, hit is _SEEN)
        _keep(key, hit)
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
