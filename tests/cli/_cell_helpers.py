"""Shared by the command-line tests of the kinestatic cell: fast simulated moves, the JSON of
a run's output, and waiting on a condition."""

from __future__ import annotations

import json
import time

import numpy as np

from kinestat.devices.cell_io import MotionProfile
from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX

FAST = MotionProfile(speed=tuple(20 * np.asarray(THESIS_SPEED_MAX)),
                     accel=tuple(400 * np.asarray(THESIS_ACCEL)))
"""Moves of a few ms each (the thesis's profile × 20 speed, × 400 acceleration)."""


def use_fast_moves(monkeypatch) -> None:
    """Make :class:`MotionProfile` default to :data:`FAST` for the test (keeps tests short)."""
    monkeypatch.setattr(MotionProfile.__init__, "__defaults__", (FAST.speed, FAST.accel))


def json_of(capsys) -> dict:
    """The JSON report a command printed on stdout (after any progress lines)."""
    out = capsys.readouterr().out
    return json.loads(out[out.index("{"):])


def wait_until(pred, timeout: float, what: str) -> None:
    """Poll ``pred`` every 5 ms; fail naming ``what`` after ``timeout`` seconds."""
    t_end = time.monotonic() + timeout
    while not pred():
        if time.monotonic() > t_end:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.005)
