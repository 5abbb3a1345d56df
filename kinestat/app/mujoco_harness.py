"""The MuJoCo cell behind the simulated devices: ``kinestat sim galil --plant mujoco``.

:class:`MujocoHarness` is :class:`~kinestat.app.sim_cell.SimHarness` with MuJoCo as the plant:
the simulated Galil (:class:`~kinestat.sim.dmc.DmcSimulator`, served on TCP) runs its
trapezoidal profiles and the PUMA's axis 4 → 5 coupling on a clock the plant drives; a thread
steps the :class:`~kinestat.sim.mujoco_plant.MujocoPlant` in real time, its joint servos
following the Galil's TRUE axis positions (coupling included, which the axis-5 encoder does not
see); the encoder emitter streams the leg counts of the same MuJoCo state
(:class:`~kinestat.sim.sensor.Sensor`). ``kinestat control --galil/--serial`` then runs the
whole stack — client, reader, the compensation of the coupling, the envelope — against MuJoCo.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np

from kinestat.app.mujoco_cell import counts_to_q
from kinestat.app.sim_cell import (
    SIM_STALE_AFTER,
    DeviceWiring,
    SimCheckedReader,
    stop_devices,
)
from kinestat.control.model import ControlModel
from kinestat.devices.cell_io import DeviceIO
from kinestat.devices.encoder_stream import EncoderReader
from kinestat.devices.galil import GalilClient
from kinestat.errors import KinestatError
from kinestat.sim.dmc import DmcSimulator, SimClock
from kinestat.sim.encoder_emitter import EncoderEmitter
from kinestat.sim.galil_server import GalilSimServer
from kinestat.sim.mujoco_plant import MujocoPlant
from kinestat.sim.sensor import Sensor

__all__ = ["PLANT_CHUNK", "MujocoHarness"]

PLANT_CHUNK = 4
"""Plant steps between two reads of the Galil's axis positions (2 ms at the 0.5 ms step)."""


class MujocoHarness(DeviceWiring):
    """The simulated Galil and encoder box on one MuJoCo plant (context manager).

    ``plant``: the MuJoCo cell at the robot's start pose; ``model``: the controller's model of
    the robot (the axis convention); ``start_counts``: the Galil's axis counts there (homed by
    construction); ``host``/``port``: where the Galil listens (loopback unless
    ``allow_remote``); ``rate_hz``/``fmt``: the encoder stream; ``speed``: simulated seconds
    per wall second (1: real time)."""

    def __init__(self, plant: MujocoPlant, model: ControlModel, sensor: Sensor, *,
                 start_counts, host: str = "127.0.0.1", port: int = 0,
                 allow_remote: bool = False, rate_hz: float = 200.0, fmt="ks",
                 seed: int | None = 0, speed: float = 1.0) -> None:
        self.plant = plant
        self.model = model
        self.sensor = sensor
        self.clock = SimClock(start=plant.time)
        self.controller = DmcSimulator(clock=self.clock, initial_counts=start_counts,
                                       coupling=model.coupling)
        self.controller.variables["HOMED"] = 1.0
        self.server = GalilSimServer(host, port, allow_remote=allow_remote,
                                     controller=self.controller)
        self.emitter = EncoderEmitter(self.counts_now, rate_hz=rate_hz, fmt=fmt)
        self._rng = np.random.default_rng(seed)
        self.speed = float(speed)
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.error: KinestatError | None = None
        self._opened: list[Any] = []

    # -- the plant in time
    def _run(self) -> None:
        plant, dt = self.plant, self.plant.model.opt.timestep
        wall0, sim0 = time.monotonic(), plant.time
        try:
            while not self._stop.is_set():
                axis = self.controller.true_axis_counts()  # physical positions, coupling in
                plant.set_reference(counts_to_q(self.model, axis))
                plant.step(PLANT_CHUNK)
                self.clock.advance(PLANT_CHUNK * dt)
                ahead = (plant.time - sim0) / self.speed - (time.monotonic() - wall0)
                if ahead > 0:
                    time.sleep(ahead)
        except KinestatError as exc:  # the plant failed: the emitter reports it
            self.error = exc

    def counts_now(self) -> np.ndarray:
        """Leg counts of the MuJoCo state now, through the leg encoders."""
        if self.error is not None:
            raise self.error
        return self.sensor.counts(self.plant.scene.cell.platform, self.plant.leg_lengths(),
                                  self._rng)

    def truth(self) -> dict:
        """The true state now (MuJoCo's contact force; for the log)."""
        t = self.plant.truth()
        T = t.pop("flange_pose")
        t["tool_axis"] = T[:3, 2].copy()
        t["tool_point"] = T[:3, :3] @ self.model.tool_point_6 + T[:3, 3]
        t["normal"] = t["true_normal"]
        return t

    # -- life cycle
    def start(self) -> MujocoHarness:
        """Start the plant's thread, the Galil's server and the encoder emitter."""
        self._thread = threading.Thread(target=self._run, name="mujoco-plant", daemon=True)
        self._thread.start()
        self.server.start()
        try:
            self.emitter.start()
        except BaseException:
            self.server.stop()
            self.stop()
            raise
        return self

    def stop(self) -> None:
        """Close what it opened, stop the emitter, the server and the plant's thread."""
        stop_devices(self._opened, self.emitter, self.server)
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)

    def device_io(self, *, samples: int = 1, settle: float = 0.1, **kw: Any) -> DeviceIO:
        """A :class:`DeviceIO` through the real Galil client and encoder reader (closed with
        the harness), the truth attached; ``settle`` as the real cell's (s)."""
        host, port = self.galil_address
        client = GalilClient(host, port, timeout=2.0).connect()
        self._opened.append(client)
        reader = EncoderReader(self.serial_path, fmt=self.emitter.fmt,
                               stale_after=SIM_STALE_AFTER).open()
        self._opened.append(reader)
        kw.setdefault("truth", self.truth)
        return DeviceIO(client, SimCheckedReader(reader, self.emitter), samples=samples,
                        settle=settle, coupling=self.model.coupling, **kw)

    def describe(self) -> dict[str, Any]:
        """Where the devices are (for the CLI's announcement)."""
        host, port = self.galil_address
        return {"galil": f"{host}:{port}", "serial": self.serial_path, "plant": "mujoco",
                "rate_hz": self.emitter.rate_hz, "format": self.emitter.fmt}
