"""Talking to the cell's hardware: the drivers between the controller's loop and the world.

- :mod:`kinestat.devices.encoder_stream` — the platform's encoder packets (codec, incremental
  parser, serial reader with stale-data detection).
- :mod:`kinestat.devices.galil` — the Galil DMC TCP client and the thesis's move recipe.
- :mod:`kinestat.devices.cell_io` — :class:`DeviceIO` and :class:`MotionProfile`: the device-side
  implementation of the loop's :class:`kinestat.control.loop.CellIO` protocol.
- :mod:`kinestat.devices.calibration` — old path of :mod:`kinestat.hardware.leg_calibration`
  (kept: documented in docs/platform.md).

The robot's axis conventions and the leg calibration are in :mod:`kinestat.hardware`. Nothing
here decides what to do (:mod:`kinestat.control` does) and nothing here imports
:mod:`kinestat.control` or :mod:`kinestat.sim`.
"""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'cell_io': ['DeviceIO', 'MotionProfile', 'SensorSample'],
        'encoder_stream': [
            'EncoderReader', 'Packet', 'Reading', 'StaleDataError', 'StreamFault', 'StreamParser',
            'decode_legacy_line', 'decode_packet', 'encode_legacy_line', 'encode_packet',
        ],
        'galil': ['GalilClient', 'GalilCommandError', 'thesis_move_plan'],
    },
)
