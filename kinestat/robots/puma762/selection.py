"""PUMA 762 axis angles, joint limits and the choice of one solution (Vibhute Appendix D.2:
the kinematic correction, the axis limits and the least-motion criterion)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError, JointLimitError
from kinestat.robots.puma762 import _cycle_kernels as _ck
from kinestat.robots.puma762.forward import _check_q
from kinestat.robots.puma762.params import _TWO_PI, AXIS_LIMITS_DEG, AXIS_OFFSET, _wrap
from kinestat.robots.puma762.reverse import ReverseBatch, ReverseResult, reverse

__all__ = ["to_axis_angles", "from_axis_angles", "wrap_into_limits", "within_limits",
           "Selection", "select_batch", "select", "select_axis_one"]


def to_axis_angles(q) -> np.ndarray:
    """Robot axis angles (radians) from joint angles: axis 1 = φ1 + π, others unchanged.

    The thesis's kinematic correction (Appendix D.2, Pos_A_KCorrection = 180°).

    >>> np.degrees(to_axis_angles(np.zeros(6)))
    array([180.,   0.,   0.,   0.,   0.,   0.])
    """
    return np.asarray(q, dtype=float) + AXIS_OFFSET


def from_axis_angles(a) -> np.ndarray:
    """Joint angles (radians) from robot axis angles: φ1 = axis 1 − π wrapped to [-π, π), the
    other joints unchanged (their whole turns matter: axes 4 and 6 span more than 360°).

    Joint 1's axis range (320°) is less than a turn, so wrapping φ1 loses nothing;
    ``from_axis_angles(to_axis_angles(q)) == q`` for φ1 in [-π, π).

    >>> np.degrees(from_axis_angles(np.radians([180.0, 10.0, 20.0, 30.0, 40.0, 50.0])))
    array([ 0., 10., 20., 30., 40., 50.])
    """
    q = np.asarray(a, dtype=float) - AXIS_OFFSET
    return np.concatenate([_wrap(q[..., :1]), q[..., 1:]], axis=-1)


def _limits_rad(limits_deg) -> tuple[np.ndarray, np.ndarray]:
    L = np.asarray(AXIS_LIMITS_DEG if limits_deg is None else limits_deg, dtype=float)
    if L.shape != (6, 2) or not np.all(np.isfinite(L)) or np.any(L[:, 0] > L[:, 1]):
        raise InputError(f"axis limits must be 6 finite (lower, upper) pairs in degrees, "
                         f"got shape {L.shape}")
    return np.radians(L[:, 0]), np.radians(L[:, 1])


_LIMITS_RAD: dict[int, tuple] = {}


def _limits_rad_frozen(limits_deg) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_limits_rad` of an immutable limits array (read-only, owning its data: a model's
    frozen limits) checked and converted once (the array is kept, so its id is not reused);
    any other limits every call."""
    if isinstance(limits_deg, np.ndarray) and not limits_deg.flags.writeable \
            and limits_deg.flags.owndata:
        got = _LIMITS_RAD.get(id(limits_deg))
        if got is None or got[0] is not limits_deg:
            got = _LIMITS_RAD[id(limits_deg)] = (limits_deg, _limits_rad(limits_deg))
        return got[1]
    return _limits_rad(limits_deg)


def wrap_into_limits(angles, current, lower, upper) -> tuple[np.ndarray, np.ndarray]:
    """Shift each angle by a multiple of 2π to the value nearest ``current`` inside its limits.

    All arrays broadcast; the last axis is the joint. Returns ``(wrapped, ok)`` where ``ok`` is
    False for a joint whose every shift is outside its limits (``wrapped`` is then the shift
    nearest ``current``).

    >>> a, ok = wrap_into_limits([3.0], [-3.0], [-4.0], [4.0])
    >>> np.round(a, 6), ok  # 3 rad is nearer to -3 as 3 - 2π
    (array([-3.283185]), array([ True]))
    """
    a = np.asarray(angles, dtype=float)
    c = np.asarray(current, dtype=float)
    base = c + _wrap(a - c)
    ks = np.array([-2.0, -1.0, 0.0, 1.0, 2.0]) * _TWO_PI
    cand = base[..., None] + ks
    lo = np.asarray(lower, dtype=float)[..., None]
    hi = np.asarray(upper, dtype=float)[..., None]
    eps = 1e-12
    inside = (cand >= lo - eps) & (cand <= hi + eps)
    dist = np.where(inside, np.abs(cand - c[..., None]), np.inf)
    idx = np.argmin(dist, axis=-1)
    wrapped = np.take_along_axis(cand, idx[..., None], axis=-1)[..., 0]
    ok = np.isfinite(np.take_along_axis(dist, idx[..., None], axis=-1)[..., 0])
    return np.where(ok, wrapped, base), ok


def within_limits(q, limits_deg=None) -> np.ndarray:
    """True where some 2π-shift of every axis angle of ``q (..., 6)`` lies inside the limits.

    >>> home = from_axis_angles(np.zeros(6))  # every axis at 0: φ1 = −180°
    >>> bool(within_limits(home)), bool(within_limits(home + np.radians([0, 0, 0, 0, 120, 0])))
    (True, False)
    """
    q = _check_q(q)
    lo, hi = _limits_rad(limits_deg)
    _, ok = wrap_into_limits(to_axis_angles(q), np.zeros(6), lo, hi)
    return np.all(ok, axis=-1)


@dataclass(frozen=True, eq=False)
class Selection:
    """The selected solution(s) of :func:`select_batch`, batched like the poses.

    Attributes:
        q: ``(*B, 6)`` joint angles (radians) of the selected solution,
            ``from_axis_angles(axis)`` (φ1 in [-π, π); θ4, θ6 may exceed ±π).
        axis: ``(*B, 6)`` the robot axis angles to command (radians): each shifted by multiples
            of 2π to the value nearest the current one inside the limits.
        branch: ``(*B,)`` the branch index chosen (−1 when none).
        ok: ``(*B,)`` a solution within the limits exists.
        motion: ``(*B,)`` total axis motion Σ|Δaxis| (radians) from the current configuration.
        candidates_axis: ``(*B, 8, 6)`` every branch wrapped the same way (NaN if invalid).
        candidates_ok: ``(*B, 8)`` which branches are within the limits.

    >>> from kinestat.robots.puma762.forward import forward
    >>> from kinestat.robots.puma762.reverse import reverse_batch_pose
    >>> q = np.radians([[-150.0, 10.0, 20.0, 30.0, 40.0, 50.0]])
    >>> sel = select_batch(reverse_batch_pose(forward(q).pose), current_q=q)
    >>> bool(sel.ok[0]), bool(np.allclose(sel.q, q)), float(sel.motion[0]) < 1e-9
    (True, True, True)
    """

    q: np.ndarray
    axis: np.ndarray
    branch: np.ndarray
    ok: np.ndarray
    motion: np.ndarray
    candidates_axis: np.ndarray
    candidates_ok: np.ndarray


def select_batch(batch: ReverseBatch, current_q=None, limits_deg=None, *,
                 current_axis=None) -> Selection:
    """Pick, for each pose, the branch nearest the current configuration within the axis limits.

    Each joint's angle is shifted by multiples of 2π to the value nearest the current one inside
    its limits (joints 4 and 6, ±266°, may sit more than half a turn away); the branch with the
    least total axis motion Σ|Δ| is chosen (the thesis's criterion, measured from the current
    configuration rather than from zero). On a wrist-singular branch the free motion is split
    evenly between joints 4 and 6.

    The current configuration is given either as joint angles ``current_q`` or, exactly as the
    controller reports it, as axis angles ``current_axis`` (``(*B, 6)`` or ``(6,)``, radians);
    neither means all axis angles zero (the thesis's choice). Joint angles do not say which
    turn axis 1 is on: its axis angle is taken inside the limits when possible.

    >>> from kinestat.robots.puma762.forward import forward
    >>> from kinestat.robots.puma762.reverse import reverse_batch_pose
    >>> q = np.radians([[-150.0, 10.0, 20.0, 30.0, 40.0, 50.0]])
    >>> sel = select_batch(reverse_batch_pose(forward(q).pose), current_q=q)
    >>> np.round(np.degrees(sel.q), 6)
    array([[-150.,   10.,   20.,   30.,   40.,   50.]])
    """
    lo, hi = _limits_rad(limits_deg)
    shape = batch.valid.shape[:-1]
    if current_q is not None and current_axis is not None:
        raise InputError("give the current configuration once: current_q or current_axis")
    if current_axis is not None:
        cur_axis = np.broadcast_to(_check_q(current_axis), shape + (6,))
    elif current_q is not None:
        cur_axis = to_axis_angles(_check_q(current_q)).copy()
        a1, _ = wrap_into_limits(cur_axis[..., 0], cur_axis[..., 0], lo[0], hi[0])
        cur_axis[..., 0] = a1
        cur_axis = np.broadcast_to(cur_axis, shape + (6,))
    else:
        cur_axis = np.zeros(shape + (6,))
    cur = cur_axis[..., None, :]  # (*B, 1, 6)
    a = to_axis_angles(np.where(batch.valid[..., None], batch.q, 0.0))
    # singular families: choose θ4, θ6 in the family, splitting the motion between them
    c4, c6 = cur[..., 3], cur[..., 5]
    fam = np.where(batch.singular, batch.family_value, 0.0)
    e_sum = _wrap(fam - (c4 + c6))
    e_dif = _wrap(fam - (c6 - c4))
    t4 = np.where(batch.family_sum, c4 + e_sum / 2, c4 - e_dif / 2)
    t6 = np.where(batch.family_sum, c6 + e_sum / 2, c6 + e_dif / 2)
    a = a.copy()
    a[..., 3] = np.where(batch.singular, t4, a[..., 3])
    a[..., 5] = np.where(batch.singular, t6, a[..., 5])
    wrapped, ok = wrap_into_limits(a, cur, lo, hi)
    cand_ok = np.all(ok, axis=-1) & batch.valid
    motion = np.where(cand_ok, np.sum(np.abs(wrapped - cur), axis=-1), np.inf)
    best = np.argmin(motion, axis=-1)
    any_ok = np.any(cand_ok, axis=-1)
    sel_axis = np.take_along_axis(wrapped, best[..., None, None], axis=-2)[..., 0, :]
    sel_axis = np.where(any_ok[..., None], sel_axis, np.nan)
    return Selection(
        q=from_axis_angles(sel_axis),
        axis=sel_axis,
        branch=np.where(any_ok, best, -1),
        ok=any_ok,
        motion=np.where(any_ok, np.take_along_axis(motion, best[..., None], axis=-1)[..., 0],
                        np.inf),
        candidates_axis=np.where(batch.valid[..., None], wrapped, np.nan),
        candidates_ok=cand_ok,
    )


def select(result: ReverseResult, current_q=None, limits_deg=None, *,
           current_axis=None) -> Selection:
    """:func:`select_batch` for one :class:`ReverseResult`; raises :class:`JointLimitError`
    when no solution (or family member) lies within the axis limits.

    >>> from kinestat.robots.puma762.forward import forward
    >>> from kinestat.robots.puma762.reverse import reverse_pose
    >>> q = np.radians([-150.0, 10.0, 20.0, 30.0, 40.0, 50.0])
    >>> sel = select(reverse_pose(forward(q).pose), current_q=q)
    >>> np.round(np.degrees(sel.q), 6)
    array([-150.,   10.,   20.,   30.,   40.,   50.])
    """
    sel = select_batch(result.batch, current_q, limits_deg, current_axis=current_axis)
    if not bool(sel.ok):
        lo, hi = _limits_rad(limits_deg)
        worst = []
        for k in np.flatnonzero(result.batch.valid):
            ax = sel.candidates_axis[k]
            _, ok = wrap_into_limits(ax, ax, lo, hi)
            bad = [j + 1 for j in range(6) if not ok[j]]
            worst.append(f"branch {k}: axis {', '.join(map(str, bad))}")
        joint = None
        if worst:
            first = worst[0].split("axis ")[1].split(",")[0]
            joint = int(first)
        raise JointLimitError(
            "no PUMA 762 solution lies within the axis limits ("
            + "; ".join(worst)
            + "); leave the robot where it is or choose another pose",
            joint=joint,
        )
    return sel


_AXIS_OFFSET = np.array(AXIS_OFFSET)  # writeable: the kernels compile for one array type


def select_axis_one(tool_point, s6, a67, tool_point_6, current_q, limits_deg) -> np.ndarray:
    """The axis angles (6,) (radians) of :func:`select` ``(reverse(tool_point, s6, a67,
    tool_point_6), current_q, limits_deg).axis`` for one pose, in one compiled pass (the
    reverse analysis's kernel and :func:`~kinestat.robots.puma762._cycle_kernels.select_one`):
    the single-pose path of a control cycle. Inputs are (3,), (3,), (3,), (3,), (6,) float
    arrays and (6, 2) limits in degrees, checked by the caller; an unreachable pose or one
    outside the limits raises what :func:`reverse` and :func:`select` raise (they are run for
    the message).
    """
    p = np.array(tool_point, dtype=float)  # writeable, C order: the kernel's one signature
    z = np.array(s6, dtype=float)
    x = np.array(a67, dtype=float)
    p6 = np.array(tool_point_6, dtype=float)
    cur = np.array(current_q, dtype=float)
    axis = np.empty(6)
    try:
        lo, hi = _limits_rad_frozen(limits_deg)
    except InputError:  # bad limits: the NumPy path raises (after the reverse analysis's own)
        lo = None
    if lo is not None and _ck.reverse_select_one(p, z, x, p6, cur, _AXIS_OFFSET, lo, hi, axis):
        return axis
    sel = select(reverse(p, z, x, p6), cur, limits_deg)
    return sel.axis  # pragma: no cover - select raises when no branch is within the limits
