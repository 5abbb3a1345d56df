"""Shared scenarios for the controller tests: the thesis's experiment in a simulated cell."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from kinestat.app.sim_cell import InProcessIO, control_model, start_counts
from kinestat.control.controller import THESIS_FORCE_DIRECTION, ControllerConfig
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import run
from kinestat.control.model import ControlModel
from kinestat.parallel.platform import special_6_6
from kinestat.sim.contact import Cell, make_cell
from kinestat.sim.sensor import Sensor, ideal_sensor

PLATFORM = special_6_6()
START = np.array([-400.0, 800.0, -100.0])
F_HAT = np.asarray(THESIS_FORCE_DIRECTION)
Y = np.array([0.0, 1.0, 0.0])


@dataclass
class Scenario:
    cell: Cell
    sensor: Sensor
    model: ControlModel

    def config(self, **kw) -> ControllerConfig:
        kw.setdefault("force", 4.0 * F_HAT)
        kw.setdefault("start_tool_point", START)
        return ControllerConfig(model=self.model, **kw)


def scenario(*, distance: float = 2.5, tilt_deg: float = 5.0, azimuth_deg: float = 90.0,
             friction: float = 0.0, ideal: bool = False, noise: float = 0.0,
             coupling: float = 0.0) -> Scenario:
    """The workpiece ``distance`` mm ahead of the start tool point along F_req, its normal
    tilted by ``tilt_deg`` (azimuth 90° = towards +y, the CLI's default)."""
    u = np.array([0.2375, 0.0, 0.9713]) / math.hypot(0.2375, 0.9713)
    v = np.cross(F_HAT, u)
    a = math.radians(azimuth_deg)
    perp = math.cos(a) * u - math.sin(a) * v  # azimuth 90° -> +y
    t = math.radians(tilt_deg)
    n = -(math.cos(t) * F_HAT + math.sin(t) * perp)
    cell = make_cell(PLATFORM, plane_point=START + distance * F_HAT, plane_normal=n,
                     friction=friction)
    sensor = ideal_sensor() if ideal else Sensor(noise=noise)
    return Scenario(cell, sensor, control_model(cell, sensor, coupling=coupling))


@pytest.fixture
def default_scenario() -> Scenario:
    return scenario()


def run_in_process(scn: Scenario, config: ControllerConfig, log_path, **io_kw):
    """Run the controller on the in-process cell; return (report, log records, io)."""

    io = InProcessIO(scn.cell, scn.sensor, start_counts=start_counts(config), **io_kw)
    with CycleLog(log_path) as log:
        report = run(config, io, log)
    return report, read_log(log_path), io
