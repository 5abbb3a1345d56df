"""The simulated PUMA 762's physical layout: where its encoder index marks and its pots' ready
positions are, relative to its home pose (Vibhute 2011 App. D.4, Table 2-1).

A robot's index marks (one per motor revolution, :data:`INDEX_PERIOD_COUNTS`) and its pots are
where the machine was built with them; the homing program (:mod:`kinestat.devices.homing`, the
``PA`` offsets of :mod:`kinestat.robots.puma762.homing`) only has to find them. This module
gives the simulated robot its own layout, as data, so that the simulator does not derive it
from the offsets it is there to check: a change of any offset's sign makes the homing of
:meth:`kinestat.sim.dmc.DmcSimulator.unknown_start` end away from the home pose
(``tests/devices/test_homing.py``).

The numbers are the robot that App. D.4 read as printed (every ``PA`` offset positive) homes:
the only published evidence of the thesis robot's layout (docs/seed-errata-vibhute.md, "Homing's PA
offsets"). In physical counts, the home pose is :data:`HOME_COUNTS`.
"""

from __future__ import annotations

import numpy as np

from kinestat.robots.puma762.homing import HOME_COUNTS, INDEX_PERIOD_COUNTS

__all__ = ["HOME_PAST_INDEX", "READY_BEFORE_HOME", "layout"]

HOME_PAST_INDEX = np.array([1250, 0, 2000, 810, 975, 500], dtype=np.int64)
"""Counts from the index mark before the home pose to the home pose, axes A..F (0: the home
pose is on a mark, axis B)."""
HOME_PAST_INDEX.setflags(write=False)

READY_BEFORE_HOME = np.array([15650, 14400, 16400, 5310, 5475, 5000], dtype=np.int64)
"""Counts from the pots' ready position (``READYPOT``) forward to the home pose, axes A..F:
19.6°, 12.5°, 18.3°, 33.2°, 34.3°, 66.9° of axis motion; half an index period before the mark
that the first index search finds, so that a coarse move anywhere within ±half a period of
the ready position homes alike."""
READY_BEFORE_HOME.setflags(write=False)


def layout(period=INDEX_PERIOD_COUNTS) -> tuple[np.ndarray, np.ndarray]:
    """``(index_phase, ready_counts)`` (6,) each, physical counts: index marks at
    ``index_phase + k·period``, the pots' ready position at ``ready_counts``.

    >>> phase, ready = layout()
    >>> ((HOME_COUNTS - HOME_PAST_INDEX - phase) % INDEX_PERIOD_COUNTS).tolist()
    [0, 0, 0, 0, 0, 0]
    """
    p = np.asarray(period, dtype=np.int64)
    return (HOME_COUNTS - HOME_PAST_INDEX) % p, HOME_COUNTS - READY_BEFORE_HOME
