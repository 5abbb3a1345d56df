"""The cell's device side of the kinestatic loop: :class:`DeviceIO` over the real drivers.

:class:`DeviceIO` implements the loop's :class:`kinestat.control.loop.CellIO` protocol with a
:class:`~kinestat.devices.galil.GalilClient` and an
:class:`~kinestat.devices.encoder_stream.EncoderReader`: moves with the PUMA's axis 4 -> 5
compensation (Vibhute App. D.9), the thesis's motion profile (:class:`MotionProfile`,
``galil_control.m``, App. D.5) and sensor samples taken after the motion settled
(:class:`SensorSample`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinestat.devices.ceilings import MAX_SAMPLES
from kinestat.devices.encoder_stream import TooManyFaultsError, sampled_after
from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX, GalilClient
from kinestat.devices.motion import MOVE_RULES, MoveRule, limit_accel, move_plan
from kinestat.devices.motion_check import POSITION_TOLERANCE_COUNTS, check_arrival
from kinestat.devices.safe_stop import RECONNECT_TIMEOUT, StopReport, send_stop
from kinestat.errors import DeviceError, InputError
from kinestat.robots.puma762.axes import AXIS4_TO_5_COUPLING, axis45_compensation

__all__ = ["MAX_SAMPLES", "STALE_PACKETS_SKIPPED", "SensorSample", "MotionProfile", "DeviceIO"]


STALE_PACKETS_SKIPPED = 1
"""Packets after the drain that may still have been sampled before it (in the box, on air or
in the receiver's buffer): with a box that delivers each packet within one period of sampling
it, the second packet after the drain was sampled after it (:meth:`DeviceIO.sensor`)."""

DEFAULT_MAX_STREAM_FAULTS = 5
"""Stream faults tolerated while acquiring one measurement (the envelope's default,
:class:`kinestat.control.envelope.Envelope`; the composition root passes the envelope's)."""


@dataclass(frozen=True)
class SensorSample:
    """Leg counts for one measurement (sensor legs 1..6), with the stream's bookkeeping."""

    counts: np.ndarray
    seq: int | None = None
    age: float | None = None
    faults: tuple[str, ...] = ()


@dataclass(frozen=True)
class MotionProfile:
    """Speeds (counts/s) and accelerations (counts/s²) per axis A..F for each move: by default
    the thesis's maxima (galil_control.m)."""

    speed: tuple[float, ...] = THESIS_SPEED_MAX
    accel: tuple[float, ...] = THESIS_ACCEL


class DeviceIO:
    """The loop's :class:`~kinestat.control.loop.CellIO` over a
    :class:`~kinestat.devices.galil.GalilClient` and an
    :class:`~kinestat.devices.encoder_stream.EncoderReader` (both opened by the caller).

    Moves compensate the axis 4 -> 5 coupling (``coupling``, as the model's). After each move
    the measurement averages ``samples`` packets SAMPLED after the motion ended and ``settle``
    seconds passed (a running sum: nothing grows with ``samples``; at most
    :data:`MAX_SAMPLES`). A packet's arrival time does not tell when it was sampled (it may
    have waited in the box, on air, in the serial buffer or in a descheduled emitter thread),
    so the rule counts packets instead (:meth:`sensor`): wait ``settle`` past the end of the
    motion, drain what is buffered, skip :data:`STALE_PACKETS_SKIPPED` packet(s) after the
    drain (by sequence number in the ``ks`` format, by count in the legacy one), then take
    the next ones. More than ``max_stream_faults`` stream faults while acquiring one
    measurement end it at once (the loop then stops). ``truth`` is an optional callable
    returning the true state (simulation only). ``move_rule`` chooses each move's per-axis
    speeds (:mod:`kinestat.devices.motion`): "coordinated" (default: the axes start and finish
    together, within the profile's maxima), "thesis" (galil_control.m's ``|Δ|/4``) or "max".

    Safety: ``guard(sent_counts, counts_now)`` is called with the FINAL counts of every axis
    (axis 5 compensated) and the positions read just before, and must raise to refuse them
    (:func:`kinestat.control.envelope.sent_command_guard`); after each move the read-back
    positions must agree with the command within ``position_tolerance`` counts before the
    axis-5 encoder is redefined (:mod:`kinestat.devices.motion_check`). :meth:`stop` sends
    ``ST`` until the controller confirms no axis moves (:mod:`kinestat.devices.safe_stop`).
    """

    def __init__(self, client: GalilClient, reader: Any, *, profile: MotionProfile | None = None,
                 settle: float = 0.03, samples: int = 1, motion_timeout: float = 30.0,
                 coupling: float = AXIS4_TO_5_COUPLING,
                 truth: Callable[[], dict] | None = None,
                 clock: Callable[[], float] = time.monotonic,
                 move_rule: MoveRule = "coordinated",
                 guard: Callable[[np.ndarray, np.ndarray], None] | None = None,
                 position_tolerance: float = POSITION_TOLERANCE_COUNTS,
                 max_stream_faults: int | None = DEFAULT_MAX_STREAM_FAULTS,
                 reconnect_timeout: float = RECONNECT_TIMEOUT) -> None:
        if not (math.isfinite(settle) and settle >= 0):
            raise InputError(f"settle must be >= 0 seconds, got {settle!r}")
        if not 1 <= int(samples) <= MAX_SAMPLES:
            raise InputError(f"samples must be in 1..{MAX_SAMPLES}, got {samples!r}")
        self.client = client
        self.reader = reader
        self.profile = profile or MotionProfile()
        self.settle = float(settle)
        self.samples = int(samples)
        self.motion_timeout = float(motion_timeout)
        self.coupling = float(coupling)
        if move_rule not in MOVE_RULES:
            raise InputError(f"move_rule must be one of {MOVE_RULES}, got {move_rule!r}")
        self.move_rule = move_rule
        self._truth = truth
        self._clock = clock
        self._t_ready = clock()
        self._axis5_carry = 0.0  # true axis 5 past its encoder (counts; see move)
        self.guard = guard
        self.position_tolerance = float(position_tolerance)
        self.max_stream_faults = max_stream_faults
        self.reconnect_timeout = float(reconnect_timeout)

    def robot_counts(self) -> np.ndarray:
        """The robot's axis positions A..F, encoder counts (``TP``)."""
        return np.asarray(self.client.position_counts(), dtype=np.int64)

    def move(self, axis_counts: np.ndarray, accel_limit: float | None = None) -> dict:
        """Move with the axis 4 -> 5 compensation (Vibhute App. D.9), keep reading the sensor
        stream while the axes move (so that the serial buffer never overflows), check the
        read-back positions, then reset the axis-5 encoder (``DP``) as
        :meth:`GalilClient.move_compensated` does. The fraction of a count the true axis 5 ends
        past the reset is carried into the next move's compensation (the thesis discarded it;
        over a long run of small axis-4 moves it added up to tenths of a degree). Returns the
        move's plan:
        ``{"delta_counts", "speed", "accel", "rule"}`` (what was sent). ``accel_limit``
        (1/s²) caps each axis's acceleration and deceleration at that times its travel
        (:func:`kinestat.devices.motion.limit_accel`).

        The final command (axis 5 compensated from the axis-4 position just read) goes through
        ``guard`` before anything is sent.
        """
        c = np.asarray(axis_counts, dtype=np.int64)
        now = self.robot_counts()
        corr = axis45_compensation(c[3], c[4], int(now[3]), self.coupling, self._axis5_carry)
        cmd = c.copy()
        cmd[4] = int(corr.axis5_command)
        plan = limit_accel(move_plan(self.move_rule, now, cmd, self.profile.speed,
                                     self.profile.accel), now, accel_limit)
        if self.guard is not None:
            self.guard(cmd, now)
        self.client.move_absolute(cmd, plan.speed, plan.accel, plan.decel)
        deadline = self._clock() + self.motion_timeout
        while self.client.is_moving():
            if self._clock() > deadline:
                raise DeviceError(f"motion not complete after {self.motion_timeout} s")
            self.reader.poll()
        check_arrival(cmd, self.robot_counts(), self.position_tolerance)
        self.client.define_position({"E": int(corr.axis5_reset)})
        self._axis5_carry = float(corr.residual)
        self._t_ready = self._clock() + self.settle
        return {"delta_counts": (cmd - now).tolist(), "speed": plan.speed.tolist(),
                "accel": plan.accel.tolist(), "rule": self.move_rule}

    def sensor(self) -> SensorSample:
        """The mean of ``samples`` packets sampled after the motion settled, with the stream
        faults seen while waiting for them (summed as they come: no list of samples).

        The rule (the same on hardware and on the simulated cell): keep reading until
        ``settle`` seconds after the end of the last move, drain what the reader has buffered
        (:meth:`EncoderReader.drain`), skip the :data:`STALE_PACKETS_SKIPPED` packet(s) that
        may have been sampled before the drain, then average the next ``samples``
        (:func:`kinestat.devices.encoder_stream.sampled_after`). Valid while the encoder box
        delivers each packet within one period of sampling it (a serial stream at a fixed rate:
        ~2-7 ms per frame at 115200 baud against a 5-10 ms period).

        With more than ``max_stream_faults`` faults it returns at once with the faults and no
        counts (NaN): the loop stops on them."""
        total = np.zeros(6)
        n = 0
        faults: list[str] = []
        last = None
        budget = self.max_stream_faults
        while self._clock() < self._t_ready:
            self.reader.poll()  # the settle time, keeping the serial buffer drained
        mark = self.reader.drain()
        while n < self.samples:
            left = None if budget is None else max(0, budget - len(faults))
            try:
                r = self.reader.read() if left is None else self.reader.read(max_faults=left)
            except TooManyFaultsError as exc:
                faults.extend(f"{f.kind}: {f.message}" for f in exc.faults)
                return SensorSample(counts=np.full(6, np.nan), faults=tuple(faults))
            faults.extend(f"{f.kind}: {f.message}" for f in r.faults)
            if sampled_after(r, mark, STALE_PACKETS_SKIPPED):
                total += np.asarray(r.counts, dtype=float)
                n += 1
                last = r
        assert last is not None
        return SensorSample(counts=total / n, seq=last.seq, age=last.age,
                            faults=tuple(faults))

    def stop(self) -> StopReport:
        """``ST`` until the controller confirms no axis moves, on the open link or on a fresh
        connection if it failed (bounded: :func:`kinestat.devices.safe_stop.confirm_stop`);
        the report says what the controller confirmed."""
        return send_stop(self.client, reconnect_timeout=self.reconnect_timeout)

    def truth(self) -> dict | None:
        """The true state when simulated (the ``truth`` callable), else None."""
        return None if self._truth is None else self._truth()
