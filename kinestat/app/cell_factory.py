"""The cell factory of ``kinestat control``: one prepared run
(:class:`~kinestat.app.control_run.PreparedRun`) in, the cell the loop talks to out — a
:class:`~kinestat.control.loop.CellIO` of

- the built-in contact simulator behind the simulated Galil and encoder box
  (:class:`~kinestat.app.sim_cell.SimHarness`), or in process with another arm
  (:func:`~kinestat.app.arm_cell.arm_io`);
- MuJoCo's rigid-body dynamics and contact, in process
  (:class:`~kinestat.app.mujoco_cell.MujocoIO`);
- the real Galil and encoder stream (:class:`~kinestat.devices.cell_io.DeviceIO`).

Every cell sends each final command (axis 5 compensated) through the envelope's guard
(:func:`~kinestat.control.envelope.sent_command_guard`).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from kinestat.app.arm_cell import arm_io
from kinestat.app.sim_cell import SimHarness, start_counts
from kinestat.control.envelope import sent_command_guard
from kinestat.control.runspec import SimulatedCell
from kinestat.devices.cell_io import DeviceIO
from kinestat.devices.encoder_stream import EncoderReader
from kinestat.devices.galil import GalilClient
from kinestat.devices.homing import is_homed

__all__ = ["NotReady", "open_cell"]


@dataclass(frozen=True)
class NotReady:
    """A cell that must not move (e.g. a robot not homed in this controller session): why."""

    reason: str


@contextmanager
def open_cell(prepared) -> Iterator[object]:
    """The prepared run's cell, started and connected (closed on exit), or :class:`NotReady`."""
    spec, config = prepared.request, prepared.config
    guard = sent_command_guard(config.envelope, config.model)
    if prepared.plant is not None:
        from kinestat.app.mujoco_cell import MujocoIO  # lazy: mujoco only for --sim mujoco

        yield MujocoIO(prepared.plant, config.model, prepared.sensor,
                       move_rule=spec.move_rule, guard=guard, seed=spec.cell.seed)
    elif prepared.arm is not None:
        yield arm_io(prepared.cell, prepared.sensor, prepared.arm, seed=spec.cell.seed,
                     guard=guard)
    elif isinstance(spec.cell, SimulatedCell):
        with SimHarness(prepared.cell, prepared.sensor, start_counts=start_counts(config),
                        rate_hz=spec.cell.rate_hz, seed=spec.cell.seed) as h:
            yield h.device_io(samples=spec.samples, guard=guard,
                              max_stream_faults=config.envelope.max_stream_faults,
                              move_rule=spec.move_rule)
    else:
        with _devices(spec, guard, config.envelope.max_stream_faults) as io:
            yield io


@contextmanager
def _devices(spec, guard, max_stream_faults: int) -> Iterator[object]:
    """The real Galil and encoder stream, or :class:`NotReady` for an unhomed robot."""
    d = spec.cell
    client = GalilClient(d.host, d.port).connect()
    try:
        if not spec.assume_homed and not is_homed(client):
            yield NotReady(f"the robot behind the Galil at {d.host}:{d.port} is not homed in "
                           "this controller session: run `kinestat home --galil "
                           f"{d.host}:{d.port}` first (or pass --assume-homed); nothing moved")
            return
        with EncoderReader(d.serial, fmt=d.serial_format) as reader:
            yield DeviceIO(client, reader, samples=spec.samples, settle=0.1, guard=guard,
                           max_stream_faults=max_stream_faults, move_rule=spec.move_rule)
    finally:
        client.close()
