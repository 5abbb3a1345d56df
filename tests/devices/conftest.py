"""Fixtures shared by the Galil tests: a simulated DMC on loopback and a client connected to it."""

from __future__ import annotations

import pytest

from kinestat.devices.galil import GalilClient
from kinestat.sim.dmc import DmcSimulator, SimClock
from kinestat.sim.galil_server import GalilSimServer


@pytest.fixture
def sim():
    """The Galil simulator (simulated clock, 2 ms per command, commands recorded), served on
    loopback for the test."""
    ctrl = DmcSimulator(clock=SimClock(step_per_command=0.002), record=True)
    with GalilSimServer(controller=ctrl) as server:
        yield server


@pytest.fixture
def client(sim):
    """A :class:`GalilClient` connected to :func:`sim`. Its reply timeout is generous: on a
    loaded 2-core machine the simulator's thread can wait over a second for a core, and
    the tests of the timeout itself use their own clients."""
    with GalilClient("127.0.0.1", sim.port, timeout=5.0) as g:
        yield g
