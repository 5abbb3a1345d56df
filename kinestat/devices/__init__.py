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

from kinestat.devices.cell_io import DeviceIO, MotionProfile, SensorSample
from kinestat.devices.encoder_stream import (
    EncoderReader,
    Packet,
    Reading,
    StaleDataError,
    StreamFault,
    StreamParser,
    decode_legacy_line,
    decode_packet,
    encode_legacy_line,
    encode_packet,
)
from kinestat.devices.galil import GalilClient, GalilCommandError, thesis_move_plan

__all__ = [
    "DeviceIO",
    "EncoderReader",
    "GalilClient",
    "GalilCommandError",
    "MotionProfile",
    "Packet",
    "Reading",
    "SensorSample",
    "StaleDataError",
    "StreamFault",
    "StreamParser",
    "decode_legacy_line",
    "decode_packet",
    "encode_legacy_line",
    "encode_packet",
    "thesis_move_plan",
]
