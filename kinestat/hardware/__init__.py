"""The cell's hardware conventions (Vibhute 2011): facts about the robot and the platform's
sensors that decisions, drivers and simulators share. No I/O, no decisions.

- :mod:`kinestat.hardware.puma762_axes` — the PUMA 762's encoder scales, joint-1 offset,
  axis 4 -> 5 coupling and its compensation, rounding to counts, the thesis tool point
  ``P_tool_6``.
- :mod:`kinestat.hardware.encoder_packets` — the encoder box's wire formats (``ks`` and the
  thesis's legacy line) and its channel -> leg wiring: the codec shared by the reader
  (:mod:`kinestat.devices`) and the emitter (:mod:`kinestat.sim`).
- :mod:`kinestat.hardware.leg_calibration` — the platform's leg encoders: counts -> leg length
  and counts -> leg force maps, and calibration fitting.

Imported by :mod:`kinestat.control`, :mod:`kinestat.devices` and :mod:`kinestat.sim` alike.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
    from kinestat.hardware.leg_calibration import (
        MM_PER_COUNT,
        THESIS_CALIBRATION,
        LegCalibration,
        counts_to_forces,
        counts_to_lengths,
        lengths_to_counts,
    )
    from kinestat.hardware.puma762_axes import (
        AXIS4_TO_5_COUPLING,
        AXIS_DEG_PER_COUNT,
        THESIS_TOOL_POINT_6,
        axis45_compensation,
        axis_deg_to_counts,
        counts_to_joint_rad,
        joint_rad_to_counts,
        round_half_away,
    )

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "MM_PER_COUNT": ("kinestat.hardware.leg_calibration", "MM_PER_COUNT"),
    "THESIS_CALIBRATION": ("kinestat.hardware.leg_calibration", "THESIS_CALIBRATION"),
    "LegCalibration": ("kinestat.hardware.leg_calibration", "LegCalibration"),
    "counts_to_forces": ("kinestat.hardware.leg_calibration", "counts_to_forces"),
    "counts_to_lengths": ("kinestat.hardware.leg_calibration", "counts_to_lengths"),
    "lengths_to_counts": ("kinestat.hardware.leg_calibration", "lengths_to_counts"),
    "AXIS4_TO_5_COUPLING": ("kinestat.hardware.puma762_axes", "AXIS4_TO_5_COUPLING"),
    "AXIS_DEG_PER_COUNT": ("kinestat.hardware.puma762_axes", "AXIS_DEG_PER_COUNT"),
    "THESIS_TOOL_POINT_6": ("kinestat.hardware.puma762_axes", "THESIS_TOOL_POINT_6"),
    "axis45_compensation": ("kinestat.hardware.puma762_axes", "axis45_compensation"),
    "axis_deg_to_counts": ("kinestat.hardware.puma762_axes", "axis_deg_to_counts"),
    "counts_to_joint_rad": ("kinestat.hardware.puma762_axes", "counts_to_joint_rad"),
    "joint_rad_to_counts": ("kinestat.hardware.puma762_axes", "joint_rad_to_counts"),
    "round_half_away": ("kinestat.hardware.puma762_axes", "round_half_away"),
}

__all__ = [
    "AXIS4_TO_5_COUPLING",
    "AXIS_DEG_PER_COUNT",
    "MM_PER_COUNT",
    "THESIS_CALIBRATION",
    "THESIS_TOOL_POINT_6",
    "LegCalibration",
    "axis45_compensation",
    "axis_deg_to_counts",
    "counts_to_forces",
    "counts_to_joint_rad",
    "counts_to_lengths",
    "joint_rad_to_counts",
    "lengths_to_counts",
    "round_half_away",
]


def __getattr__(name: str) -> Any:
    """Load a public name's module on first use (PEP 562): importing the package stays cheap."""
    where = _LAZY.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = importlib.import_module(where[0])
    value = module if where[1] is None else getattr(module, where[1])
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
