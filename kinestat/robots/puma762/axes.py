"""The PUMA 762's axis conventions in the Vibhute 2011 cell (hardware facts, no I/O).

* the encoder scales (degrees per count per axis A..F, ``ENC_DEG_1..6``, App. D.3, D.5);
* the joint-1 offset (``Pos_A_KCorrection`` = 180°, App. D.2/D.3) and the conversions between
  counts, axis degrees and joint angles in radians;
* rounding to whole counts the way the thesis's MATLAB does (halves away from zero);
* the axis 4 -> 5 coupling of that robot and its compensation (``Axis_4_5_Correction.m``,
  App. D.9);
* the thesis's tool point ``P_tool_6`` (App. D.1).

Imported by :mod:`kinestat.control` (decisions), :mod:`kinestat.devices` (the Galil driver) and
:mod:`kinestat.sim` (the simulated controller) alike.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from kinestat.errors import InputError

__all__ = [
    "AXES",
    "AXIS_DEG_PER_COUNT",
    "JOINT_OFFSET_DEG",
    "JOINT1_OFFSET_DEG",
    "AXIS4_TO_5_COUPLING",
    "COUNT_LIMIT",
    "THESIS_TOOL_POINT_6",
    "as_finite",
    "as_axes6",
    "round_half_away",
    "counts_to_axis_deg",
    "axis_deg_to_counts",
    "axis_deg_to_joint_rad",
    "joint_rad_to_axis_deg",
    "counts_to_joint_rad",
    "joint_rad_to_counts",
    "Axis45Correction",
    "axis45_compensation",
]

AXES = "ABCDEF"
"""Galil axis letters; axis A drives joint 1, ..., axis F joint 6."""

AXIS_DEG_PER_COUNT = np.array([0.00125, 0.00086875, 0.001115625, 0.00626, 0.00626, 0.01337])
"""Degrees of axis motion per encoder count, axes A..F (``ENC_DEG_1..6``, Vibhute App. D.3,
D.5). Checked: ``startup_initialize.m`` defines joints 2 and 3 at 90° with ``DP 0,103597,80672``
and 103597 x 0.00086875 = 89.9999°, 80672 x 0.001115625 = 89.9997°."""
AXIS_DEG_PER_COUNT.setflags(write=False)

JOINT_OFFSET_DEG = np.array([180.0, 0.0, 0.0, 0.0, 0.0, 0.0])
"""Joint angle minus axis angle, degrees (``Pos_A_KCorrection`` = 180 on joint 1, Vibhute App.
D.2/D.3): phi1 = axis_A + 180°."""
JOINT_OFFSET_DEG.setflags(write=False)

JOINT1_OFFSET_DEG = 180.0
"""``Pos_A_KCorrection``: joint 1 angle phi1 = axis-A angle + 180° (Vibhute App. D.3)."""

AXIS4_TO_5_COUPLING = -11200.0 / 23962.0
"""Physical axis-5 motion per axis-4 encoder count, in axis-5 counts (Vibhute App. D.9).

The thesis measured 11200 counts of axis 5 (70.1°) for 23962 counts of axis 4 (150.0°) and
calls the ratio ``Compensation_Factor``. The sign follows from the thesis's correction formula
with its two OCR-dropped minus signs restored, ``E_cmd - (D_now - D_cmd) * 11200/23962``: that
formula cancels the coupling only if axis 5 turns by ``-11200/23962`` counts per count of
axis 4. The axis-5 encoder does not see this motion."""

COUNT_LIMIT = 2_147_483_647
"""Galil position registers are signed 32-bit."""

THESIS_TOOL_POINT_6 = np.array([0.0, 0.0, 235.0])
"""The thesis's unloaded tool point in frame 6, ``P_tool_6 = (0, 0, 235)`` mm (Vibhute App.
D.1): where the tip sits when the compliant platform is at home."""
THESIS_TOOL_POINT_6.setflags(write=False)


def as_finite(x: Any, name: str) -> np.ndarray:
    """``x`` as a float array, every value finite (else InputError naming ``name``)."""
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: expected numbers, got {x!r}") from exc
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name}: values must be finite, got {x!r}")
    return a


def as_axes6(x: Any, name: str) -> np.ndarray:
    """``x`` as finite floats of shape (..., 6), axes A..F (else InputError naming ``name``)."""
    a = as_finite(x, name)
    if a.ndim == 0 or a.shape[-1] != 6:
        raise InputError(f"{name}: expected shape (..., 6) for axes A..F, got {a.shape}")
    return a


def round_half_away(x: Any) -> np.ndarray:
    """Round to the nearest integer, halves away from zero (MATLAB's ``round``), as int64."""
    a = np.asarray(x, dtype=float)
    return (np.sign(a) * np.floor(np.abs(a) + 0.5)).astype(np.int64)


def counts_to_axis_deg(counts: Any) -> np.ndarray:
    """Axis angles in degrees from encoder counts, shape (..., 6) (``Pos = PosE * ENC_DEG``)."""
    return as_axes6(counts, "counts_to_axis_deg") * AXIS_DEG_PER_COUNT


def axis_deg_to_counts(axis_deg: Any) -> np.ndarray:
    """Encoder counts (int64) from axis angles in degrees (``En = round(Deg / ENC_DEG)``)."""
    c = as_axes6(axis_deg, "axis_deg_to_counts") / AXIS_DEG_PER_COUNT
    if np.any(np.abs(c) > COUNT_LIMIT):
        raise InputError("axis_deg_to_counts: a position exceeds the Galil's 32-bit range")
    return round_half_away(c)


def axis_deg_to_joint_rad(axis_deg: Any) -> np.ndarray:
    """Joint angles q (radians, Crane-Duffy convention) from axis angles: q = axis + offset."""
    return np.deg2rad(as_axes6(axis_deg, "axis_deg_to_joint_rad") + JOINT_OFFSET_DEG)


def joint_rad_to_axis_deg(q: Any) -> np.ndarray:
    """Axis angles in degrees from joint angles q: axis = q - offset (no wrapping).

    Which multiple of 360° an axis should take (limits, least motion) is the caller's choice;
    the thesis adds +180° to phi1, which equals -180° modulo 360°.
    """
    return np.rad2deg(as_axes6(q, "joint_rad_to_axis_deg")) - JOINT_OFFSET_DEG


def counts_to_joint_rad(counts: Any) -> np.ndarray:
    """Joint angles q (radians) from encoder counts A..F."""
    return axis_deg_to_joint_rad(counts_to_axis_deg(counts))


def joint_rad_to_counts(q: Any) -> np.ndarray:
    """Encoder counts A..F (int64) for joint angles q (radians), joint 1 offset applied."""
    return axis_deg_to_counts(joint_rad_to_axis_deg(q))


class Axis45Correction(NamedTuple):
    """Result of :func:`axis45_compensation`: the axis-5 command and ``DP`` value (counts,
    int64 arrays or scalars) and the fraction of a count the true axis 5 ends past the reset
    value (float; the ``carry`` of the next move)."""

    axis5_command: np.ndarray
    axis5_reset: np.ndarray
    residual: np.ndarray | float = 0.0


def axis45_compensation(
    axis4_target: Any, axis5_target: Any, axis4_now: Any,
    coupling: float = AXIS4_TO_5_COUPLING, carry: Any = 0.0,
) -> Axis45Correction:
    """Compensate the PUMA's axis 4 -> 5 coupling (Vibhute App. D.9 ``Axis_4_5_Correction.m``).

    Moving axis 4 by ``d4 = axis4_target - axis4_now`` counts turns axis 5 by ``coupling*d4``
    counts that its encoder does not see. Commanding axis 5 to
    ``axis5_target - coupling * d4`` (thesis: ``E_cmd + (D_cmd - D_now) * 11200/23962``) makes
    the true axis-5 position end at ``axis5_target``; afterwards the encoder reads the command,
    so it is reset with ``DP`` to ``axis5_reset = axis5_target``. All inputs are counts and may
    carry a leading batch shape; the command and reset are rounded (halves away from zero).

    The command is a whole count, so the true axis 5 ends ``residual`` =
    ``axis5_command + coupling * d4 - axis5_target`` past the reset value (|·| ≤ 0.5 for a
    whole-count target, as every move sends). The
    thesis discards it at every ``DP``; over many small axis-4 moves of one sense the
    fractions add up (20 counts, 0.13°, over a 50 mm follow run: 0.6 mm at the tool).
    ``carry`` is where the true axis 5 stood past its encoder before this move (the previous
    move's ``residual``): the command takes it off, so the true position stays within half a
    count of the encoder over any number of moves. Pass the returned ``residual`` to the next
    move (0 after homing, when the encoder agrees with the true position).

    >>> c = axis45_compensation(101, 0, 100)  # axis 4 by +1 count: axis 5 by -0.467
    >>> int(c.axis5_command), int(c.axis5_reset), round(float(c.residual), 3)
    (0, 0, -0.467)
    >>> c2 = axis45_compensation(102, 0, 101, carry=c.residual)  # the next count: -0.935 ...
    >>> int(c2.axis5_command), round(float(c2.residual), 3)  # ... so axis 5 is sent 1 count
    (1, 0.065)
    """
    d4 = as_finite(axis4_target, "axis4_target") - as_finite(axis4_now, "axis4_now")
    e = as_finite(axis5_target, "axis5_target")
    if not math.isfinite(coupling):
        raise InputError(f"axis45_compensation: coupling must be finite, got {coupling!r}")
    r0 = as_finite(carry, "carry")
    if np.any(np.abs(r0) > 0.5 + 1e-9):
        raise InputError(f"axis45_compensation: carry must be within half a count, got {carry!r}")
    cmd = round_half_away(e - coupling * d4 - r0)
    return Axis45Correction(cmd, round_half_away(e), cmd + coupling * d4 + r0 - e)
