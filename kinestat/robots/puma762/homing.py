"""The PUMA 762's start-up and homing constants (Vibhute 2011 App. D.4, startup_initialize.m;
Table 2-1), shared by the homing procedure (:mod:`kinestat.devices.homing`) and the simulated
DMC (:mod:`kinestat.sim.dmc`).

startup_initialize.m homes the robot in four moves: a coarse move by the potentiometers
(``PR round((READYPOT − pot) · POT_ENCSCALE)``, the pots averaged over 100 readings), an index
search (``FI``, which zeroes each encoder at its next index mark), an absolute move
(:data:`FIRST_OFFSET`), a second, slower index search, a final absolute move
(:data:`SECOND_OFFSET`) and ``DP`` :data:`HOME_COUNTS` — the home pose, axes 0°, 90°, 90°, 0°,
0°, 0°.

Index marks come once per motor revolution: Table 2-1's "encoder index resolution" 4.0°, 2.78°,
3.57°, 6.26°, 6.26°, 13.4° divided by the encoder scales 0.00125, 0.00086875, 0.001115625,
0.00626, 0.00626, 0.01337 °/count gives 3200, 3200, 3200, 1000, 1000, 1002 counts; the joint
angular resolution of axis 6 (13.4e-3°) gives exactly 1000, so :data:`INDEX_PERIOD_COUNTS` is
(3200, 3200, 3200, 1000, 1000, 1000).

The ``PA`` offsets' signs are taken as printed (all positive). The seed's OCR drops minus signs
elsewhere in this listing; the computation in docs/seed-errata-vibhute.md ("Homing's PA
offsets") shows that the seed cannot decide them (every reading homes alike on a robot laid out
for it) and gives the pot voltages at home that tell the readings apart on the robot. The
simulated robot has its own layout (:mod:`kinestat.robots.puma762.layout`), not derived from
these offsets.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "READY_POT_V",
    "POT_COUNTS_PER_V",
    "INDEX_PERIOD_COUNTS",
    "FIRST_OFFSET",
    "SECOND_OFFSET",
    "HOME_COUNTS",
    "COARSE_JOG",
    "COARSE_ACCEL",
    "COARSE_SPEED",
    "FIRST_SEARCH_SPEED",
    "SECOND_SEARCH_SPEED",
]


def _ro(a, dtype=float) -> np.ndarray:
    out = np.array(a, dtype=dtype)
    out.setflags(write=False)
    return out


READY_POT_V = _ro([2.500, 2.525, 2.566, 2.538, 2.512, 2.512])
"""``READYPOT_1..6``: the pots' voltages at the ready position (V)."""
POT_COUNTS_PER_V = _ro([77220, 75188, 75301, 23866, 24079, 24036])
"""``POT_ENCSCALE_1..6``: encoder counts per volt of pot."""
INDEX_PERIOD_COUNTS = _ro([3200, 3200, 3200, 1000, 1000, 1000], dtype=np.int64)
"""Counts between index marks (one motor revolution, Table 2-1; see the module docstring)."""
FIRST_OFFSET = _ro([7700, 9650, 11500, 3400, 3000, 1700], dtype=np.int64)
"""``PA 7700, 9650, 11500, 3400, 3000, 1700`` after the first index search."""
SECOND_OFFSET = _ro([4450, 0, 2000, 810, 975, 2500], dtype=np.int64)
"""``PA 4450, 0, 2000, 810, 975, 2500`` after the second index search."""
HOME_COUNTS = _ro([0, 103597, 80672, 0, 0, 0], dtype=np.int64)
"""``DP 0,103597,80672,0,0,0``: the home pose's counts (axes 0°, 90°, 90°, 0°, 0°, 0°)."""
COARSE_JOG = _ro([5000, 5000, 5000, 1000, 1000, 1000])
COARSE_ACCEL = _ro([2000, 2000, 2000, 400, 400, 400])
COARSE_SPEED = _ro([5000, 5000, 5000, 1000, 1000, 1000])
FIRST_SEARCH_SPEED = _ro([1000, 1000, 1000, 200, 200, 200])
SECOND_SEARCH_SPEED = _ro([500, 500, 500, 100, 100, 100])
"""Jog, acceleration and speed settings of the coarse move and the two index searches."""

