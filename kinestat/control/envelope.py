"""The safety envelope of the kinestatic controller: limits, predictions, verdicts.

Over 600 lines on purpose: the checks, the predictions they judge and the compiled paths of
both share the model's constants (``_Consts``) and the array conventions of the kernels, and
the Python checks are the authority the compiled pre-checks defer to; kept in one place so
that a change to a limit cannot miss one of them.

What the cell must never do (Vibhute 2011 Table 3-1 and the PUMA 762's axis limits):

* command an axis outside its limits (every commanded configuration is checked as the absolute
  axis angles actually sent, after wrapping and rounding), or move an axis by more than
  ``max_joint_step_deg`` in one command;
* deflect a leg by more than ``max_deflection`` (5 mm, Table 3-1 "Individual Connector
  Deflection");
* load the platform beyond ``max_load`` (50 N, Table 3-1 "Maximum perpendicular load");
* move the top relative to the base beyond Table 3-1's motion ranges: 4 mm along the base's z
  axis (perpendicular to the base plane), 3.5 mm along its x and y axes, 6° about z and 4°
  about x and y (:func:`top_motion`: the displacement of the top triangle's centroid from
  where it sits when the legs are unloaded, and the rotation vector of the top's rotation
  from its unloaded orientation, both in the base frame; each component against its range).

Loads, deflections and the top's motion are checked on every measurement AND predicted before a
command is sent:
:func:`predict` assumes the worst case for a step — the tip pinned where it is (a sticking
contact; a sliding one loads the platform less) — and maps the flange's displacement at the tip
through the platform's point stiffness at the tip, ``K_tip``, the inverse of the tip's
translational compliance computed from the spatial stiffness at the measured pose
(:func:`kinestat.parallel.stiffness.stiffness`, which includes the load terms), plus the
moment of the present load about the moved point of application. Out of contact the same
prediction is the load if the workpiece were met at the very start of the step. The pinned
tip bounds the load, not the top's motion: a frictionless tip that runs on a tight convex
surface (an R = 100 mm cylinder at 4 N, docs/control.md "Limits") carried the top 0.01–0.03°
past the 4° range after commands predicted inside it; the next measurement's check stopped
the run there.

Every check returns a list of violations (empty: safe); :func:`require` turns them into a
:class:`~kinestat.errors.SafetyStop`.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from kinestat.control._cycle_kernels import (
    command_clear_kernel,
    measurement_clear_kernel,
    predict_kernel,
    slide_kernel,
)
from kinestat.control.cycle import cross3, cross_rows, cycle_data
from kinestat.control.model import ControlModel
from kinestat.control.wrench import Measurement
from kinestat.errors import InputError, SafetyStop
from kinestat.hardware.platform_spec import MAX_DEFLECTION, MAX_LOAD, MOTION_RANGE
from kinestat.parallel.stiffness import pinned_tip_step, platform_arrays
from kinestat.parallel.stiffness import tip_compliance as platform_tip_compliance
from kinestat.spatial.se3 import rotvec_matrix_one
from kinestat.spatial.transforms import apply, apply_one, inv, skew

__all__ = [
    "MAX_DEFLECTION",
    "MAX_LOAD",
    "MOTION_RANGE",
    "AXIS_STEP_VIOLATION",
    "Envelope",
    "top_motion",
    "check_motion",
    "Prediction",
    "tip_compliance",
    "tip_stiffness",
    "predict",
    "predict_sliding",
    "sliding_force",
    "sliding_push",
    "check_target",
    "check_measurement",
    "check_command",
    "check_sent_counts",
    "sent_command_guard",
    "require",
]



AXIS_STEP_VIOLATION = " in one command"
"""The words that mark a violation of the per-command axis step in :func:`check_command`'s
list (a caller that can make the command smaller looks for them)."""


@dataclass(frozen=True)
class Envelope:
    """Limits the controller enforces (joint limits come from the :class:`ControlModel`).

    Attributes:
        max_deflection: mm, per leg.
        max_load: N, magnitude of the force on the platform.
        max_joint_step_deg: largest axis motion in one command, degrees.
        max_stream_faults: sensor-stream faults (lost, corrupt, garbled packets) tolerated while
            acquiring one measurement; more means the link is unreliable → stop.
        motion_range: the top's largest motion from its unloaded pose, base frame: x, y, z
            (mm) and rotation about x, y, z (degrees), Table 3-1 (:data:`MOTION_RANGE`).
    """

    max_deflection: float = MAX_DEFLECTION
    max_load: float = MAX_LOAD
    max_joint_step_deg: float = 30.0
    max_stream_faults: int = 5
    motion_range: tuple[float, ...] = MOTION_RANGE

    def __post_init__(self) -> None:
        r = np.asarray(self.motion_range, dtype=float)
        if r.shape != (6,) or not np.all(np.isfinite(r)) or np.any(r <= 0):
            raise InputError(f"envelope motion_range must be 6 positive numbers (x, y, z mm; "
                             f"about x, y, z degrees), got {self.motion_range!r}")
        object.__setattr__(self, "motion_range", tuple(float(v) for v in r))
        for name in ("max_deflection", "max_load", "max_joint_step_deg"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"envelope {name} must be a positive number, got {v!r}")
        if int(self.max_stream_faults) < 0:
            raise InputError("envelope max_stream_faults must be >= 0")


@dataclass(frozen=True, eq=False)
class Prediction:
    """Predicted state after a command (worst case: the tip pinned where it is).

    Attributes:
        force: (3,) force the tool would apply to the workpiece, fixed frame (N).
        deflections: (6,) leg deflections ``l − l0`` (mm).
        tip_motion: (3,) displacement of the flange-carried point at the tip (mm, fixed frame).
        top_pose: (4, 4) the predicted top pose in the base frame (first order), or None.
    """

    force: np.ndarray
    deflections: np.ndarray
    tip_motion: np.ndarray
    top_pose: np.ndarray | None = None

    @property
    def force_magnitude(self) -> float:
        return _norm3(self.force)


def _tip_base(model: ControlModel, meas: Measurement) -> np.ndarray:
    return apply_one(meas.top_pose, model.tool_tip_top)


def tip_compliance(model: ControlModel, meas: Measurement) -> np.ndarray:
    """Translational compliance of the tool tip (3, 3), base frame, mm/N, at the measured pose:
    :func:`kinestat.parallel.stiffness.tip_compliance` (Vibhute eq. 2-16/2-17)."""
    return platform_tip_compliance(model.platform, meas.top_pose, _tip_base(model, meas))


def tip_stiffness(model: ControlModel, meas: Measurement) -> np.ndarray:
    """Point stiffness of the platform at the tool tip (3, 3), FIXED frame, N/mm.

    The inverse of :func:`tip_compliance` rotated into the fixed frame
    (:func:`kinestat.parallel.stiffness.tip_stiffness`): moving the flange by ``δ`` (at the
    tip) with the tip held changes the tool's force by ``K_tip δ``.
    """
    R = np.asarray(meas.base_pose, dtype=float)[:3, :3]
    # platform_tip_stiffness's R C_tip⁻¹ Rᵀ, with the cycle's C_tip (shared with predict)
    return R @ np.linalg.inv(cycle_data(model, meas).C_tip) @ np.swapaxes(R, -1, -2)


def predict(model: ControlModel, meas: Measurement, flange_pose_new) -> Prediction:
    """Predict force and leg deflections after moving the flange to ``flange_pose_new``.

    Worst case for the load: the tip stays where it is in the fixed frame (pinned, as by a
    sticking contact) while the top may turn about it. In the new base frame the tip sits at
    ``p' = p + u``; the springs must then carry ``[F + δF; p' × (F + δF)]`` with the top's tip at
    ``p'``. To first order, with ``K`` the platform stiffness at the measured pose and ``D`` the
    top's small twist: ``K D = [δF; p × δF + u × F]`` and ``[−[p]×, I] D = u``, so
    ``δF = C_tip⁻¹ (u − [−[p]×, I] K⁻¹ [0; u × F])`` and the legs change by ``jᵀ D``. The
    force on the workpiece, fixed frame, is ``−R' (F + δF)``.
    """
    Tn = np.asarray(flange_pose_new, dtype=float)
    fast = _predict_fast(model, meas, Tn)
    if fast is not None:
        return fast
    TB_new = Tn @ model.mount
    data = cycle_data(model, meas)  # K, the tip and C_tip at the measured pose, made once
    tip_F = data.tip_fixed
    p = data.tip_base
    u = apply(inv(TB_new), tip_F) - p
    R = meas.base_pose[:3, :3]
    F = -(R.T @ meas.estimate("point"))  # external force on the tip, base frame
    K = data.K
    A = np.vstack([np.eye(3), skew(p)])
    B = np.hstack([-skew(p), np.eye(3)])
    C_tip = data.C_tip
    b = np.concatenate([np.zeros(3), cross3(u, F)])
    dF = np.linalg.solve(C_tip, u - B @ np.linalg.solve(K, b))
    D = np.linalg.solve(K, A @ dF + b)  # top twist [δφ; δx_O] relative to the base
    return _prediction(model, meas, data, Tn, TB_new, F + dF, D)


def _prediction(model: ControlModel, meas: Measurement, data, Tn: np.ndarray,
                TB_new: np.ndarray, F_new: np.ndarray, D: np.ndarray) -> Prediction:
    """The :class:`Prediction` of a move to the flange pose ``Tn`` (base ``TB_new``) after
    which the springs carry the external force ``F_new`` (base frame) and the top has turned
    by the small twist ``D = [δφ; δx_O]`` relative to the base (:func:`predict`,
    :func:`predict_sliding`)."""
    S, _ = data.leg_directions
    dl = cross_rows(model.platform.base_points, S) @ D[:3] + S @ D[3:]
    top = np.eye(4)
    Rd = rotvec_matrix_one(D[:3])  # Rotation.from_rotvec(·).as_matrix(), to rounding
    top[:3, :3] = Rd @ meas.top_pose[:3, :3]
    top[:3, 3] = Rd @ meas.top_pose[:3, 3] + D[3:]
    tip_F = data.tip_fixed
    return Prediction(force=-(TB_new[:3, :3] @ F_new),
                      deflections=meas.deflections(model) + dl,
                      tip_motion=apply(Tn @ inv(meas.flange_pose), tip_F) - tip_F,
                      top_pose=top)


def _slide(model: ControlModel, meas: Measurement, Tn: np.ndarray, push=None):
    """The first-order frictionless slide of :func:`predict_sliding`: ``(f + δf, n', v, F,
    TB_new, data, rate)``, or None out of contact (|F| ≤ 1e-9 N). ``rate`` is ``d(f + δf)/ds``
    (N/mm) for a further translation ``s`` of the flange along the unit vector ``push`` (fixed
    frame; None: not computed): the slide is linear in the tip's motion ``u``, which such a
    translation changes by ``−s R'ᵀ push``."""
    est = meas.estimate("point")  # force on the workpiece, fixed frame
    f = math.sqrt(float(est @ est))
    if not f > 1e-9:
        return None
    R = meas.base_pose[:3, :3]
    F = -(R.T @ est)  # external force on the tip, base frame
    TB_new = Tn @ model.mount
    Rn = TB_new[:3, :3]
    data = cycle_data(model, meas)
    p = data.tip_base
    u = Rn.T @ (data.tip_fixed - TB_new[:3, 3]) - p  # the pinned tip's motion, new base frame
    n_new = Rn.T @ (-est / f)  # the normal (fixed frame) in the new base frame
    KiZ = np.linalg.solve(data.K, np.vstack([np.zeros((3, 3)), skew(F)]))
    M = np.eye(3) + KiZ[3:] - skew(p) @ KiZ[:3]  # M v = v − B K⁻¹ [0; v × F]
    pick = np.zeros(3)
    pick[int(np.argmin(np.abs(n_new)))] = 1.0
    t1 = cross3(n_new, pick)
    t1 = t1 / math.sqrt(float(t1 @ t1))
    t2 = cross3(n_new, t1)
    C_tip = data.C_tip
    lhs = np.empty((3, 3))
    lhs[:, 0], lhs[:, 1], lhs[:, 2] = M @ t1, M @ t2, -(C_tip @ n_new)
    rhs = C_tip @ (f * n_new - F) - M @ u
    if push is None:
        sol = np.linalg.solve(lhs, rhs)
        rate = None
    else:
        both = np.linalg.solve(lhs, np.stack([rhs, M @ (Rn.T @ push)], axis=1))
        sol, rate = both[:, 0], float(both[2, 1])
    return f + float(sol[2]), n_new, u + sol[0] * t1 + sol[1] * t2, F, TB_new, data, rate


def sliding_force(model: ControlModel, meas: Measurement, flange_pose_new) -> float:
    """|F| (N) after moving the flange to ``flange_pose_new`` with the tip sliding freely:
    :func:`predict_sliding`'s force magnitude without the rest of the prediction (the press's
    step, :func:`kinestat.control.align.turned_force`). Out of contact, :func:`predict`'s."""
    Tn = np.asarray(flange_pose_new, dtype=float)
    fast = _slide_fast(model, meas, Tn, None)
    if fast is not None:
        return abs(fast[0]) if fast else predict(model, meas, Tn).force_magnitude
    out = _slide(model, meas, Tn)
    if out is None:
        return predict(model, meas, Tn).force_magnitude
    return abs(out[0])


def sliding_push(model: ControlModel, meas: Measurement, flange_pose_new,
                 axis) -> tuple[float, float] | None:
    """``(f, k)``: the force magnitude (N) :func:`predict_sliding` gives after moving the flange
    to ``flange_pose_new``, and its rate ``k = df/ds`` (N/mm) for a further translation ``s``
    of the flange along the unit vector ``axis`` (fixed frame): with the tip sliding freely the
    force after the move and a push ``s`` is ``f + k s`` to first order. None out of contact.
    The press's step after a turn (:func:`kinestat.control.align.contact_move`)."""
    Tn = np.asarray(flange_pose_new, dtype=float)
    push = np.asarray(axis, dtype=float)
    fast = _slide_fast(model, meas, Tn, push)
    if fast is not None:
        return fast or None
    out = _slide(model, meas, Tn, push=push)
    if out is None:
        return None
    return out[0], out[6]


def _slide_compiled(model: ControlModel, meas: Measurement, Tn: np.ndarray,
                    push: np.ndarray | None) -> tuple[float, float | None] | tuple | None:
    """:func:`_slide`'s force and rate compiled for the one pose, in one call
    (:func:`kinestat.control._cycle_kernels.slide_kernel`; equal to the NumPy formulation to
    rounding): ``(f + δf, rate)`` (``rate`` None without ``push``), ``()`` out of contact, or
    None where the kernel meets a singular matrix (the NumPy formulation then runs and
    raises)."""
    data = cycle_data(model, meas)
    out = np.empty(2)
    got = slide_kernel(_c(Tn), _consts(model).mount, _c(data.tip_fixed), _c(data.tip_base),
                       _c(meas.base_pose[:3, :3]), _c(meas.estimate("point")), _c(data.K),
                       _c(data.C_tip), np.zeros(3) if push is None else _c(push), push is not None,
                       out)
    if got < 0:
        return None
    if got == 0:
        return ()
    return float(out[0]), (float(out[1]) if push is not None else None)


#: the sliding prediction's compiled path (None on the reference path: NumPy only)
_slide_fast = _slide_compiled


def predict_sliding(model: ControlModel, meas: Measurement, flange_pose_new) -> Prediction:
    """Predict the state after moving the flange to ``flange_pose_new`` with the tip SLIDING
    freely (a frictionless contact) on the surface whose normal is the measured force's
    direction: the force stays along that normal in the fixed frame, the tip moves only in the
    tangent plane. (:func:`predict` pins the tip: the worst case for the load of a sticking
    contact; on a frictionless surface met far off the tool axis it overstates the load of a
    turn several times, and understates the top's motion.)

    To first order, with ``M v = v + B K⁻¹ [0; [F]× v]`` the map from the tip's displacement
    ``v`` relative to the top (base frame) to ``C_tip δF`` (:func:`predict`'s relation
    ``M u = C_tip δF``): the tip's displacement is ``u + T τ`` (``u`` as for the pinned tip,
    ``T`` (3, 2) the tangent plane of the normal ``n'`` in the new base frame) and the force
    ``(f + δf) n'``, so ``[M T, −C_tip n'] [τ; δf] = C_tip (f n' − F) − M u``. Out of contact
    (|F| below 1e-9 N) it returns :func:`predict`'s (pinned) prediction. NumPy, not compiled.
    """
    Tn = np.asarray(flange_pose_new, dtype=float)
    out = _slide(model, meas, Tn)
    if out is None:
        return predict(model, meas, Tn)
    f_new, n_new, v, F, TB_new, data, _ = out
    p = data.tip_base
    dF = f_new * n_new - F
    A = np.vstack([np.eye(3), skew(p)])
    D = np.linalg.solve(data.K, A @ dF + np.concatenate([np.zeros(3), cross3(v, F)]))
    return _prediction(model, meas, data, Tn, TB_new, F + dF, D)


def _c(a) -> np.ndarray:
    """``a`` as a writeable C-ordered float array (itself when it is one: the kernels compile
    for one array type)."""
    if type(a) is np.ndarray and a.dtype is _F64:
        f = a.flags
        if f.c_contiguous and f.writeable:
            return a
    return np.array(a, dtype=float)


_F64 = np.dtype(np.float64)


def _predict_compiled(model: ControlModel, meas: Measurement, Tn: np.ndarray) -> Prediction | None:
    """:func:`predict`'s formulation compiled for the one pose, in one call
    (:func:`kinestat.control._cycle_kernels.predict_kernel` around
    :func:`kinestat.parallel._stiffness_kernels.pinned_tip_step_one`: one elimination of K
    instead of three solves, the legs and the Rodrigues rotation in scalars, the frame changes
    around them in scalars); equal to the NumPy formulation to rounding. None when the kernel
    meets a singular matrix (the NumPy formulation then runs and raises)."""
    data = cycle_data(model, meas)
    k = _consts(model)
    B, P_top, _, _ = platform_arrays(model.platform)
    force, defl, tip_motion, top = np.empty(3), np.empty(6), np.empty(3), np.empty((4, 4))
    if not predict_kernel(_c(Tn), k.mount, _c(data.tip_fixed), _c(data.tip_base),
                          _c(meas.base_pose), _c(meas.estimate("point")), B, P_top,
                          _c(data.top_pose), _c(data.K), _c(meas.flange_pose),
                          _c(meas.leg_lengths), k.free_lengths_array, force, defl, tip_motion,
                          top):
        return None
    return Prediction(force=force, deflections=defl, tip_motion=tip_motion, top_pose=top)


def _predict_numpy_wrapped(model: ControlModel, meas: Measurement,
                           Tn: np.ndarray) -> Prediction | None:
    """:func:`_predict_compiled` as first written: the platform's kernel
    (:func:`kinestat.parallel.stiffness.pinned_tip_step`) wrapped in NumPy (kept for the
    tests of the compiled wrapping)."""
    TB_new = Tn @ model.mount
    data = cycle_data(model, meas)
    tip_F = data.tip_fixed
    p = data.tip_base
    R_new, t_new = TB_new[:3, :3], TB_new[:3, 3]
    u = (tip_F - t_new) @ R_new - p  # inv(TB_new) tip_F − p
    F = -(meas.estimate("point") @ meas.base_pose[:3, :3])  # −Rᵀ F: external force, base frame
    out = pinned_tip_step(model.platform, data.top_pose, data.K, p, u, F)
    if out is None:
        return None
    dF, _, dl, top = out
    Tf = meas.flange_pose
    local = (tip_F - Tf[:3, 3]) @ Tf[:3, :3]  # the tip in the measured flange frame
    tip_motion = Tn[:3, :3] @ local + Tn[:3, 3] - tip_F
    return Prediction(force=-(R_new @ (F + dF)), deflections=meas.deflections(model) + dl,
                      tip_motion=tip_motion, top_pose=top)


#: the prediction's compiled path (None on the reference path: the NumPy formulation only)
_predict_fast = _predict_compiled


def top_motion(model: ControlModel, top_pose) -> np.ndarray:
    """The top's motion from its unloaded pose (Table 3-1's quantities), base frame: (6,)
    ``[dx, dy, dz]`` (mm) of the top triangle's centroid and ``[rx, ry, rz]`` (degrees), the
    rotation vector of ``R_top R_home⁻¹``."""
    T = np.asarray(top_pose, dtype=float)
    H = model.platform.home_pose
    r = Rotation.from_matrix(T[:3, :3] @ H[:3, :3].T).as_rotvec(degrees=True)
    return np.concatenate([_top_translation(model, T), r])


class _Consts:
    """A model's constants of the checks as Python floats, made once per model (the checks run
    several times a cycle; their scalar arithmetic beats NumPy's per-call set-up on 3-vectors)."""

    def __init__(self, model: ControlModel) -> None:
        H = model.platform.home_pose
        c = model.platform.top_points.mean(axis=0)
        self.H_rot = H[:3, :3].tolist()
        self.centroid = c.tolist()
        self.home_centroid = (H[:3, :3] @ c + H[:3, 3]).tolist()
        self.lo = model.limits_deg[:, 0].tolist()
        self.hi = model.limits_deg[:, 1].tolist()
        self.free_lengths = model.platform.free_lengths.tolist()
        # writeable C copies for the compiled prediction (it compiles for one array type)
        self.mount = np.array(model.mount, dtype=float)
        self.free_lengths_array = np.array(model.platform.free_lengths, dtype=float)
        # and for the compiled pre-checks (_measurement_clear, _command_clear)
        self.H_rot_array = np.array(H[:3, :3], dtype=float)
        self.centroid_array = np.array(c, dtype=float)
        self.home_centroid_array = np.array(self.home_centroid, dtype=float)
        self.lo_array = np.array(model.limits_deg[:, 0], dtype=float)
        self.hi_array = np.array(model.limits_deg[:, 1], dtype=float)


_CONSTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _consts(model: ControlModel) -> _Consts:
    k = _CONSTS.get(model)
    if k is None:
        k = _CONSTS[model] = _Consts(model)
    return k


def _translation_list(model: ControlModel, T: np.ndarray) -> list[float]:
    """:func:`top_motion`'s ``[dx, dy, dz]``: the top centroid's displacement from home (mm),
    ``(R c + t) − (R_home c + t_home)`` in scalars."""
    k = _consts(model)
    (r0, r1, r2, t0), (r3, r4, r5, t1), (r6, r7, r8, t2) = T[:3].tolist()
    c0, c1, c2 = k.centroid
    h0, h1, h2 = k.home_centroid
    return [(r0 * c0 + r1 * c1 + r2 * c2 + t0) - h0,
            (r3 * c0 + r4 * c1 + r5 * c2 + t1) - h1,
            (r6 * c0 + r7 * c1 + r8 * c2 + t2) - h2]


def _top_translation(model: ControlModel, T: np.ndarray) -> np.ndarray:
    """:func:`top_motion`'s ``[dx, dy, dz]`` as an array (:func:`_translation_list`)."""
    return np.array(_translation_list(model, np.asarray(T, dtype=float)))


def _rotation_clear(envelope: Envelope, model: ControlModel, T: np.ndarray) -> bool:
    """True when the top's rotation from home is so small that no component of
    :func:`top_motion`'s rotation vector can exceed its range: its angle (from the trace,
    ``cos θ = (tr R − 1) / 2``, ``tr(R R_homeᵀ) = Σ R_ij R_home,ij``), which bounds every
    component, is below the smallest rotation range by 1e-6° (more than the two computations'
    rounding apart). :func:`check_motion` then needs no rotation vector — the same verdicts,
    without SciPy's conversion."""
    H = _consts(model).H_rot
    tr = 0.0
    for row, hrow in zip(T[:3, :3].tolist(), H, strict=True):
        tr += row[0] * hrow[0] + row[1] * hrow[1] + row[2] * hrow[2]
    c = (tr - 1.0) / 2.0
    angle = math.degrees(math.acos(min(1.0, max(-1.0, c))))
    return angle + 1e-6 < min(envelope.motion_range[3:])


_MOTION_NAMES = ("x", "y", "z", "about x", "about y", "about z")


def check_motion(envelope: Envelope, model: ControlModel, top_pose, what: str) -> list[str]:
    """Violations of Table 3-1's motion ranges by the top at ``top_pose`` (``what``: "measured"
    or "predicted")."""
    T = np.asarray(top_pose, dtype=float)
    if _rotation_clear(envelope, model, T):  # no rotation component can be out of range
        m = _translation_list(model, T) + [0.0, 0.0, 0.0]
    else:
        m = top_motion(model, T).tolist()
    out = []
    for k, (v, lim) in enumerate(zip(m, envelope.motion_range, strict=True)):
        if abs(v) > lim:
            unit = "mm" if k < 3 else "°"
            out.append(f"{what} top motion {_MOTION_NAMES[k]} {v:+.3f} {unit} is beyond the "
                       f"±{lim:g} {unit} range (Vibhute Table 3-1)")
    return out


def _norm3(v) -> float:
    """``|v|`` of a 3-vector in scalars."""
    a, b, c = v.tolist()
    return math.sqrt(a * a + b * b + c * c)


def _largest(values: list[float]) -> int:
    """Index of the largest ``|v|`` (the first of equals, as :func:`numpy.argmax`)."""
    k, best = 0, abs(values[0])
    for i in range(1, len(values)):
        if abs(values[i]) > best:
            k, best = i, abs(values[i])
    return k


def check_target(envelope: Envelope, force_target) -> list[str]:
    """Violations of the requested force itself (before anything moves)."""
    F = float(np.linalg.norm(np.asarray(force_target, dtype=float)))
    if not math.isfinite(F):
        return ["the requested force is not finite"]
    if F > envelope.max_load:
        return [f"the requested force {F:.3g} N exceeds the platform's load limit "
                f"{envelope.max_load:g} N (Vibhute Table 3-1)"]
    return []


def _shaped(a, shape: tuple) -> np.ndarray | None:
    """``a`` as a writeable C float array of ``shape`` (:func:`_c`), or None."""
    if not isinstance(a, np.ndarray) or a.shape != shape:
        return None
    return _c(a)


def _measurement_clear_compiled(envelope: Envelope, model: ControlModel,
                                meas: Measurement) -> bool:
    """True when :func:`check_measurement` would find nothing, decided compiled with a margin
    (:func:`kinestat.control._cycle_kernels.measurement_clear_kernel`); False when it may
    find something (the checks in Python then run and say what)."""
    w, lengths, T = (_shaped(meas.wrench, (6,)), _shaped(meas.leg_lengths, (6,)),
                     _shaped(meas.top_pose, (4, 4)))
    if w is None or lengths is None or T is None:
        return False
    k = _consts(model)
    mr, rot_min = _ranges(envelope.motion_range)
    return bool(measurement_clear_kernel(
        w, lengths, k.free_lengths_array, T, k.H_rot_array, k.centroid_array,
        k.home_centroid_array, mr, rot_min, float(envelope.max_load),
        float(envelope.max_deflection)))


def _command_clear_compiled(envelope: Envelope, model: ControlModel, axis_deg_new,
                            axis_deg_now, prediction: Prediction | None) -> bool:
    """True when :func:`check_command` would find nothing, decided compiled with a margin
    (:func:`kinestat.control._cycle_kernels.command_clear_kernel`); False when it may find
    something (the checks in Python then run and say what)."""
    a = _shaped(axis_deg_new, (6,))
    now = None if axis_deg_now is None else _shaped(axis_deg_now, (6,))
    if a is None or (axis_deg_now is not None and now is None):
        return False
    f = d = T = None
    if prediction is not None:
        f, d = _shaped(prediction.force, (3,)), _shaped(prediction.deflections, (6,))
        if f is None or d is None:
            return False
        if prediction.top_pose is not None:
            T = _shaped(prediction.top_pose, (4, 4))
            if T is None:
                return False
    k = _consts(model)
    mr, rot_min = _ranges(envelope.motion_range)
    return bool(command_clear_kernel(
        a, _UNUSED6 if now is None else now, now is not None, k.lo_array, k.hi_array,
        float(envelope.max_joint_step_deg), _UNUSED3 if f is None else f,
        _UNUSED6 if d is None else d, _UNUSED44 if T is None else T, prediction is not None,
        T is not None, k.H_rot_array, k.centroid_array, k.home_centroid_array, mr, rot_min,
        float(envelope.max_load), float(envelope.max_deflection)))


# placeholders for the arguments a pre-check does not read (writeable: one array type)
_UNUSED3, _UNUSED6, _UNUSED44 = np.zeros(3), np.zeros(6), np.zeros((4, 4))
_RANGES: dict[tuple, tuple[np.ndarray, float]] = {}


def _ranges(motion_range: tuple) -> tuple[np.ndarray, float]:
    """The motion ranges (6,) as an array and the least rotation range, made once per tuple."""
    got = _RANGES.get(motion_range)
    if got is None:
        got = _RANGES[motion_range] = (np.array(motion_range, dtype=float),
                                       min(motion_range[3:]))
    return got


#: the checks' compiled pre-checks (on the reference path: never clear, the Python checks run)
_measurement_clear = _measurement_clear_compiled
_command_clear = _command_clear_compiled


def check_measurement(envelope: Envelope, model: ControlModel, meas: Measurement) -> list[str]:
    """Violations in a measurement: load and leg deflections beyond the envelope. A
    measurement clearly inside (the compiled pre-check, with a margin of 1e-9 relative) has
    none; any other is checked here, value by value."""
    if _measurement_clear(envelope, model, meas):
        return []
    out = []
    w = np.asarray(meas.wrench, dtype=float).tolist()
    lengths = np.asarray(meas.leg_lengths, dtype=float).tolist()
    if not all(map(math.isfinite, w + lengths)):
        return ["the measurement contains NaN or infinity"]
    F = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if F > envelope.max_load:
        out.append(f"measured load {F:.3g} N exceeds the limit {envelope.max_load:g} N")
    defl = [x - x0 for x, x0 in zip(lengths, _consts(model).free_lengths, strict=True)]
    k = _largest(defl)
    if abs(defl[k]) > envelope.max_deflection:
        out.append(f"leg {model.platform.leg_names[k]} is deflected {defl[k]:+.3f} mm, beyond "
                   f"±{envelope.max_deflection:g} mm")
    out += check_motion(envelope, model, meas.top_pose, "measured")
    return out


def check_command(envelope: Envelope, model: ControlModel, axis_deg_new, axis_deg_now,
                  prediction: Prediction | None) -> list[str]:
    """Violations of a command: axis limits, axis step, predicted load and deflections.

    ``axis_deg_new`` are the absolute axis angles that will be commanded (degrees, after
    rounding to counts); ``axis_deg_now`` the current ones. (Scalar arithmetic on Python
    floats: the checks run on every command.) A command clearly inside (the compiled
    pre-check, with a margin of 1e-9 relative) has no violations.
    """
    if _command_clear(envelope, model, axis_deg_new, axis_deg_now, prediction):
        return []
    out = []
    arr = np.asarray(axis_deg_new, dtype=float)
    a = arr.tolist()
    if arr.shape != (6,) or not all(map(math.isfinite, a)):
        return [f"commanded axis angles are not 6 finite numbers: {a}"]
    k = _consts(model)
    for j in range(6):
        if not k.lo[j] <= a[j] <= k.hi[j]:
            out.append(f"axis {j + 1} command {a[j]:.4f}° is outside its limits "
                       f"[{k.lo[j]:g}°, {k.hi[j]:g}°]")
    if axis_deg_now is not None:
        now = np.asarray(axis_deg_now, dtype=float).tolist()
        step = [abs(x - y) for x, y in zip(a, now, strict=True)]
        j = _largest(step)
        if step[j] > envelope.max_joint_step_deg:
            out.append(f"axis {j + 1} would move {step[j]:.3f}°{AXIS_STEP_VIOLATION}, more than "
                       f"{envelope.max_joint_step_deg:g}°")
    if prediction is not None:
        defl = prediction.deflections.tolist()
        if not all(map(math.isfinite, prediction.force.tolist() + defl)):
            return out + ["the predicted force or leg deflections are not finite"]
        F = prediction.force_magnitude
        if F > envelope.max_load:
            out.append(f"predicted load {F:.3g} N after the move exceeds the limit "
                       f"{envelope.max_load:g} N")
        j = _largest(defl)
        if abs(defl[j]) > envelope.max_deflection:
            out.append(f"leg {model.platform.leg_names[j]} would deflect {defl[j]:+.3f} mm "
                       f"after the move, beyond ±{envelope.max_deflection:g} mm")
        if prediction.top_pose is not None:
            out += check_motion(envelope, model, prediction.top_pose, "predicted")
    return out


def require(violations: list[str], what: str = "safety envelope") -> None:
    """Raise :class:`SafetyStop` listing ``violations`` (no-op when empty)."""
    if violations:
        raise SafetyStop(f"{what}: " + "; ".join(violations))


def check_sent_counts(envelope: Envelope, model: ControlModel, sent_counts,
                      counts_now) -> list[str]:
    """Violations of the counts actually sent to the motion controller (after the axis 4 -> 5
    compensation changed axis 5): axis limits and the per-command step of every axis,
    measured from the encoder positions read just before (:func:`check_command`)."""
    res = np.asarray(model.axis_deg_per_count, dtype=float)
    sent = np.asarray(sent_counts, dtype=float) * res
    now = None if counts_now is None else np.asarray(counts_now, dtype=float) * res
    return check_command(envelope, model, sent, now, None)


def sent_command_guard(envelope: Envelope, model: ControlModel):
    """A ``guard(sent_counts, counts_now)`` for the device side
    (:class:`kinestat.devices.cell_io.DeviceIO`): raises :class:`SafetyStop` on
    :func:`check_sent_counts`'s violations, so nothing outside the envelope is ever sent."""
    def guard(sent_counts, counts_now) -> None:
        require(check_sent_counts(envelope, model, sent_counts, counts_now),
                "final command (axis 5 compensated)")
    return guard
