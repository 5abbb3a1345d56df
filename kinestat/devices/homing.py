"""Homing the PUMA 762: startup_initialize.m (Vibhute 2011 App. D.4) over a Galil client.

:func:`home` runs the thesis's start-up against a real DMC or the simulator
(:meth:`kinestat.sim.dmc.DmcSimulator.unknown_start`):

1. power-on checks: ``MO`` (amplifiers off), ``OP0``, ``AF 0,...`` (digital feedback), the VAL
   controller's power on input 3 (``MG @IN[3]`` must read 0), ``SH`` (servo here) and every
   axis servoing (``MG _MOx`` = 0), ``OP1``, the arm's power on input 1 (``MG @IN[1]`` = 0).
   The MATLAB waits in a loop for the operator to switch the power on; :func:`home` refuses
   instead (a clear error; nothing has moved, the amplifiers are switched off with ``MO``);
2. ``DP 0,...``; the pots, each averaged over ``samples`` readings of ``MG @AN[n]``; the
   coarse move ``PR round((READYPOT − pot) · POT_ENCSCALE)`` (refused when a pot reads outside
   0..5 V or asks for more than ``max_coarse`` counts);
3. the first index search (``JG``/``SP`` 1000..200, ``FI``, ``BG``), ``PA`` 7700, 9650,
   11500, 3400, 3000, 1700, the second (``JG`` 500..100), ``PA`` 4450, 0, 2000, 810, 975,
   2500, and ``DP 0,103597,80672,0,0,0``: the home definition (axes 0°, 90°, 90°, 0°, 0°, 0°);
4. read-back: ``TP`` must equal the home definition; then ``HOMED=1``, the session's mark
   that ``kinestat control --galil`` checks (:func:`is_homed`).

Any fault (a check failing, a ``?``, a dropped link, a motion timeout, a signal) ends with
``ST`` confirmed by the controller (:func:`kinestat.devices.safe_stop.confirm_stop`, on a
fresh connection if the link failed), then ``MO`` (amplifiers off), and a report saying why
and what the controller confirmed (a signal arriving during that stop does not cut it short:
the stop is run again); ``record`` receives a JSON-ready
record per step so that the caller's log is complete.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from kinestat.devices.galil import GalilClient, GalilCommandError
from kinestat.devices.safe_stop import confirm_motor_off, confirm_stop, despite_one_signal
from kinestat.errors import DeviceError, KinestatError, SafetyStop, StopRequested
from kinestat.robots.puma762.axes import AXES
from kinestat.robots.puma762.homing import (
    COARSE_ACCEL,
    COARSE_JOG,
    COARSE_SPEED,
    FIRST_OFFSET,
    FIRST_SEARCH_SPEED,
    HOME_COUNTS,
    POT_COUNTS_PER_V,
    READY_POT_V,
    SECOND_OFFSET,
    SECOND_SEARCH_SPEED,
)

__all__ = ["HomingReport", "home", "is_homed", "HOMED_VARIABLE"]

HOMED_VARIABLE = "HOMED"
"""The DMC variable the homing sets to 1 (kept until the controller is reset)."""


def _csv(v) -> str:
    return ",".join(str(int(x)) if float(x).is_integer() else f"{float(x):.4f}" for x in v)


@dataclass
class HomingReport:
    """The outcome of :func:`home` (also its CLI's ``--json``).

    ``axes``: one dict per axis A..F (pot volts, coarse move, position after homing)."""

    homed: bool
    stop_reason: str
    axes: list[dict] = field(default_factory=list)
    elapsed_s: float = 0.0

    def as_dict(self) -> dict:
        return {"homed": self.homed, "axes": self.axes, "stop_reason": self.stop_reason,
                "elapsed_s": self.elapsed_s}


def is_homed(client: GalilClient) -> bool:
    """True when the controller says this session was homed (``MG HOMED`` = 1); an undefined
    variable (``?``) means not homed."""
    try:
        return client.query(f"MG {HOMED_VARIABLE}") == 1.0
    except GalilCommandError:
        return False


class _Steps:
    """The procedure's steps over one client, each recorded."""

    def __init__(self, client: GalilClient, record: Callable[[dict], None], timeout: float,
                 poll: float) -> None:
        self.g = client
        self.record = record
        self.timeout = timeout
        self.poll = poll

    def cmd(self, text: str) -> str:
        reply = self.g.command(text)
        self.record({"type": "command", "command": text, "reply": reply})
        return reply

    def check(self, ok: bool, why: str) -> None:
        if not ok:
            raise SafetyStop(why)

    def wait(self, what: str) -> np.ndarray:
        self.g.wait_motion_complete(timeout=self.timeout, poll_interval=self.poll)
        tp = np.asarray(self.g.position_counts(), dtype=np.int64)
        self.record({"type": "motion_complete", "step": what, "positions": tp.tolist()})
        return tp


def _power_on(s: _Steps) -> None:
    s.cmd("MO")
    s.cmd("OP0")
    s.cmd("AF 0,0,0,0,0,0")
    val = s.g.query("MG @IN[3]")
    s.record({"type": "check", "what": "VAL power (input 3)", "value": val})
    s.check(val == 0, f"power-on check failed: the VAL controller's power is off (input 3 "
            f"reads {val:g}, expected 0)")
    s.cmd("SH")
    servo = [s.g.query(f"MG _MO{a}") for a in AXES]
    s.record({"type": "check", "what": "servo on (MO flags)", "value": servo})
    s.check(all(v == 0 for v in servo), f"power-on check failed: axes not servoing after SH "
            f"(MO flags {servo})")
    s.cmd("OP1")
    arm = s.g.query("MG @IN[1]")
    s.record({"type": "check", "what": "arm power (input 1)", "value": arm})
    s.check(arm == 0, f"power-on check failed: the arm's power is off (input 1 reads {arm:g}, "
            "expected 0)")


def _pots(s: _Steps, samples: int) -> np.ndarray:
    tot = np.zeros(6)
    for _ in range(samples):
        tot += [s.g.query(f"MG @AN[{n}]") for n in range(1, 7)]
    pots = tot / samples
    s.record({"type": "pots", "volts": pots.tolist(), "samples": samples})
    return pots


def _motion(s: _Steps, axes: list[dict], pots: np.ndarray, max_coarse: float) -> None:
    bad = [f"axis {a}: {v:.3f} V" for a, v in zip(AXES, pots, strict=True) if not 0 <= v <= 5]
    s.check(not bad, "pot reading out of its 0-5 V range: " + ", ".join(bad))
    err = np.rint((READY_POT_V - pots) * POT_COUNTS_PER_V).astype(np.int64)
    far = [f"axis {a}: {e:+d}" for a, e in zip(AXES, err, strict=True) if abs(e) > max_coarse]
    s.check(not far, f"coarse move larger than {max_coarse:g} counts (pot or wiring fault?): "
            + ", ".join(far))
    for k in range(6):
        axes[k].update({"axis": AXES[k], "pot_volts": float(pots[k]),
                        "coarse_move": int(err[k])})
    s.cmd("JG " + _csv(COARSE_JOG))
    s.cmd("SH")
    s.cmd("AC " + _csv(COARSE_ACCEL))
    s.cmd("SP " + _csv(COARSE_SPEED))
    s.cmd("PR " + _csv(err))
    s.cmd("BG")
    s.wait("coarse move by the pots")
    for speed, offset, what in ((FIRST_SEARCH_SPEED, FIRST_OFFSET, "first"),
                                (SECOND_SEARCH_SPEED, SECOND_OFFSET, "second")):
        s.cmd("JG " + _csv(speed))
        if what == "first":
            s.cmd("SP " + _csv(speed))
        s.cmd("FI")
        s.cmd("BG")
        tp = s.wait(f"{what} index search")
        s.check(bool(np.all(tp == 0)), f"{what} index search did not zero every encoder "
                f"(TP {tp.tolist()})")
        s.cmd("PA " + _csv(offset))
        s.cmd("BG")
        s.wait(f"move after the {what} index search")


def home(client: GalilClient, *, samples: int = 100, max_coarse: float = 60000.0,
         motion_timeout: float = 120.0, poll_interval: float = 0.01,
         record: Callable[[dict], None] | None = None) -> HomingReport:
    """Run startup_initialize.m on ``client`` (connected); never raises for a cell fault —
    the report says why it stopped (module docstring)."""
    t0 = time.monotonic()
    rec = record if record is not None else (lambda _r: None)
    s = _Steps(client, rec, motion_timeout, poll_interval)
    axes: list[dict] = [{"axis": a} for a in AXES]
    try:
        _power_on(s)
        s.cmd("DP 0,0,0,0,0,0")
        s.cmd("AF 0,0,0,0,0,0")
        _motion(s, axes, _pots(s, int(samples)), max_coarse)
        s.cmd("DP " + _csv(HOME_COUNTS))
        tp = np.asarray(client.position_counts(), dtype=np.int64)
        for k in range(6):
            axes[k]["position"] = int(tp[k])
            axes[k]["home"] = int(HOME_COUNTS[k])
        s.check(bool(np.array_equal(tp, HOME_COUNTS)), f"read-back after DP: TP {tp.tolist()} "
                f"is not the home definition {HOME_COUNTS.tolist()}")
        s.cmd(f"{HOMED_VARIABLE}=1")
        reason = "homed: positions read back as the home definition " + str(HOME_COUNTS.tolist())
        rec({"type": "homed", "positions": tp.tolist()})
        return HomingReport(True, reason, axes, time.monotonic() - t0)
    except (KinestatError, KeyboardInterrupt) as exc:
        why = (f"stopped by {exc.signal_name}" if isinstance(exc, StopRequested) else
               "interrupted by the user" if isinstance(exc, KeyboardInterrupt) else
               str(exc) if isinstance(exc, SafetyStop) else
               f"{'device fault' if isinstance(exc, DeviceError) else type(exc).__name__}: {exc}")
        # a signal arriving during the stop (the run's first) must not cut it or its record
        done, confirmed = despite_one_signal(_amplifiers_off, client)
        despite_one_signal(rec, {"type": "fault", "reason": why, "action": done,
                                 "stop_confirmed": confirmed})
        return HomingReport(False, f"{why} ({done})", axes, time.monotonic() - t0)


def _amplifiers_off(client: GalilClient) -> tuple[str, bool]:
    """``ST`` until the controller confirms no axis moves (on a fresh connection if the link
    failed: :func:`kinestat.devices.safe_stop.confirm_stop`), then ``MO``; say what the
    controller confirmed and what was done."""
    stop = confirm_stop(client)
    if not client.connected:
        return f"{stop}; MO could not be sent", stop.confirmed
    return f"{stop}; {confirm_motor_off(client)[1]}", stop.confirmed
