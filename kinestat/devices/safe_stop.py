"""Stopping the axes when something went wrong, and proving it: ``ST`` until the controller
says no axis moves.

An acknowledgement ``:`` proves nothing about a stop: after an interrupted exchange (a signal
while waiting for ``BG``'s reply) the late ``:`` of ``BG`` looks exactly like ``ST``'s, and a
lost ``ST`` has no reply at all. :func:`confirm_stop` therefore sends ``ST`` without reading
its reply (:meth:`~kinestat.devices.galil.GalilClient.send_only`) and then asks the controller
whether any axis is still profiling a motion with ``MG <tag>,_BGA,...,_BGF``
(:meth:`~kinestat.devices.galil.GalilClient.tagged_query`): the reply carrying the fresh tag
is provably the answer to that query and was produced after the controller had processed
every earlier command, ``ST`` included. ``ST`` is repeated (harmless while the axes
decelerate) until two successive tagged answers say no axis moves: one garbled flag cannot
confirm a stop.

A reply timeout, a garbled tagged reply or a dropped link close the connection; the stop is
then retried on a fresh connection (at most :data:`MAX_ATTEMPTS` connections in all, each
bounded by ``reconnect_timeout``). :class:`StopReport` says what the controller confirmed:
``"ST confirmed by the controller ..."`` or ``"ST unconfirmed: ..."`` (the link gone, or the
axes still moving after ``stop_timeout``).
"""

from __future__ import annotations

import itertools
import random
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX, GalilClient
from kinestat.errors import KinestatError
from kinestat.robots.puma762.axes import AXES

__all__ = ["RECONNECT_TIMEOUT", "STOP_TIMEOUT", "MAX_ATTEMPTS", "StopReport", "confirm_stop",
           "confirm_motor_off", "send_stop", "despite_one_signal"]

RECONNECT_TIMEOUT = 1.0
"""Bound (s) on a fresh connection and on each reply during a stop."""

STOP_TIMEOUT = 2.0 * max(v / a for v, a in zip(THESIS_SPEED_MAX, THESIS_ACCEL, strict=True))
"""Time (s) the axes get to come to rest after ``ST``: twice the longest deceleration of the
thesis's profile from its maximum speed (``SP / DC``, 1 s on axes A, B, C and F)."""

MAX_ATTEMPTS = 3
"""Connections tried for one stop: the open link, then up to two fresh ones."""

_MOTION_FLAGS = [f"_BG{a}" for a in AXES]
_T = TypeVar("_T")
_tags = itertools.count(random.SystemRandom().randrange(1, 500_000))


@dataclass(frozen=True)
class StopReport:
    """What a stop achieved: ``confirmed`` when the controller answered (twice, to tagged
    queries) that no axis moves; ``text`` for the log; ``attempts`` connections used."""

    confirmed: bool
    text: str
    attempts: int = 1

    def __str__(self) -> str:
        return self.text


def _next_tag() -> int:
    return next(_tags) % 999_999 + 1


def _stop_until_still(client: GalilClient, t_end: float, poll: float) -> list[float] | None:
    """``ST`` then the tagged motion query, repeated until two answers in a row say no axis
    moves (None) or ``t_end`` passes (the last flags)."""
    still = 0
    while True:
        client.send_only("ST")
        flags = client.tagged_query(_MOTION_FLAGS, _next_tag())
        still = still + 1 if not any(flags) else 0
        if still >= 2:
            return None
        if still == 0 and time.monotonic() > t_end:
            return flags
        if still == 0 and poll > 0:
            time.sleep(poll)


def confirm_stop(client: GalilClient, *, reconnect_timeout: float = RECONNECT_TIMEOUT,
                 stop_timeout: float = STOP_TIMEOUT, poll: float = 0.01) -> StopReport:
    """Stop every axis and prove it (module docstring); bounded in time, never raises for a
    device fault."""
    saved = client.timeout
    notes: list[str] = []
    t_end = time.monotonic() + float(stop_timeout)
    flags: list[float] | None = None
    try:
        client.timeout = min(saved, float(reconnect_timeout))
        for attempt in range(1, MAX_ATTEMPTS + 1):
            fresh = attempt > 1 or not client.connected
            try:
                if fresh:
                    client.connect(timeout=client.timeout)
                flags = _stop_until_still(client, t_end, poll)
            except KinestatError as exc:
                client.close()
                notes.append(f"{'fresh connection' if fresh else 'open link'}: {exc}")
                continue
            if flags is None:
                where = (f" on a fresh connection ({'; '.join(notes) or 'the link was down'})"
                         if fresh else "")
                return StopReport(True, "ST confirmed by the controller: no axis in motion "
                                  f"(MG _BGA.._BGF all 0, twice){where}", attempt)
            moving = [a for a, f in zip(AXES, flags, strict=True) if f]
            return StopReport(False, f"ST unconfirmed: axes {', '.join(moving)} still in "
                              f"motion {stop_timeout:g} s after ST", attempt)
    finally:
        client.timeout = saved
    return StopReport(False, "ST unconfirmed: the link is gone (" + "; ".join(notes) + ")",
                      MAX_ATTEMPTS)


def confirm_motor_off(client: GalilClient) -> tuple[bool, str]:
    """``MO`` (amplifiers off) on the open link, proved the same way: the tagged answer of
    ``MG <tag>,_MOA,...,_MOF`` must say every axis is off. (confirmed, what happened)."""
    try:
        client.send_only("MO")
        flags = client.tagged_query([f"_MO{a}" for a in AXES], _next_tag())
    except KinestatError as exc:
        return False, f"MO failed: {exc}"
    on = [a for a, f in zip(AXES, flags, strict=True) if f != 1]
    if on:
        return False, f"MO sent but axes {', '.join(on)} still servo (MG _MO flags)"
    return True, "MO sent and confirmed: amplifiers off (MG _MOA.._MOF all 1)"


def send_stop(client: GalilClient, *, reconnect_timeout: float = RECONNECT_TIMEOUT) -> StopReport:
    """:func:`confirm_stop` with the default stop timeout (the loop's and homing's stop)."""
    return confirm_stop(client, reconnect_timeout=reconnect_timeout)


def despite_one_signal(fn: Callable[..., _T], *args: object) -> _T:
    """``fn(*args)``, run again if a signal interrupted it: a stop that a fault started must not
    be cut short by the operator's Ctrl-C or a SIGTERM arriving meanwhile
    (:func:`kinestat.app.signals.stop_on_signals` raises on the first signal only, so the second
    call runs to its end)."""
    try:
        return fn(*args)
    except KeyboardInterrupt:
        return fn(*args)
