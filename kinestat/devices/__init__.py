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

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
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

# public name -> (module, attribute or None for a submodule), imported on first use
_LAZY: dict[str, tuple[str, str | None]] = {
    "DeviceIO": ("kinestat.devices.cell_io", "DeviceIO"),
    "MotionProfile": ("kinestat.devices.cell_io", "MotionProfile"),
    "SensorSample": ("kinestat.devices.cell_io", "SensorSample"),
    "EncoderReader": ("kinestat.devices.encoder_stream", "EncoderReader"),
    "Packet": ("kinestat.devices.encoder_stream", "Packet"),
    "Reading": ("kinestat.devices.encoder_stream", "Reading"),
    "StaleDataError": ("kinestat.devices.encoder_stream", "StaleDataError"),
    "StreamFault": ("kinestat.devices.encoder_stream", "StreamFault"),
    "StreamParser": ("kinestat.devices.encoder_stream", "StreamParser"),
    "decode_legacy_line": ("kinestat.devices.encoder_stream", "decode_legacy_line"),
    "decode_packet": ("kinestat.devices.encoder_stream", "decode_packet"),
    "encode_legacy_line": ("kinestat.devices.encoder_stream", "encode_legacy_line"),
    "encode_packet": ("kinestat.devices.encoder_stream", "encode_packet"),
    "GalilClient": ("kinestat.devices.galil", "GalilClient"),
    "GalilCommandError": ("kinestat.devices.galil", "GalilCommandError"),
    "thesis_move_plan": ("kinestat.devices.galil", "thesis_move_plan"),
}

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
