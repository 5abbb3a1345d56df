"""Stand-ins for the cell's hardware, for tests, demos and development without the robot.

- :mod:`kinestat.sim.galil_server` — a simulated Galil DMC controller served over TCP
  (loopback only unless told otherwise), with trapezoidal profiles, the PUMA's axis 4 -> 5
  coupling, simulated or real time and fault injection.
- :mod:`kinestat.sim.encoder_emitter` — a simulated encoder box streaming packets onto a
  pseudo-terminal, with fault injection.
"""

from kinestat.sim.encoder_emitter import EncoderEmitter, constant_counts
from kinestat.sim.galil_server import DmcSimulator, GalilSimServer, SimClock

__all__ = ["DmcSimulator", "EncoderEmitter", "GalilSimServer", "SimClock", "constant_counts"]
