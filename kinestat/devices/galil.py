"""Galil DMC motion controller: a small TCP client and the thesis's move recipe.

The PUMA 762 of Vibhute 2011 is driven by a Galil DMC 2160 over Ethernet (App. D.4, D.5, D.9).
The robot's axis conventions (encoder scales, joint-1 offset, axis 4 -> 5 coupling and its
compensation, rounding to counts) live in :mod:`kinestat.robots.puma762.axes`. This module
holds:

* the thesis's move recipe (speeds, accelerations, the +5-count nudge: ``galil_control.m``);
* :class:`GalilClient`, a pure-Python client for the command subset the thesis uses.

DMC replies: a command is acknowledged by ``:``; a query returns its data then ``\\r\\n:``; a
rejected command returns ``?`` and the reason is read with ``TC1`` (``"<code> <message>"``).
A ``?`` is never parsed as a number: it raises :class:`GalilCommandError`.
"""

from __future__ import annotations

import math
import socket
import time
from typing import Any, NamedTuple

import numpy as np

from kinestat.devices.galil_replies import match_reply, split_reply
from kinestat.devices.motion_check import check_arrival
from kinestat.errors import DeviceError, InputError, ProtocolError
from kinestat.robots.puma762.axes import (
    AXES,
    AXIS4_TO_5_COUPLING,
    COUNT_LIMIT,
    as_axes6,
    as_finite,
    axis45_compensation,
    round_half_away,
)

THESIS_ACCEL = (8000.0, 11511.0, 8964.0, 3194.0, 3194.0, 1496.0)
"""``AC`` and ``DC`` used by ``galil_control.m`` (counts/s^2), axes A..F."""

THESIS_SPEED_MAX = (8000.0, 11511.0, 8964.0, 3194.0, 0.46 * 3194.0, 1496.0)
"""Maximum ``SP`` per axis in ``galil_control.m`` (counts/s), axes A..F."""

THESIS_SPEED_MIN = 10.0
"""Slowest ``SP`` the thesis commands (counts/s)."""

THESIS_NUDGE_COUNTS = 5
"""``galil_control.m`` adds 5 counts to a target closer than 5 counts to the current position."""

DEFAULT_PORT = 23
"""Galil controllers accept commands on TCP port 23."""


# --------------------------------------------------------------------------- move recipe


class MovePlan(NamedTuple):
    """Targets and profile parameters for one ``PA`` move, axes A..F."""

    target: np.ndarray
    speed: np.ndarray
    accel: np.ndarray
    decel: np.ndarray


def thesis_move_plan(current: Any, target: Any, *, nudge: bool = True) -> MovePlan:
    """The move recipe of ``galil_control.m`` (Vibhute App. D.5), for counts A..F.

    Speed per axis ``ceil(|target - current| / 4)`` clamped to [10, max] (so every axis takes
    about 4 s at cruise), ``AC = DC = THESIS_ACCEL``, and with ``nudge`` a target less than 5
    counts away is moved 5 counts further (+5) as the thesis does. The thesis sets tiny-move
    speeds of axes D and E to the maximum instead of 10 (see docs/seed-errata.md); this
    function uses 10 for every axis.
    """
    cur = as_axes6(current, "thesis_move_plan current")
    tgt = round_half_away(as_axes6(target, "thesis_move_plan target"))
    dist = np.abs(cur - tgt)
    speed = np.clip(np.ceil(dist / 4.0), THESIS_SPEED_MIN, np.asarray(THESIS_SPEED_MAX))
    if nudge:
        tgt = np.where(dist < THESIS_NUDGE_COUNTS, tgt + THESIS_NUDGE_COUNTS, tgt)
    acc = np.broadcast_to(np.asarray(THESIS_ACCEL), tgt.shape).copy()
    return MovePlan(tgt.astype(np.int64), speed, acc, acc.copy())


# --------------------------------------------------------------------------- client


class GalilCommandError(DeviceError):
    """The controller answered ``?``: ``code`` and ``message`` come from ``TC1``."""

    def __init__(self, command: str, code: int | None, message: str) -> None:
        self.command = command
        self.code = code
        self.message = message
        why = f"error {code}: {message}" if code is not None else message
        super().__init__(f"Galil rejected {command!r} ({why})")


def _fmt(x: float) -> str:
    if float(x).is_integer():
        return str(int(x))
    return f"{float(x):.4f}"


def _per_axis(value: Any, name: str, *, positive: bool) -> list[float]:
    a = as_finite(value, name)
    if a.ndim == 0:
        a = np.full(6, float(a))
    if a.shape != (6,):
        raise InputError(f"{name}: expected one value or 6 (axes A..F), got shape {a.shape}")
    if positive and np.any(a <= 0):
        raise InputError(f"{name}: values must be > 0, got {a.tolist()}")
    if np.any(np.abs(a) > COUNT_LIMIT):
        raise InputError(f"{name}: values exceed the Galil's 32-bit range")
    return a.tolist()


def parse_number(reply: str, command: str = "") -> float:
    """Read one number from a DMC reply (e.g. ``" 1234.0000"``); :class:`ProtocolError` if not.

    A ``?`` or any non-numeric text is refused, never guessed.
    """
    text = reply.strip()
    if "?" in text or not text:
        raise ProtocolError(f"Galil reply to {command!r} is not a number: {reply!r}")
    try:
        v = float(text)
    except ValueError as exc:
        raise ProtocolError(f"Galil reply to {command!r} is not a number: {reply!r}") from exc
    if not math.isfinite(v):
        raise ProtocolError(f"Galil reply to {command!r} is not finite: {reply!r}")
    return v


def parse_numbers(reply: str, n: int, command: str = "") -> list[float]:
    """Read ``n`` comma-separated numbers from a DMC reply (``TP``); :class:`ProtocolError`."""
    parts = reply.strip().split(",")
    if len(parts) != n:
        raise ProtocolError(f"Galil reply to {command!r} has {len(parts)} fields, expected {n}: "
                            f"{reply!r}")
    return [parse_number(p, command) for p in parts]


class GalilClient:
    """A TCP client for a Galil DMC controller (or :mod:`kinestat.sim.galil_server`).

    Every method sends one command and waits for its reply up to ``timeout`` seconds. A
    timeout or a closed link raises :class:`DeviceError` and closes the connection (a late
    reply would otherwise be taken for the next one); call :meth:`connect` to reconnect.
    """

    def __init__(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT, *,
                 timeout: float = 2.0) -> None:
        if not (isinstance(timeout, (int, float)) and timeout > 0 and math.isfinite(timeout)):
            raise InputError(f"GalilClient: timeout must be a positive number, got {timeout!r}")
        self.host = host
        self.port = int(port)
        self.timeout = float(timeout)
        self._sock: socket.socket | None = None
        self._buf = b""
        self._in_flight: str | None = None  # a command sent whose reply was not read yet
        self.axis5_residual = 0.0  # after move_compensated: true axis 5 past its encoder

    # -- connection
    def connect(self, timeout: float | None = None) -> GalilClient:
        """Open the TCP connection (closing any previous one); ``timeout`` bounds the connect
        (default the client's ``timeout``)."""
        self.close()
        t = self.timeout if timeout is None else float(timeout)
        try:
            self._sock = socket.create_connection((self.host, self.port), timeout=t)
        except OSError as exc:
            raise DeviceError(f"cannot connect to the Galil at {self.host}:{self.port}: {exc}. "
                              "Check the address and that the controller/simulator runs") from exc
        self._sock.settimeout(self.timeout)
        self._sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._buf = b""
        return self

    def close(self) -> None:
        """Close the connection (idempotent)."""
        s, self._sock = self._sock, None
        self._in_flight = None
        if s is not None:
            try:
                s.close()
            except OSError:
                pass

    @property
    def connected(self) -> bool:
        return self._sock is not None

    def __enter__(self) -> GalilClient:
        return self.connect() if self._sock is None else self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- raw commands
    def command(self, cmd: str, *, discard_pending: bool = False) -> str:
        """Send one command; return its data (without the ``:``), or raise.

        ``?`` -> :class:`GalilCommandError` with the ``TC1`` code and message; no reply within
        ``timeout`` or a closed link -> :class:`DeviceError`. Bytes already waiting before the
        command, bytes after its reply, or a reply of the wrong kind (data for a command, a
        bare ``:`` for a query: :mod:`kinestat.devices.galil_replies`) ->
        :class:`ProtocolError`, and the connection is closed. ``discard_pending`` drops the
        waiting bytes instead (for ``ST``, which must go out whatever came before).
        """
        reply = self._exchange(cmd, discard_pending=discard_pending)
        if reply == "?":
            code, message = self._tell_error()
            raise GalilCommandError(cmd, code, message)
        return reply

    def _fault(self, message: str) -> ProtocolError:
        self.close()
        return ProtocolError(f"Galil at {self.host}:{self.port}: {message}; connection closed")

    def _drain(self, cmd: str, discard: bool) -> bytes:
        """Read whatever is already waiting on the socket without blocking; a protocol fault
        unless ``discard`` (then the bytes are returned)."""
        assert self._sock is not None
        pending = self._buf
        self._buf = b""
        self._sock.setblocking(False)
        try:
            while True:
                try:
                    chunk = self._sock.recv(4096)
                except (BlockingIOError, InterruptedError):
                    break
                except OSError as exc:
                    self.close()
                    raise DeviceError(f"Galil link to {self.host}:{self.port} failed before "
                                      f"{cmd!r}: {exc}") from exc
                if not chunk:
                    self.close()
                    raise DeviceError(f"Galil at {self.host}:{self.port} closed the link "
                                      f"(seen before sending {cmd!r})")
                pending += chunk
        finally:
            if self._sock is not None:
                self._sock.settimeout(self.timeout)
        if pending and not discard:
            raise self._fault(f"{len(pending)} unexpected byte(s) {pending[:40]!r} waiting "
                              f"before {cmd!r} (a stale or unsolicited reply)")
        return pending

    def _exchange(self, cmd: str, *, discard_pending: bool = False) -> str:
        raw = self._encode(cmd)
        if self._sock is None:
            raise DeviceError(f"Galil at {self.host}:{self.port} is not connected; call "
                              "connect() first")
        unread = self._in_flight  # a previous exchange was interrupted before its reply
        if unread is not None and not discard_pending:
            raise self._fault(f"the reply to {unread!r} was never read (interrupted); "
                              f"{cmd!r} would take it for its own")
        pending = self._drain(cmd, discard_pending)
        self._in_flight = cmd
        try:
            self._sock.sendall(raw)
        except OSError as exc:
            self.close()
            raise DeviceError(f"Galil link to {self.host}:{self.port} failed while sending "
                              f"{cmd!r}: {exc}") from exc
        if unread is not None:
            # the interrupted command's reply may have been lost, be waiting, or still be on
            # its way: replies come in order, so ours is the last one to arrive
            reply, extra = self._receive_last(cmd, pending), b""
        else:
            reply, extra = self._receive(cmd)
        self._in_flight = None
        if extra:
            raise self._fault(f"{len(extra)} unexpected byte(s) {extra[:40]!r} after the reply "
                              f"to {cmd!r} (an unsolicited reply)")
        try:
            return match_reply(cmd, reply, f"Galil at {self.host}:{self.port}")
        except ProtocolError:
            self.close()
            raise

    def _receive_last(self, cmd: str, buf: bytes, quiet: float = 0.05) -> bytes:
        """The last of the replies arriving until none came for ``quiet`` seconds."""
        reply, extra = self._receive(cmd, buf)
        t_end = time.monotonic() + quiet
        while self._sock is not None:
            if (parts := split_reply(extra)) is not None:
                reply, extra = parts
                t_end = time.monotonic() + quiet
                continue
            left = t_end - time.monotonic()
            if left <= 0:
                break
            self._sock.settimeout(left)
            try:
                chunk = self._sock.recv(4096)
            except OSError:  # includes the quiet timeout
                break
            if not chunk:
                break
            extra += chunk
        if self._sock is not None:
            self._sock.settimeout(self.timeout)
        return reply

    def _receive(self, cmd: str, buf: bytes = b"") -> tuple[bytes, bytes]:
        """Read up to the end of one reply (the first ``:`` or ``?``): (reply, bytes after)."""
        deadline = time.monotonic() + self.timeout
        while (parts := split_reply(buf)) is None:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                self.close()
                raise DeviceError(f"Galil at {self.host}:{self.port} did not answer {cmd!r} "
                                  f"within {self.timeout} s; connection closed")
            assert self._sock is not None
            self._sock.settimeout(remaining)
            try:
                chunk = self._sock.recv(4096)
            except TimeoutError:
                continue
            except OSError as exc:
                self.close()
                raise DeviceError(f"Galil link to {self.host}:{self.port} failed while waiting "
                                  f"for the reply to {cmd!r}: {exc}") from exc
            if not chunk:
                self.close()
                raise DeviceError(f"Galil at {self.host}:{self.port} closed the link while "
                                  f"answering {cmd!r}")
            buf += chunk
        return parts

    def _send_unread(self, cmd: str) -> None:
        """Send ``cmd`` and mark it in flight, its reply not read yet (the link closed and a
        :class:`DeviceError` if the send fails)."""
        raw = self._encode(cmd)
        if self._sock is None:
            raise DeviceError(f"Galil at {self.host}:{self.port} is not connected")
        try:
            self._sock.sendall(raw)
        except OSError as exc:
            self.close()
            raise DeviceError(f"Galil link to {self.host}:{self.port} failed while sending "
                              f"{cmd!r}: {exc}") from exc
        self._in_flight = cmd

    def send_only(self, cmd: str) -> None:
        """Send ``cmd`` without reading its reply (for ``ST``, whose bare ``:`` proves nothing:
        it cannot be told from a late ``:`` of an earlier command). The next
        :meth:`tagged_query` skips that reply; any other command refuses to go on first."""
        self._send_unread(cmd)

    def tagged_query(self, operands: list[str], tag: int) -> list[float]:
        """``MG tag,op1,op2...``: the values of ``operands``, read from the one reply that
        begins with ``tag``.

        Replies come in the order of the commands, so the replies before the tagged one
        belong to earlier commands (an interrupted exchange, :meth:`send_only`, a late or
        duplicated reply) and are skipped; a reply carrying the tag but not exactly
        ``len(operands)`` finite numbers after it is garbled (:class:`ProtocolError`, link
        closed). No tagged reply within ``timeout``: :class:`DeviceError`, link closed.
        """
        if not (isinstance(tag, int) and 0 < tag < 10**6):
            raise InputError(f"tagged_query: tag must be an integer in 1..999999, got {tag!r}")
        cmd = "MG " + ",".join([str(tag), *operands])
        self._send_unread(cmd)
        buf, self._buf = self._buf, b""
        t_end = time.monotonic() + self.timeout
        while True:
            if time.monotonic() > t_end:  # earlier replies kept coming, never ours
                self.close()
                raise DeviceError(f"Galil at {self.host}:{self.port} did not answer {cmd!r} "
                                  f"within {self.timeout} s; connection closed")
            reply, buf = self._receive(cmd, buf)
            text = reply.decode("ascii", errors="replace")
            # the tagged reply's fields are the last ones (a garbled earlier reply may have
            # run into it: its ':' lost); no tag: an earlier command's reply, skipped
            fields = text[:-1].split()[-len(operands) - 1:]
            try:
                vals = [float(f) for f in fields]
            except ValueError:
                vals = []
            if not text.endswith(":") or len(vals) != len(operands) + 1 or vals[0] != tag:
                continue
            vals = vals[1:]
            if not all(math.isfinite(v) for v in vals):
                raise self._fault(f"garbled reply {text!r} to {cmd!r}")
            self._in_flight = None
            self._buf = buf  # bytes after it (a duplicate?) are a fault for the next command
            return vals

    def _encode(self, cmd: str) -> bytes:
        if not isinstance(cmd, str) or not cmd.strip():
            raise InputError(f"Galil command must be a non-empty string, got {cmd!r}")
        if any(c in cmd for c in ";\r\n"):
            raise InputError(f"send one Galil command at a time (no ';' or newline): {cmd!r}")
        try:
            return cmd.encode("ascii") + b"\r"
        except UnicodeEncodeError as exc:
            raise InputError(f"Galil commands are ASCII: {cmd!r}") from exc

    def _tell_error(self) -> tuple[int | None, str]:
        reply = self._exchange("TC1")
        if reply == "?":
            return None, "rejected, and TC1 was rejected too"
        head, _, rest = reply.strip().partition(" ")
        try:
            return int(head), rest.strip()
        except ValueError:
            return None, reply.strip()

    def query(self, cmd: str) -> float:
        """Send a query (``MG _TPA``, ...) and return its single numeric answer."""
        return parse_number(self.command(cmd), cmd)

    # -- typed helpers
    def position_counts(self) -> tuple[int, ...]:
        """Encoder positions of axes A..F (``TP``), in counts."""
        vals = parse_numbers(self.command("TP"), 6, "TP")
        return tuple(int(round(v)) for v in vals)

    def axis_position(self, axis: str) -> int:
        """Encoder position of one axis (``MG _TP<axis>``), in counts."""
        return int(round(self.query(f"MG _TP{_axis(axis)}")))

    def moving_axes(self) -> tuple[bool, ...]:
        """Which of axes A..F are profiling a motion (``MG _BGA`` ... ``MG _BGF``)."""
        return tuple(self.query(f"MG _BG{a}") != 0 for a in AXES)

    def is_moving(self) -> bool:
        """True while any axis is in motion."""
        return any(self.moving_axes())

    def move_absolute(self, counts: Any, speed: Any, accel: Any, decel: Any | None = None
                      ) -> None:
        """Start a move of axes A..F to absolute ``counts`` (``AC``, ``DC``, ``SP``, ``PA``,
        ``BG``). ``speed``/``accel``/``decel`` in counts/s and counts/s^2, one value or six;
        ``decel`` defaults to ``accel``. Returns at once: see :meth:`wait_motion_complete`.
        """
        c = _per_axis(counts, "move_absolute counts", positive=False)
        if any(not float(v).is_integer() for v in c):
            raise InputError(f"move_absolute: counts must be integers, got {c}")
        sp = _per_axis(speed, "move_absolute speed", positive=True)
        ac = _per_axis(accel, "move_absolute accel", positive=True)
        dc = _per_axis(accel if decel is None else decel, "move_absolute decel", positive=True)
        self.command("AC " + ",".join(_fmt(v) for v in ac))
        self.command("DC " + ",".join(_fmt(v) for v in dc))
        self.command("SP " + ",".join(_fmt(v) for v in sp))
        self.command("PA " + ",".join(_fmt(v) for v in c))
        self.command("BG")

    def wait_motion_complete(self, timeout: float = 30.0, poll_interval: float = 0.01
                             ) -> tuple[int, ...]:
        """Poll ``MG _BGx`` until no axis moves; return the final positions (``TP``).

        Raises :class:`DeviceError` if the motion is still running after ``timeout`` seconds
        (the axes are NOT stopped: call :meth:`stop` if that is what you want).
        """
        deadline = time.monotonic() + float(timeout)
        while self.is_moving():
            if time.monotonic() > deadline:
                raise DeviceError(f"Galil motion not complete after {timeout} s "
                                  f"(axes moving: {self.moving_axes()}); stop it or wait longer")
            if poll_interval > 0:
                time.sleep(poll_interval)
        return self.position_counts()

    def move_compensated(self, counts: Any, speed: Any, accel: Any, decel: Any | None = None,
                         *, timeout: float = 30.0, poll_interval: float = 0.01,
                         coupling: float = AXIS4_TO_5_COUPLING,
                         carry: float = 0.0) -> tuple[int, ...]:
        """Move to ``counts`` with the axis 4 -> 5 compensation, wait, and reset axis 5 (``DP``).

        The sequence of ``Axis_4_5_Correction.m`` + ``galil_control.m``: read axis 4, command
        axis 5 to the corrected position, wait for the motion, then ``DP ,,,,<axis5 target>``
        so the axis-5 encoder reads the true position again — only after the read-back
        positions agreed with the command (:func:`~kinestat.devices.motion_check.check_arrival`,
        else :class:`DeviceError` and no ``DP``). Returns the final ``TP``. ``carry`` is the
        fraction of a count the true axis 5 stood past its encoder before the move (the last
        move's :attr:`axis5_residual`; :func:`~kinestat.robots.puma762.axes.axis45_compensation`);
        after the move :attr:`axis5_residual` holds the new one.
        """
        c = _per_axis(counts, "move_compensated counts", positive=False)
        d_now = self.axis_position("D")
        corr = axis45_compensation(c[3], c[4], d_now, coupling, carry)
        c[4] = float(corr.axis5_command)
        self.move_absolute(c, speed, accel, decel)
        final = self.wait_motion_complete(timeout, poll_interval)
        check_arrival(c, final, what="compensated move")  # before DP: never hide a mismatch
        self.define_position({"E": int(corr.axis5_reset)})
        self.axis5_residual = float(corr.residual)
        return self.position_counts()

    def define_position(self, counts: Any) -> None:
        """``DP``: redefine encoder positions without motion; six counts, or ``{axis: count}``."""
        if isinstance(counts, dict):
            fields = [""] * 6
            for k, v in counts.items():
                fields[AXES.index(_axis(k))] = _fmt(_per_axis(v, "DP", positive=False)[0])
        else:
            vals = _per_axis(counts, "define_position counts", positive=False)
            fields = [_fmt(v) for v in vals]
        self.command("DP " + ",".join(fields))

    def stop(self) -> None:
        """``ST``: decelerate every axis to a stop (bytes waiting on the link are dropped
        first: the stop must go out whatever came before)."""
        self.command("ST", discard_pending=True)

    def motor_off(self) -> None:
        """``MO``: servo off on every axis."""
        self.command("MO")

    def servo_here(self) -> None:
        """``SH``: servo on, holding the current positions."""
        self.command("SH")

    def error_code(self) -> tuple[int | None, str]:
        """``TC1``: the last error's code and message."""
        return self._tell_error()


def _axis(axis: str) -> str:
    a = str(axis).upper()
    if len(a) != 1 or a not in AXES:
        raise InputError(f"unknown Galil axis {axis!r}; use one of {', '.join(AXES)}")
    return a

