"""``ik_all``: every inverse-kinematics solution of a 6-joint serial arm, batched.

Dispatch (:func:`kinestat.serial.analytic.geometry.classify`): a closed form by subproblems when
the geometry admits one (spherical wrist with meeting shoulder axes; three parallel axes with a
meeting wrist pair), otherwise the general 6R eigenvalue method of Raghavan & Roth. A model with
prismatic joints goes to the decoupled solver (:mod:`kinestat.serial.analytic.decoupled`: any
three R/P positioning joints and a spherical wrist).
A robot's own closed form runs by its registered name (:mod:`kinestat.serial.ik_methods`), e.g.
``method="puma762"``: the thesis's PUMA 762 closed form (:mod:`kinestat.robots.puma762`) on a
model with the PUMA 762's geometry.
"""

from __future__ import annotations

import math
import sys
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from kinestat.errors import ModelError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.analytic import closed_form
from kinestat.serial.analytic._common import _ENTRY, call_compiled, check_poses, plain_poses
from kinestat.serial.analytic.geometry import DERIVED, PRESET, check_independent, classify
from kinestat.serial.analytic.result import IKAllResult
from kinestat.serial.ik_methods import get as _robot_method
from kinestat.serial.ik_methods import registered as _robot_methods
from kinestat.spatial.validate import as_number

if TYPE_CHECKING:
    from kinestat.serial.analytic.locked import SelfMotion

__all__ = ["ik_all", "ik_self_motion", "METHODS", "BACKENDS", "method_for"]

METHODS = ("auto", "pieper", "three-parallel", "decoupled", "middle-wrist", "raghavan-roth")
"""The generic methods; a robot's own closed form adds its name
(:func:`kinestat.serial.ik_methods.registered`, e.g. ``"puma762"``)."""
BACKENDS = ("numba", "numpy")


def _check_model(model: ChainModel) -> None:
    if not isinstance(model, ChainModel):
        raise ModelError(f"ik_all: expected a ChainModel, got {type(model).__name__}")
    _check_chain(model)


@lru_cache(maxsize=64)
def _check_chain(model: ChainModel) -> None:
    """The model checks (cached per model: a failing model raises every time)."""
    if model.n != 6:
        raise ModelError(
            f"ik_all: model {model.name!r} has {model.n} joints; all-solutions IK needs exactly "
            f"6 (fewer: the pose is over-constrained, more: the solutions are not isolated)")
    for i, j in enumerate(model.joints):
        if j.kind == "screw":
            raise ModelError(
                f"ik_all: joint {i + 1} of model {model.name!r} is a screw joint; the "
                f"all-solutions solvers handle revolute and prismatic joints only (q and q + 2π "
                f"of a screw joint are different configurations) — use kinestat.ik for a "
                f"numerical solution")
    if model.prismatic.any():
        from kinestat.serial.analytic import decoupled  # lazy: start-up (prismatic arms only)

        decoupled.plan(model)  # raises, naming why, outside the decoupled class
    if model not in DERIVED:  # reversed or folded: its arm was checked
        check_independent(model)


@lru_cache(maxsize=64)
def _classify(model: ChainModel):
    """:func:`~kinestat.serial.analytic.geometry.classify`, once per model (a reversed chain is
    classified for its model's plan, then for its own; a class already known for the model,
    :data:`~kinestat.serial.analytic.geometry.PRESET`, is taken as it is)."""
    hit = PRESET.get(model)
    return classify(model) if hit is None else hit


@lru_cache(maxsize=64)
def _classified(model: ChainModel):
    kind, data = _classify(model)
    if kind == "general":  # axes 1, 2, 3 meeting: the reversed chain is a pieper arm
        from kinestat.serial.analytic import middle_wrist, reversed_chain  # lazy: first call

        rev = reversed_chain.reverse(model)
        if _classify(rev)[0] == "pieper":
            return "pieper", {"reversed": rev}
        if middle_wrist.middle_point(model) is not None:  # axes 2, 3, 4 meeting
            return "middle-wrist", data
        if middle_wrist.middle_point(rev) is not None:  # axes 3, 4, 5 meeting
            return "middle-wrist", {"reversed": rev}
    return kind, data


@lru_cache(maxsize=64)
def _plan(model: ChainModel):
    """The model checks and its geometry class, once per model (ik_all's per-call cost; a
    model with a class already known was built from a checked one)."""
    if model not in PRESET:
        _check_chain(model)
    return _classified(model)


def method_for(model: ChainModel) -> str:
    """The method ``ik_all(model, T)`` uses with ``method="auto"``."""
    _check_model(model)
    kind, _ = _classified(model)
    return "raghavan-roth" if kind == "general" else kind


def _reshape(res: IKAllResult, shape: tuple[int, ...]) -> IKAllResult:
    if len(shape) == 1 or res.valid.shape[:-1] == shape:
        return res

    def r(a):
        return a.reshape(shape + a.shape[1:])

    return IKAllResult(
        q=r(res.q), valid=r(res.valid), position_error=r(res.position_error),
        rotation_error=r(res.rotation_error), singular=r(res.singular),
        family_sign=r(res.family_sign), family_value=r(res.family_value),
        family_joints=res.family_joints, n_solutions=r(res.n_solutions),
        reason=r(res.reason), method=res.method, tol=res.tol, family_curve=res.family_curve,
    )


def _nearest_rigid(Tf: np.ndarray) -> np.ndarray:
    """Project rotations that are orthonormal only to within the accepted 1e-6 (rounded input,
    float32) onto the nearest rotation (SVD), so that an exact solution can exist."""
    R = Tf[:, :3, :3]
    err = np.abs(np.einsum("nij,nkj->nik", R, R) - np.eye(3)).max(axis=(1, 2))
    bad = np.flatnonzero(err > 1e-13)
    if bad.size:
        Tf = Tf.copy()
        U, _, Vt = np.linalg.svd(Tf[bad, :3, :3])
        Tf[bad, :3, :3] = U @ Vt
    return Tf


_S44 = (4, 4)
_F64 = np.dtype(np.float64)
_INF = math.inf

#: the compiled closed forms (each kernel checks its poses: :func:`ik_all`'s fast path)
_CLOSED_FORMS = {"pieper": closed_form.solve_pieper_compiled,
                 "three-parallel": closed_form.solve_three_parallel_compiled}


def _checked_poses(T, fast: bool):
    """``(Tf (N, 4, 4), batch shape, plain)``: the poses checked as rigid transforms (raises
    :class:`~kinestat.errors.InputError` naming the first that is not), those orthonormal only
    to within 1e-6 projected onto the nearest rotation; ``plain``: see
    :func:`~kinestat.serial.analytic._common.plain_poses` (None: not known)."""
    if type(T) is np.ndarray and T.dtype == np.float64 and T.ndim >= 2 and \
            T.shape[-2:] == (4, 4) and fast:
        Tf = T[None] if T.ndim == 2 and T.flags.c_contiguous else \
            np.ascontiguousarray(T.reshape(-1, 4, 4))
        plain = plain_poses(Tf)
        if plain:
            bad, n_project = call_compiled(_kernels().check_rigid, Tf, 1e-6)
        else:
            bad, n_project = _kernels().check_rigid(Tf, 1e-6)
        if bad >= 0:
            check_poses(T)  # raises with the full message
        if n_project:
            Tf = _nearest_rigid(Tf)
            plain = None
        return Tf, T.shape[:-2], plain
    T = check_poses(T)
    return _nearest_rigid(np.ascontiguousarray(T.reshape(-1, 4, 4))), T.shape[:-2], None


def _kernels():
    """The closed-form kernel module (imported on first use: Numba start-up)."""
    mod = sys.modules.get("kinestat.serial.analytic._cf_kernels")
    if mod is None:
        from kinestat.serial.analytic import _cf_kernels as mod  # lazy: Numba start-up
    return mod


def _locked_plan(model: ChainModel, locked):
    """:func:`kinestat.serial.analytic.locked.plan` (its module imported on first use)."""
    mod = sys.modules.get("kinestat.serial.analytic.locked")
    if mod is None:
        from kinestat.serial.analytic import locked as mod  # lazy: first-call time
    if not isinstance(locked, dict):
        mod.check_locked(model, locked)  # raises, naming the type
    return mod.plan(model, locked)


def _bind_locked(lp):
    """The locked plan's single call (:meth:`~kinestat.serial.analytic.locked.LockedPlan.
    bind_one`), from its folded chain's plan (and its reversed chain's); None until bound."""
    kind, data = _plan(lp.six)
    rev = data.get("reversed")
    return lp.bind_one(kind, data, None if rev is None else _plan(rev)[1])


def _locked_one(model: ChainModel, locked, T: np.ndarray, tol, plain: bool):
    """:func:`ik_all`'s single call with ``locked`` joints on one pose ``T (4, 4)``: the
    result where a value of a joint is solved without a plan
    (:func:`~kinestat.serial.analytic.locked.single`), else the plan's bound call (None where
    the full path must solve it)."""
    mod = sys.modules.get("kinestat.serial.analytic.locked")
    if plain and mod is not None and type(locked) is dict:
        res = mod.single(model, locked, T[None], float(tol))
        if res is not mod._MISS:
            return res
    lp = _locked_plan(model, locked)
    one = lp.one
    return _bind_locked(lp) if one is None else one


def ik_all(model: ChainModel, T_base_flange, *, method: str = "auto", tol: float = 1e-9,
           backend: str = "numba", locked: dict | None = None) -> IKAllResult:
    """Every IK solution of the 6-joint ``model`` for poses ``T_base_flange (..., 4, 4)``.

    Returns an :class:`~kinestat.serial.analytic.result.IKAllResult` (``q (..., K, 6)``,
    ``valid (..., K)``, residuals, singular families); each valid solution reproduces its pose
    by :func:`kinestat.fk` within ``tol`` (model length unit; radians). An unreachable pose
    gives no valid slot and a ``reason``; a model that is not six revolute joints (or prismatic
    joints before a spherical wrist: ``method="decoupled"``), or a pose
    that is not a rigid transform, raises a :class:`~kinestat.errors.KinestatError`.
    ``backend``: ``"numba"`` (compiled kernels, default) or ``"numpy"`` (the references).
    A rotation accepted as orthonormal within 1e-6 but not to rounding (float32 or printed
    poses) is first replaced by the nearest rotation; residuals refer to that pose.
    ``locked``: ``{joint index (0-based): value}`` for an arm of more than 6 joints, the
    joints held fixed (radians or length) so that six remain; ``q`` then holds every joint,
    the locked ones at their values (:mod:`kinestat.serial.analytic.locked`).

    >>> import kinestat, numpy as np
    >>> m = kinestat.load("puma560")
    >>> q = np.array([0.1, 0.5, -0.3, 0.4, 0.6, -0.2])
    >>> res = kinestat.ik_all(m, kinestat.fk(m, q))
    >>> res.method, int(res.n_solutions)
    ('pieper', 8)
    >>> bool(np.any(np.all(np.abs(res.solutions() - q) < 1e-9, axis=1)))
    True
    """
    T = T_base_flange
    if type(T) is np.ndarray and T.shape == _S44 and method == "auto" and backend == "numba" \
            and isinstance(model, ChainModel) and type(tol) is float and 0.0 < tol < _INF:
        # one plain pose, defaults: the closed form's bound single call (after the first); with
        # locked joints, the folded chain's
        # C-contiguous, aligned, writeable (NPY_ARRAY_C_CONTIGUOUS | ALIGNED | WRITEABLE)
        plain = T.dtype is _F64 and T.flags.num & 0x501 == 0x501
        one = _locked_one(model, locked, T, tol, plain) if locked else _plan(model)[1].get("one")
        if one is not None and plain:
            res = one if type(one) is IKAllResult else one(T[None], float(tol))
            if res is not None:
                return res
    if not isinstance(model, ChainModel):
        raise ModelError(f"ik_all: expected a ChainModel, got {type(model).__name__}")
    tol = as_number(tol, "ik_all: tol", positive=True)
    if locked:
        lp = _locked_plan(model, locked)
        return lp.expand(ik_all(lp.six, lp.poses(T_base_flange), method=method, tol=tol,
                                backend=backend))
    kind, data = _plan(model)
    robot = None if method in METHODS else _robot_method(method)
    if method not in METHODS and robot is None:
        raise ModelError(f"ik_all: unknown method {method!r}; expected one of "
                         f"{METHODS + _robot_methods()}")
    if backend not in BACKENDS:
        raise ModelError(f"ik_all: unknown backend {backend!r}; expected one of {BACKENDS}")
    use = method if method != "auto" else ("raghavan-roth" if kind == "general" else kind)
    if use == "middle-wrist" and method == "auto" and backend == "numpy":
        use = "raghavan-roth"  # no NumPy reference of its own
    if (use in ("pieper", "three-parallel", "middle-wrist") or kind == "decoupled") and \
            use != kind:
        raise ModelError(f"ik_all: method {use!r} does not apply to model {model.name!r} "
                         f"(its geometry is {kind!r})")
    fast = backend == "numba"
    closed = fast and use in _CLOSED_FORMS and "reversed" not in data
    if closed and type(T) is np.ndarray and T.dtype == np.float64 and T.ndim >= 2 and \
            T.shape[-2:] == (4, 4):
        # the closed-form kernels check each pose themselves (None: some pose is not
        # orthonormal to rounding, or needs Newton steps; the checks below then raise or
        # project it, and the kernel runs again with Newton steps)
        Tf = T[None] if T.ndim == 2 and T.flags.c_contiguous else \
            np.ascontiguousarray(T.reshape(-1, 4, 4))
        plain = plain_poses(Tf)
        one = data.get("one") if plain and T.ndim == 2 else None  # one pose: the bound call
        res = one(Tf, float(tol)) if one is not None else _CLOSED_FORMS[use](
            model, Tf, data, tol=tol, shape=T.shape[:-2], plain=plain, checked=False)
        if res is not None:
            return res
    Tf, shape, plain = _checked_poses(T, fast)
    if closed:
        res = _CLOSED_FORMS[use](model, Tf, data, tol=tol, shape=shape, plain=plain)
        if res is None:
            raise AssertionError("ik_all: a checked pose failed the kernel's check (a bug)")
        return res
    if robot is not None:
        if not robot.applies(model):
            raise ModelError(f"ik_all: method {robot.name!r} applies only to {robot.geometry}; "
                             f"model {model.name!r} differs")
        res = robot.solve(model, Tf, tol=tol, backend=backend)
    elif use == "decoupled":
        from kinestat.serial.analytic import decoupled  # lazy: start-up (prismatic arms only)

        if kind != use:
            try:
                decoupled.plan(model)
            except ModelError as exc:
                raise ModelError(f"ik_all: method 'decoupled' does not apply to model "
                                 f"{model.name!r}: {exc}") from None
        if fast:
            from kinestat.serial.analytic import decoupled_compiled as dc  # lazy: start-up

            res = dc.solve_decoupled_compiled(model, Tf, tol=tol, shape=shape)
            if shape == () and plain and method == "auto" and "one" not in data:
                data["one"] = dc.bind_one(model, _ENTRY.get((_kernels().check_rigid, None)))
        else:
            res = decoupled.solve_decoupled(model, Tf, tol=tol)
    elif use == "middle-wrist":
        from kinestat.serial.analytic import middle_wrist, reversed_chain  # lazy: first call

        if "reversed" in data:
            res = ik_all(data["reversed"], reversed_chain.invert_poses(Tf), tol=tol)
            res = reversed_chain.unreverse(res)
        else:
            res = middle_wrist.solve_middle(model, Tf, tol=tol)
    elif use == "pieper" and "reversed" in data:
        from kinestat.serial.analytic import reversed_chain  # lazy: first-call time

        Ti = reversed_chain.invert_poses(Tf)
        res = reversed_chain.unreverse(ik_all(data["reversed"], Ti[0] if shape == () else Ti,
                                              tol=tol, backend=backend))
        if shape == () and plain and method == "auto" and fast and "one" not in data:
            data["one"] = reversed_chain.bind_one(_plan(data["reversed"])[1])
    elif use == "pieper":
        from kinestat.serial.analytic import pieper_offset  # lazy: NumPy reference only

        solve = closed_form.solve_pieper if data["shoulder"] is not None else \
            pieper_offset.solve_pieper_offset
        res = solve(model, Tf, data, tol=tol)
    elif use == "three-parallel":
        from kinestat.serial.analytic import families  # lazy: start-up (NumPy path only)

        res = families.add_wrist_families(model, Tf, data,
                                          closed_form.solve_three_parallel(model, Tf, data,
                                                                           tol=tol))
    else:
        from kinestat.serial.analytic import general6r  # lazy: start-up (SciPy's LAPACK)

        res = general6r.solve_general_6r(model, Tf, tol=tol, backend=backend, shape=shape)
        if shape == () and plain and method == "auto" and fast and "one" not in data:
            data["one"] = general6r.bind_one(model, _ENTRY.get((_kernels().check_rigid, None)))
    return _reshape(res, shape)


def ik_self_motion(model: ChainModel, T_base_flange, joint: int, n: int, *,
                   method: str = "auto", tol: float = 1e-9) -> SelfMotion:
    """Every solution along the self-motion of a 7-joint ``model``: ``joint`` (0-based) locked
    at ``n`` values over its limits (:func:`~kinestat.serial.analytic.locked.self_motion_values`)
    and the other six solved by :func:`ik_all` at each (families included)."""
    from kinestat.serial.analytic import locked as _locked  # lazy: first-call time

    if not isinstance(model, ChainModel):
        raise ModelError(f"ik_self_motion: expected a ChainModel, got {type(model).__name__}")
    values = _locked.self_motion_values(model, joint, n)
    results = tuple(ik_all(model, T_base_flange, method=method, tol=tol,
                           locked={joint: float(v)}) for v in values)
    return _locked.SelfMotion(joint=int(joint), values=values, results=results)
