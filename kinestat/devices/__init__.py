"""Talking to the cell's hardware: the I/O edge between the controller and the world.

- :mod:`kinestat.devices.encoder_stream` — the platform's encoder packets (codec, incremental
  parser, serial reader with stale-data detection).
- :mod:`kinestat.devices.galil` — the Galil DMC TCP client, the thesis's axis scales and
  offsets, and the PUMA's axis 4 -> 5 coupling compensation.
- :mod:`kinestat.devices.calibration` — encoder counts to leg lengths and forces.

Nothing here decides what to do; :mod:`kinestat.control` does.
"""

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
from kinestat.devices.galil import (
    GalilClient,
    GalilCommandError,
    axis45_compensation,
    axis_deg_to_counts,
    counts_to_axis_deg,
)

__all__ = [
    "EncoderReader",
    "GalilClient",
    "GalilCommandError",
    "Packet",
    "Reading",
    "StaleDataError",
    "StreamFault",
    "StreamParser",
    "axis45_compensation",
    "axis_deg_to_counts",
    "counts_to_axis_deg",
    "decode_legacy_line",
    "decode_packet",
    "encode_legacy_line",
    "encode_packet",
]
