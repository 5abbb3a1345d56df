"""The cell's hardware conventions (Vibhute 2011): facts about the platform's sensors that
decisions, drivers and simulators share. No I/O, no decisions. The robot's own conventions
(encoder scales, joint-1 offset, axis 4 -> 5 coupling, homing) are in its package,
:mod:`kinestat.robots.puma762`; ``puma762_axes`` and ``puma762_homing`` here are deprecated
import paths re-exporting them.

- :mod:`kinestat.hardware.encoder_packets` — the encoder box's wire formats (``ks`` and the
  thesis's legacy line) and its channel -> leg wiring: the codec shared by the reader
  (:mod:`kinestat.devices`) and the emitter (:mod:`kinestat.sim`).
- :mod:`kinestat.hardware.leg_calibration` — the platform's leg encoders: counts -> leg length
  and counts -> leg force maps, and calibration fitting.

Imported by :mod:`kinestat.control`, :mod:`kinestat.devices` and :mod:`kinestat.sim` alike.
"""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'leg_calibration': [
            'LegCalibration', 'MM_PER_COUNT', 'THESIS_CALIBRATION', 'counts_to_forces',
            'counts_to_lengths', 'lengths_to_counts',
        ],
        'puma762_axes': [
            'AXIS4_TO_5_COUPLING', 'AXIS_DEG_PER_COUNT', 'THESIS_TOOL_POINT_6',
            'axis45_compensation', 'axis_deg_to_counts', 'counts_to_joint_rad',
            'joint_rad_to_counts', 'round_half_away',
        ],
    },
)
