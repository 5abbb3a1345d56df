"""The safety envelope of the kinestatic controller: limits and verdicts.

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

Loads, deflections and the top's motion are checked on every measurement AND on the prediction
of every command before it is sent (:func:`check_command`; the predictions are the plant model's,
:mod:`kinestat.control.predict`). The pinned tip of :func:`kinestat.control.predict.predict`
bounds the load, not the top's motion: a frictionless tip that runs on a tight convex surface
(an R = 100 mm cylinder at 4 N, docs/control.md "Limits") carried the top 0.01–0.03° past the
4° range after commands predicted inside it; the next measurement's check stopped the run there.

Every check returns a list of violations (empty: safe); :func:`require` turns them into a
:class:`~kinestat.errors.SafetyStop`.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial.transform import Rotation

from kinestat.control.model import ControlModel
from kinestat.control.wrench import Measurement
from kinestat.errors import InputError, SafetyStop
from kinestat.hardware.platform_spec import MAX_DEFLECTION, MAX_LOAD, MOTION_RANGE

if TYPE_CHECKING:
    from kinestat.control.predict import Prediction

__all__ = [
    "MAX_DEFLECTION",
    "MAX_LOAD",
    "MOTION_RANGE",
    "AXIS_STEP_VIOLATION",
    "Envelope",
    "top_motion",
    "check_motion",
    "check_target",
    "check_measurement",
    "check_deflection",
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




def top_motion(model: ControlModel, top_pose) -> np.ndarray:
    """The top's motion from its unloaded pose (Table 3-1's quantities), base frame: (6,)
    ``[dx, dy, dz]`` (mm) of the top triangle's centroid and ``[rx, ry, rz]`` (degrees), the
    rotation vector of ``R_top R_home⁻¹``."""
    T = np.asarray(top_pose, dtype=float)
    H = model.platform.home_pose
    r = Rotation.from_matrix(T[:3, :3] @ H[:3, :3].T).as_rotvec(degrees=True)
    return np.concatenate([_top_translation(model, T), r])


class _Consts:
    """A model's constants of the checks as Python floats, made once per model."""

    def __init__(self, model: ControlModel) -> None:
        H = model.platform.home_pose
        c = model.platform.top_points.mean(axis=0)
        self.centroid = c.tolist()
        self.home_centroid = (H[:3, :3] @ c + H[:3, 3]).tolist()
        self.lo = model.limits_deg[:, 0].tolist()
        self.hi = model.limits_deg[:, 1].tolist()
        self.free_lengths = model.platform.free_lengths.tolist()


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


_MOTION_NAMES = ("x", "y", "z", "about x", "about y", "about z")


def check_motion(envelope: Envelope, model: ControlModel, top_pose, what: str) -> list[str]:
    """Violations of Table 3-1's motion ranges by the top at ``top_pose`` (``what``: "measured"
    or "predicted")."""
    T = np.asarray(top_pose, dtype=float)
    m = top_motion(model, T).tolist()
    out = []
    for k, (v, lim) in enumerate(zip(m, envelope.motion_range, strict=True)):
        if abs(v) > lim:
            unit = "mm" if k < 3 else "°"
            out.append(f"{what} top motion {_MOTION_NAMES[k]} {v:+.3f} {unit} is beyond the "
                       f"±{lim:g} {unit} range (Vibhute Table 3-1)")
    return out


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


def check_measurement(envelope: Envelope, model: ControlModel, meas: Measurement) -> list[str]:
    """Violations in a measurement: load, leg deflections and the top's motion beyond the
    envelope."""
    out = []
    w = np.asarray(meas.wrench, dtype=float).tolist()
    lengths = np.asarray(meas.leg_lengths, dtype=float).tolist()
    if not all(map(math.isfinite, w + lengths)):
        return ["the measurement contains NaN or infinity"]
    F = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if F > envelope.max_load:
        out.append(f"measured load {F:.3g} N exceeds the limit {envelope.max_load:g} N")
    out += check_deflection(envelope, model, lengths)
    out += check_motion(envelope, model, meas.top_pose, "measured")
    return out


def check_deflection(envelope: Envelope, model: ControlModel, lengths) -> list[str]:
    """The most deflected leg beyond ``max_deflection`` (mm), as a one-item list, for leg
    lengths ``(6,)`` (mm, the platform's leg order); finite lengths expected."""
    lengths = np.asarray(lengths, dtype=float).tolist()
    defl = [x - x0 for x, x0 in zip(lengths, _consts(model).free_lengths, strict=True)]
    k = _largest(defl)
    if abs(defl[k]) > envelope.max_deflection:
        return [f"leg {model.platform.leg_names[k]} is deflected {defl[k]:+.3f} mm, beyond "
                f"±{envelope.max_deflection:g} mm"]
    return []


def check_command(envelope: Envelope, model: ControlModel, axis_deg_new, axis_deg_now,
                  prediction: Prediction | None) -> list[str]:
    """Violations of a command: axis limits, axis step, predicted load and deflections.

    ``axis_deg_new`` are the absolute axis angles that will be commanded (degrees, after
    rounding to counts); ``axis_deg_now`` the current ones.
    """
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
