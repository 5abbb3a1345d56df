"""A simulated Galil DMC motion controller (six axes A..F): the command interpreter and the motion.

:class:`DmcSimulator` executes DMC command lines (the subset used by Vibhute 2011 App. D.4, D.5
and D.9) and answers like the hardware — ``:`` to acknowledge, data then ``\\r\\n:`` for
queries, ``?`` for a rejected command with the reason available from ``TC1`` (e.g.
``1 Unrecognized command``). Axes follow trapezoidal profiles (``SP`` speed, ``AC``/``DC``
acceleration and deceleration, counts/s and counts/s²). The PUMA's axis 4 -> 5 coupling is
modelled: when axis 4 moves, axis 5 physically turns by ``coupling x (axis-4 motion)`` without
its encoder seeing it; :meth:`DmcSimulator.true_axis_counts` returns the physical positions,
for the simulated cell and for tests. :mod:`kinestat.sim.galil_server` serves it over TCP.

Time is real (``time.monotonic``) unless the simulator is given a :class:`SimClock`, which
only moves when stepped (``advance``) or, with ``step_per_command``, by a fixed amount per
command received — deterministic and fast for tests.
"""

from __future__ import annotations

import math
import re
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from kinestat.errors import InputError
from kinestat.robots.puma762.axes import AXES, AXIS4_TO_5_COUPLING, COUNT_LIMIT
from kinestat.robots.puma762.homing import (
    HOME_COUNTS,
    INDEX_PERIOD_COUNTS,
    POT_COUNTS_PER_V,
    READY_POT_V,
)
from kinestat.robots.puma762.layout import layout

__all__ = ["TC_MESSAGES", "SimClock", "RealClock", "trapezoid", "DmcSimulator"]

TC_MESSAGES: dict[int, str] = {
    0: "No error",
    1: "Unrecognized command",
    4: "Operand error",
    6: "Number out of range",
    7: "Command not valid while running",
    20: "Begin not valid with motor off",
    21: "Begin not valid while running",
}
"""DMC ``TC1`` codes the simulator produces (numbers and texts as in the DMC manuals)."""

DEFAULT_SPEED = 25000.0
DEFAULT_ACCEL = 256000.0
"""DMC power-up defaults for ``SP`` and ``AC``/``DC``."""

MAX_SPEED = 22_000_000.0
MAX_ACCEL = 1_073_740_800.0


class SimClock:
    """A clock that moves only when told: :meth:`advance`, or ``step_per_command`` per command."""

    def __init__(self, start: float = 0.0, step_per_command: float = 0.0) -> None:
        if not (math.isfinite(step_per_command) and step_per_command >= 0):
            raise InputError(f"SimClock: step_per_command must be >= 0, got {step_per_command}")
        self._t = float(start)
        self.step_per_command = float(step_per_command)
        self._lock = threading.Lock()

    def now(self) -> float:
        with self._lock:
            return self._t

    def advance(self, dt: float) -> float:
        """Move time forward by ``dt`` seconds; returns the new time."""
        if not (math.isfinite(dt) and dt >= 0):
            raise InputError(f"SimClock.advance: dt must be >= 0, got {dt}")
        with self._lock:
            self._t += float(dt)
            return self._t

    def on_command(self) -> None:
        if self.step_per_command:
            self.advance(self.step_per_command)


class RealClock:
    """Wall-clock time (``time.monotonic``)."""

    @staticmethod
    def now() -> float:
        return time.monotonic()

    def on_command(self) -> None:
        return None


# --------------------------------------------------------------------------- profiles


@dataclass
class _Motion:
    """Piecewise-constant acceleration from (t0, x0, v0); the last segment may be endless."""

    t0: float
    x0: float
    v0: float
    segs: list[tuple[float, float]]  # (duration, acceleration)
    final: float | None = None  # exact end position of a point-to-point move
    zero_at_end: bool = False  # FI: define the encoder as 0 where the motion ends

    def state(self, t: float) -> tuple[float, float, bool]:
        x, v, tau = self.x0, self.v0, max(0.0, t - self.t0)
        for dur, a in self.segs:
            h = min(tau, dur)
            x += v * h + 0.5 * a * h * h
            v += a * h
            tau -= h
            if tau <= 0 and h < dur:
                return x, v, False
        if self.final is not None:
            return self.final, 0.0, True
        return x, v, not self.segs or math.isfinite(self.segs[-1][0])


def trapezoid(distance: float, speed: float, accel: float, decel: float
              ) -> list[tuple[float, float]]:
    """Segments (duration, acceleration) of a rest-to-rest move over ``distance`` (signed)."""
    d = abs(distance)
    if d == 0.0:
        return []
    s = 1.0 if distance > 0 else -1.0
    vp = min(speed, math.sqrt(2.0 * d * accel * decel / (accel + decel)))
    t1, t3 = vp / accel, vp / decel
    t2 = max(0.0, (d - 0.5 * vp * t1 - 0.5 * vp * t3) / vp)
    return [(t1, s * accel), (t2, 0.0), (t3, -s * decel)]


@dataclass
class _Axis:
    motor: float = 0.0
    enc_offset: float = 0.0
    servo: bool = True
    sp: float = DEFAULT_SPEED
    ac: float = DEFAULT_ACCEL
    dc: float = DEFAULT_ACCEL
    jg: float = 0.0
    mode: str = "PA"
    target: float | None = None
    rel: float = 0.0
    af: float = 0.0
    motion: _Motion | None = None
    velocity: float = 0.0
    history: list[tuple[float, float, float]] = field(default_factory=list)


class _Reject(Exception):
    def __init__(self, code: int) -> None:
        self.code = code
        super().__init__(TC_MESSAGES.get(code, "error"))


_NAME = re.compile(r"^([A-Z]{2})(.*)$")
_ASSIGN = re.compile(r"^([A-Za-z][A-Za-z0-9]{0,7})\s*=\s*(\S+)$")


class DmcSimulator:
    """The simulated controller state machine (thread-safe; no sockets).

    ``initial_counts`` are the encoder (and true) positions at start; the encoders are
    calibrated (encoder == true) then. ``coupling`` is the axis 4 -> 5 ratio (0 disables it).
    ``index_period`` (one number or six; default Table 2-1's one motor revolution, 3200 counts
    on axes 1-3 and 1000 on 4-6) / ``index_phase`` place the encoder index marks for ``FI``.

    Start-up (Vibhute App. D.4): ``inputs`` are the digital inputs ``@IN[n]`` (default all 0:
    VAL and arm power on; a 1 on input 3 or 1 is a failed power-on check); ``pot_ready``
    (physical counts of the pots' ready position, None: pots read the ready voltages at the
    initial counts) and ``pot_noise`` (V, standard deviation, seeded by ``seed``) make
    ``@AN[n]`` read ``READYPOT_n + (motor_n − ready_n) / POT_ENCSCALE_n``. Variables
    (``NAME=value``, ``MG NAME``) are kept for the session; the homing procedure sets ``HOMED``
    (:attr:`homed`). :meth:`unknown_start` builds a robot at an arbitrary position whose
    encoders read 0 at power-up, laid out so that startup_initialize.m homes it.
    """

    def __init__(
        self,
        *,
        clock: SimClock | RealClock | None = None,
        initial_counts: Sequence[float] = (0, 0, 0, 0, 0, 0),
        coupling: float = AXIS4_TO_5_COUPLING,
        index_period: float | Sequence[float] = tuple(INDEX_PERIOD_COUNTS),
        index_phase: Sequence[float] = (0, 0, 0, 0, 0, 0),
        record: bool = False,
        inputs: dict[int, float] | None = None,
        pot_ready: Sequence[float] | None = None,
        pot_noise: float = 0.0,
        seed: int | None = None,
    ) -> None:
        c0 = np.asarray(initial_counts, dtype=float)
        if c0.shape != (6,) or not np.all(np.isfinite(c0)):
            raise InputError(f"DmcSimulator: initial_counts must be 6 finite counts, got "
                             f"{initial_counts!r}")
        if not math.isfinite(coupling):
            raise InputError("DmcSimulator: coupling must be finite")
        per = np.broadcast_to(np.asarray(index_period, dtype=float), (6,))
        if not (np.all(np.isfinite(per)) and np.all(per > 0)):
            raise InputError("DmcSimulator: index_period must be > 0")
        if not (math.isfinite(pot_noise) and pot_noise >= 0):
            raise InputError("DmcSimulator: pot_noise must be >= 0 volts")
        self.clock = clock if clock is not None else RealClock()
        self.coupling = float(coupling)
        self.index_period = tuple(float(p) for p in per)
        self.index_phase = tuple(float(p) for p in index_phase)
        self.inputs: dict[int, float] = dict(inputs or {})
        self.pot_ready = np.asarray(c0 if pot_ready is None else pot_ready, dtype=float)
        self.pot_noise = float(pot_noise)
        self._rng = np.random.default_rng(seed)
        self.variables: dict[str, float] = {}
        self.record = record
        self._axes = [_Axis(motor=float(c)) for c in c0]
        self._motor4_ref = float(c0[3])
        self._code = 0
        self._lock = threading.RLock()
        self._rules: list[list] = []  # [prefix, action, code, times]
        self.commands: list[str] = []

    @classmethod
    def unknown_start(cls, seed: int | None = None, *, pot_noise: float = 0.002,
                      **kw) -> DmcSimulator:
        """A robot at an arbitrary position (within ±25° of home on axes 1-3, ±19° on 4-6),
        its encoders reading 0 at power-up, its index marks and pots where the simulated
        robot has them (:mod:`kinestat.robots.puma762.layout`; its home pose is
        :data:`HOME_COUNTS` in physical counts)."""
        rng = np.random.default_rng(seed)
        span = np.array([20000, 28000, 22000, 3000, 3000, 1400])
        start = HOME_COUNTS + rng.integers(-span, span + 1)
        phase, ready = layout(kw.get("index_period", INDEX_PERIOD_COUNTS))
        sim = cls(initial_counts=start, index_phase=tuple(phase), pot_ready=ready,
                  pot_noise=pot_noise, seed=None if seed is None else seed + 1, **kw)
        for ax in sim._axes:
            ax.enc_offset = -ax.motor  # encoders read 0 at power-up
        sim._motor4_ref = float(HOME_COUNTS[3])  # axis 5's coupling: a fixed mechanism
        return sim

    @property
    def homed(self) -> bool:
        """The homing procedure completed in this session (variable ``HOMED`` = 1)."""
        with self._lock:
            return self.variables.get("HOMED") == 1.0

    def motor_counts(self) -> np.ndarray:
        """Motor positions in physical counts (where the index marks and pots are)."""
        with self._lock:
            self._update()
            return np.array([ax.motor for ax in self._axes])

    # -- fault injection
    def reject_next(self, prefix: str, code: int = 1, times: int = 1) -> None:
        """Answer ``?`` (and set ``TC1`` to ``code``) to the next ``times`` commands starting
        with ``prefix``, without executing them."""
        with self._lock:
            self._rules.append([prefix, "reject", int(code), int(times)])

    def silence_next(self, prefix: str, times: int = 1) -> None:
        """Send no reply at all to the next ``times`` commands starting with ``prefix``."""
        with self._lock:
            self._rules.append([prefix, "silence", 0, int(times)])

    def stale_before_next(self, prefix: str, text: str = " 0.0000\r\n:", times: int = 1
                          ) -> None:
        """Execute the next ``times`` commands starting with ``prefix`` normally but send
        ``text`` (a stale reply) ahead of their reply, as if an old answer were still queued."""
        with self._lock:
            self._rules.append([prefix, "stale", 0, int(times), str(text)])

    def _rule_for(self, cmd: str) -> list | None:
        for r in self._rules:
            if cmd.startswith(r[0]) and r[3] > 0:
                r[3] -= 1
                if r[3] == 0:
                    self._rules.remove(r)
                return r
        return None

    # -- state
    def _update(self) -> float:
        t = self.clock.now()
        for ax in self._axes:
            m = ax.motion
            if m is None:
                ax.velocity = 0.0
            else:
                x, v, done = m.state(t)
                ax.motor, ax.velocity = x, v
                if done:
                    ax.motion = None
                    ax.velocity = 0.0
                    if m.zero_at_end:
                        ax.enc_offset = -ax.motor
            if self.record:
                ax.history.append((t, ax.motor, ax.velocity))
        return t

    def true_axis_counts(self) -> np.ndarray:
        """Physical axis positions in counts (what an encoder correct at start would read).

        Equal to the encoders except for ``DP``/``FI`` redefinitions and axis 5, which also
        carries ``coupling x (axis-4 motion since start)``.
        """
        with self._lock:
            self._update()
            pos = np.array([ax.motor for ax in self._axes])
            pos[4] += self.coupling * (self._axes[3].motor - self._motor4_ref)
            return pos

    def encoder_counts(self) -> np.ndarray:
        """What ``TP`` reports (rounded), as floats before rounding."""
        with self._lock:
            self._update()
            return np.array([ax.motor + ax.enc_offset for ax in self._axes])

    def velocities(self) -> np.ndarray:
        """Current axis velocities, counts/s."""
        with self._lock:
            self._update()
            return np.array([ax.velocity for ax in self._axes])

    def moving(self) -> tuple[bool, ...]:
        with self._lock:
            self._update()
            return tuple(ax.motion is not None for ax in self._axes)

    def history(self, axis: int) -> list[tuple[float, float, float]]:
        """(time, position, velocity) samples taken at each command when ``record=True``."""
        with self._lock:
            return list(self._axes[axis].history)

    @property
    def error_code(self) -> int:
        return self._code

    # -- command processing
    def handle(self, line: str) -> str | None:
        """Execute one command; return the reply text, or None to stay silent."""
        with self._lock:
            self.clock.on_command()
            cmd = line.strip()
            if self.record:
                self.commands.append(cmd)
            rule = self._rule_for(cmd)
            stale = ""
            if rule is not None and rule[1] == "stale":
                stale, rule = rule[4], None
            if rule is not None:
                if rule[1] == "silence":
                    return None
                self._code = rule[2]
                return "?"
            self._update()
            try:
                data = self._execute(cmd)
            except (_Reject, ValueError, ArithmeticError, RecursionError) as rej:
                self._code = getattr(rej, "code", 4)  # else an operand out of reach
                return stale + "?"
            return stale + (":" if data is None else f"{data}\r\n:")

    def _execute(self, cmd: str) -> str | None:
        v = _ASSIGN.match(cmd)
        if v is not None:  # a variable: NAME=value
            try:
                val = float(v.group(2))
            except ValueError:
                raise _Reject(4) from None
            if not math.isfinite(val):
                raise _Reject(4)
            self.variables[v.group(1)] = val
            return None
        m = _NAME.match(cmd)
        if m is None:
            raise _Reject(1)
        name, rest = m.group(1), m.group(2).strip()
        fn = getattr(self, f"_cmd_{name}", None)
        if fn is None:
            raise _Reject(1)
        return fn(rest)

    @staticmethod
    def _axes_arg(rest: str) -> list[int]:
        if not rest:
            return list(range(6))
        letters = rest.replace(" ", "")
        if any(c not in AXES for c in letters):
            raise _Reject(4)
        return sorted({AXES.index(c) for c in letters})

    @staticmethod
    def _fields(rest: str, lo: float, hi: float) -> list[float | None]:
        if not rest:
            raise _Reject(4)
        parts = [p.strip() for p in rest.split(",")]
        if len(parts) > 6:
            raise _Reject(4)
        out: list[float | None] = []
        for p in parts:
            if p == "":
                out.append(None)
                continue
            try:
                v = float(p)
            except ValueError:
                raise _Reject(4) from None
            if not (math.isfinite(v) and lo <= v <= hi):
                raise _Reject(6)
            out.append(v)
        return out

    def _set(self, rest: str, attr: str, lo: float, hi: float, *, idle: bool = False) -> None:
        vals = self._fields(rest, lo, hi)
        if idle and any(v is not None and self._axes[i].motion is not None
                        for i, v in enumerate(vals)):
            raise _Reject(7)
        for ax, v in zip(self._axes, vals, strict=False):
            if v is not None:
                setattr(ax, attr, v)

    # motion parameters
    def _cmd_AC(self, rest: str) -> None:
        self._set(rest, "ac", 1e-9, MAX_ACCEL)

    def _cmd_DC(self, rest: str) -> None:
        self._set(rest, "dc", 1e-9, MAX_ACCEL)

    def _cmd_SP(self, rest: str) -> None:
        self._set(rest, "sp", 1e-9, MAX_SPEED)

    def _cmd_AF(self, rest: str) -> None:
        self._set(rest, "af", -1e9, 1e9)

    def _cmd_OP(self, rest: str) -> None:
        self._fields(rest, -1e9, 1e9)

    def _cmd_PA(self, rest: str) -> None:
        vals = self._fields(rest, -COUNT_LIMIT, COUNT_LIMIT)
        if any(v is not None and self._axes[i].motion is not None for i, v in enumerate(vals)):
            raise _Reject(7)
        for ax, v in zip(self._axes, vals, strict=False):
            if v is not None:
                ax.mode, ax.target = "PA", float(round(v)) - ax.enc_offset

    def _cmd_PR(self, rest: str) -> None:
        vals = self._fields(rest, -COUNT_LIMIT, COUNT_LIMIT)
        if any(v is not None and self._axes[i].motion is not None for i, v in enumerate(vals)):
            raise _Reject(7)
        for ax, v in zip(self._axes, vals, strict=False):
            if v is not None:
                ax.mode, ax.rel = "PR", float(round(v))

    def _cmd_JG(self, rest: str) -> None:
        vals = self._fields(rest, -MAX_SPEED, MAX_SPEED)
        t = self.clock.now()
        for ax, v in zip(self._axes, vals, strict=False):
            if v is None:
                continue
            ax.jg = v
            if ax.motion is not None and ax.mode == "JG":  # change a running jog's speed
                ax.motion = self._jog(ax, t)
            elif ax.motion is None:
                ax.mode = "JG"

    def _cmd_FI(self, rest: str) -> None:
        for i in self._axes_arg(rest):
            if self._axes[i].motion is not None:
                raise _Reject(7)
        for i in self._axes_arg(rest):
            self._axes[i].mode = "FI"

    def _cmd_DP(self, rest: str) -> None:
        vals = self._fields(rest, -COUNT_LIMIT, COUNT_LIMIT)
        if any(v is not None and self._axes[i].motion is not None for i, v in enumerate(vals)):
            raise _Reject(7)
        for ax, v in zip(self._axes, vals, strict=False):
            if v is not None:
                ax.enc_offset = float(round(v)) - ax.motor
                ax.target = None

    # servo and motion
    def _cmd_MO(self, rest: str) -> None:
        for i in self._axes_arg(rest):
            ax = self._axes[i]
            ax.motion, ax.servo, ax.velocity = None, False, 0.0

    def _cmd_SH(self, rest: str) -> None:
        for i in self._axes_arg(rest):
            ax = self._axes[i]
            ax.servo, ax.target = True, None

    def _jog(self, ax: _Axis, t: float) -> _Motion:
        dv = ax.jg - ax.velocity
        acc = ax.ac if abs(ax.jg) >= abs(ax.velocity) else ax.dc
        segs = [(abs(dv) / acc, math.copysign(acc, dv))] if dv else []
        return _Motion(t, ax.motor, ax.velocity, segs + [(math.inf, 0.0)])

    def _cmd_BG(self, rest: str) -> None:
        idx = self._axes_arg(rest)
        for i in idx:
            if not self._axes[i].servo:
                raise _Reject(20)
            if self._axes[i].motion is not None:
                raise _Reject(21)
        if any(self._axes[i].mode == "FI" and self._axes[i].jg == 0 for i in idx):
            raise _Reject(6)
        t = self.clock.now()
        for i in idx:
            ax = self._axes[i]
            if ax.mode == "JG":
                if ax.jg != 0:
                    ax.motion = self._jog(ax, t)
                continue
            zero = False
            if ax.mode == "PR":
                goal = ax.motor + ax.rel
                speed = ax.sp
            elif ax.mode == "FI":
                p, ph = self.index_period[i], self.index_phase[i]
                k = (math.floor((ax.motor - ph) / p) + 1 if ax.jg > 0
                     else math.ceil((ax.motor - ph) / p) - 1)
                goal, speed, zero = ph + k * p, abs(ax.jg), True
            else:
                goal = ax.motor if ax.target is None else ax.target
                speed = ax.sp
            segs = trapezoid(goal - ax.motor, speed, ax.ac, ax.dc)
            if segs:
                ax.motion = _Motion(t, ax.motor, 0.0, segs, final=goal, zero_at_end=zero)

    def _cmd_ST(self, rest: str) -> None:
        t = self.clock.now()
        for i in self._axes_arg(rest):
            ax = self._axes[i]
            if ax.motion is None:
                continue
            v = ax.velocity
            segs = [(abs(v) / ax.dc, -math.copysign(ax.dc, v))] if v else []
            ax.motion = _Motion(t, ax.motor, v, segs)
            if not segs:
                ax.motion = None
            ax.target = None

    # queries
    def _cmd_TP(self, rest: str) -> str:
        vals = [round(self._axes[i].motor + self._axes[i].enc_offset)
                for i in self._axes_arg(rest)]
        return " " + ", ".join(f"{v:d}" for v in vals)

    def _cmd_TC(self, rest: str) -> str:
        if rest in ("", "0"):
            return f"{self._code:d}"
        if rest == "1":
            return f"{self._code:d} {TC_MESSAGES.get(self._code, 'Unknown error')}"
        raise _Reject(4)

    def _operand(self, op: str) -> float:
        op = op.strip()
        m = re.fullmatch(r"_(TP|RP|BG|SP|AC|DC|MO|TV)([A-F])", op)
        if m:
            ax = self._axes[AXES.index(m.group(2))]
            key = m.group(1)
            if key in ("TP", "RP"):
                return float(round(ax.motor + ax.enc_offset))
            if key == "BG":
                return 1.0 if ax.motion is not None else 0.0
            if key == "MO":
                return 0.0 if ax.servo else 1.0
            if key == "TV":
                return float(round(ax.velocity))
            return float(getattr(ax, key.lower()))
        m = re.fullmatch(r"@(IN|AN)\[(\d{1,4})\]", op)  # more digits: an operand error
        if m:
            n = int(m.group(2))
            if m.group(1) == "IN":  # 0: "VAL power on", "arm power on" (startup_initialize.m)
                return float(self.inputs.get(n, 0.0))
            if not 1 <= n <= 6:
                raise _Reject(6)
            i = n - 1
            v = READY_POT_V[i] + (self._axes[i].motor - self.pot_ready[i]) / POT_COUNTS_PER_V[i]
            return float(v + (self._rng.normal(0.0, self.pot_noise) if self.pot_noise else 0.0))
        if op in self.variables:
            return self.variables[op]
        try:
            v = float(op)
        except ValueError:
            raise _Reject(4) from None
        if not math.isfinite(v):
            raise _Reject(4)
        return v

    def _cmd_MG(self, rest: str) -> str:
        if not rest:
            raise _Reject(4)
        return " ".join(f"{self._operand(op): .4f}" for op in rest.split(","))
