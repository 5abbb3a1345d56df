"""Composition root of ``kinestat home``: connect to the Galil, run the start-up
(:func:`kinestat.devices.homing.home`) and log every step (JSON lines, like the control log).
"""

from __future__ import annotations

import time
from pathlib import Path

from kinestat.control.log import CycleLog
from kinestat.devices.galil import GalilClient
from kinestat.devices.homing import HomingReport, home
from kinestat.devices.safe_stop import despite_one_signal
from kinestat.errors import DeviceError

__all__ = ["run_home"]


def run_home(host: str, port: int, log_path: Path, *, samples: int = 100,
             timeout: float = 2.0, motion_timeout: float = 120.0) -> HomingReport:
    """Home the robot behind the Galil at ``host``:``port``; the log holds a ``start``
    record, one record per step (commands, checks, pots, motions), a ``fault`` record if it
    stopped, and an ``end`` record with the report."""
    with CycleLog(log_path) as log:
        log.write({"type": "start", "time": time.strftime("%Y-%m-%dT%H:%M:%S"),
                   "galil": f"{host}:{port}", "samples": samples})
        client = GalilClient(host, port, timeout=timeout)
        try:
            try:
                client.connect()
            except (DeviceError, KeyboardInterrupt) as exc:  # incl. SIGTERM/SIGHUP (StopRequested)
                why = (f"device fault: {exc}" if isinstance(exc, DeviceError) else
                       f"stopped by {getattr(exc, 'signal_name', 'the user')} while connecting")
                log.write({"type": "fault", "reason": why, "action": "nothing sent"})
                rep = HomingReport(False, f"{why} (nothing sent)")
            else:
                rep = home(client, samples=samples, motion_timeout=motion_timeout,
                           record=log.write)
        finally:
            client.close()
        despite_one_signal(log.write, {"type": "end", "report": rep.as_dict()})
    return rep
