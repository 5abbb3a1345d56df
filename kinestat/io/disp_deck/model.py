"""The DISP deck data model: joints (SET FOUR), the deck (SET ONE to FIVE), advice."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from kinestat.errors import InputError
from kinestat.io.disp_deck.commands import OperatorCommand
from kinestat.io.disp_deck.validate import (
    _HAND7_MS,
    _MS_MEANING,
    SETS_BY_MS,
    _finite_float,
    _frame_problem,
    _int_value,
    _io_problem,
    _it_problem,
    _ms_problem,
    _n_problem,
    _np_problem,
    _pitch_problem,
    _raise_if,
)
from kinestat.mechanism.joints import PRISMATIC_PITCH_THRESHOLD
from kinestat.spatial.validate import frozen


@dataclass(frozen=True)
class DeckJoint:
    """One SET FOUR joint card: R(I), ALPHA(I), A(I), THETA(I), PH(I) (Nadkarni App. I, ch. II).

    ``r`` and ``a`` are lengths in the deck's unit, ``alpha_deg`` and ``theta_deg`` degrees as
    punched; ``pitch`` is PH: 0 revolute, > 1e5 prismatic (999999.00), otherwise a screw joint
    whose pitch is a length per radian (eq. 2-14: δr = h δθ, θ in radians).
    """

    r: float
    alpha_deg: float
    a: float
    theta_deg: float
    pitch: float = 0.0

    def __post_init__(self) -> None:
        for name in ("r", "alpha_deg", "a", "theta_deg", "pitch"):
            object.__setattr__(self, name, _finite_float(getattr(self, name), f"joint {name}"))
        problem = _pitch_problem(self.pitch)
        if problem:
            raise InputError(f"joint {problem}")

    @property
    def kind(self) -> str:
        """'prismatic' (PH > 1e5), 'revolute' (PH = 0) or 'screw' (0 < |PH| ≤ 1e5)."""
        if self.pitch > PRISMATIC_PITCH_THRESHOLD:
            return "prismatic"
        return "revolute" if self.pitch == 0.0 else "screw"

    @property
    def alpha(self) -> float:
        """α_i in radians."""
        return math.radians(self.alpha_deg)

    @property
    def theta(self) -> float:
        """θ_i in radians."""
        return math.radians(self.theta_deg)


def _points_array(value, shape: tuple[int, ...], what: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} must be an array of numbers of shape {shape}") from None
    if a.shape != shape:
        raise InputError(f"{what} must have shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{what} contains NaN or infinity")
    return frozen(a + 0.0)  # own copy; -0.0 -> 0.0


@dataclass(frozen=True, eq=False)
class DispDeck:
    """A DISP input deck (Nadkarni App. I): SET ONE's MS, NP, IT, IO and the sets MS needs.

    - ``positions``: SET TWO, ``(NP, 3, 3)``: per position the origin, a point on +z and a point
      in the z-x half plane (+x side). All-zero first position = "initial hand given by the
      seventh joint" (MS = 0, 4, 6), see :attr:`hand_from_seventh_joint`.
    - ``commands``: SET THREE (MS = 5), NP :class:`OperatorCommand`.
    - ``joints``: SET FOUR, N ≤ 15 :class:`DeckJoint` (the seventh is the hand's, for guidance).
    - ``frame_points``: SET FIVE, ``(3, 3)``: x*(1)'s origin, a point on +z of joint 1, a point
      on the normal a1.
    - ``source``: where the deck came from (for messages; not compared).

    ``np_`` defaults to the number of positions or commands (0 for MS = 2, where DISP ignores
    it). Sets not used by MS must be None. Arrays are read-only copies. Decks compare equal when
    every number is equal.
    """

    ms: int
    np_: int | None = None
    it: int = 0
    io: int = 0
    positions: np.ndarray | None = None
    commands: tuple[OperatorCommand, ...] | None = None
    joints: tuple[DeckJoint, ...] | None = None
    frame_points: np.ndarray | None = None
    source: str = field(default="<deck>", compare=False)

    def __post_init__(self) -> None:
        ms = _int_value(self.ms, "MS")
        _raise_if(_ms_problem(ms))
        sets = SETS_BY_MS[ms]
        object.__setattr__(self, "ms", ms)
        for name, set_name in (
            ("positions", "TWO"),
            ("commands", "THREE"),
            ("joints", "FOUR"),
            ("frame_points", "FIVE"),
        ):
            present = getattr(self, name) is not None
            if present and set_name not in sets:
                raise InputError(
                    f"MS = {ms} decks have no SET {set_name} (Table A1-1): pass {name}=None"
                )
            if not present and set_name in sets:
                raise InputError(f"MS = {ms} decks need SET {set_name}: give {name}")

        if self.np_ is not None:
            np_ = _int_value(self.np_, "NP")
        elif self.positions is not None or self.commands is not None:
            given = self.positions if self.positions is not None else self.commands
            try:
                np_ = len(given)
            except TypeError:
                raise InputError(
                    f"positions/commands must be a sequence, got {type(given).__name__}"
                ) from None
        else:
            np_ = 0
        _raise_if(_np_problem(ms, np_))
        object.__setattr__(self, "np_", np_)
        it = _int_value(self.it, "IT")
        io = _int_value(self.io, "IO")
        _raise_if(_it_problem(it))
        _raise_if(_io_problem(io))
        object.__setattr__(self, "it", it)
        object.__setattr__(self, "io", io)

        if self.positions is not None:
            positions = _points_array(self.positions, (np_, 3, 3), "SET TWO positions")
            for k in range(np_):
                if k == 0 and ms in _HAND7_MS and not np.any(positions[0]):
                    continue
                problem = _frame_problem(positions[k])
                if problem:
                    if k == 0 and not np.any(positions[0]):
                        problem += (
                            " (an all-zero first position means 'hand given by the seventh "
                            "joint', only for MS = 0, 4, 6)"
                        )
                    raise InputError(f"SET TWO position {k + 1}: {problem}")
            object.__setattr__(self, "positions", positions)
        if self.commands is not None:
            commands = tuple(_as_command(c) for c in _as_tuple(self.commands, "commands"))
            if len(commands) != np_:
                raise InputError(f"SET THREE has {len(commands)} commands but NP = {np_}")
            object.__setattr__(self, "commands", commands)
        if self.joints is not None:
            joints = tuple(_as_joint(j) for j in _as_tuple(self.joints, "joints"))
            _raise_if(_n_problem(ms, len(joints), self.hand_from_seventh_joint))
            object.__setattr__(self, "joints", joints)
        if self.frame_points is not None:
            fp = _points_array(self.frame_points, (3, 3), "SET FIVE frame points")
            problem = _frame_problem(fp)
            if problem:
                raise InputError(f"SET FIVE: {problem}")
            object.__setattr__(self, "frame_points", fp)

    # -- comparison ---------------------------------------------------------------------------
    def _key(self) -> tuple:
        def arr(a):
            return None if a is None else (a.shape, a.tobytes())

        return (self.ms, self.np_, self.it, self.io, arr(self.positions), self.commands,
                self.joints, arr(self.frame_points))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, DispDeck):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    # -- helpers ------------------------------------------------------------------------------
    @property
    def sets(self) -> tuple[str, ...]:
        """The data sets this deck holds, e.g. ('ONE', 'TWO', 'FOUR', 'FIVE') (Table A1-1)."""
        return SETS_BY_MS[self.ms]

    @property
    def analysis(self) -> str:
        """What DISP does with this deck (App. I, READM's MS)."""
        return _MS_MEANING[self.ms]

    @property
    def joint_kinds(self) -> tuple[str, ...]:
        """Per SET FOUR joint: 'revolute' | 'prismatic' | 'screw' (empty without SET FOUR)."""
        return tuple(j.kind for j in self.joints or ())

    @property
    def joint_table(self) -> np.ndarray:
        """SET FOUR as an ``(N, 5)`` array ``[r, alpha, a, theta, pitch]``, angles in radians.

        The layout :func:`kinestat.mechanism.nadkarni.mechanism_frames` and
        :func:`kinestat.mechanism.chain.from_nadkarni` take. ``(0, 5)`` without SET FOUR.
        """
        rows = [(j.r, j.alpha, j.a, j.theta, j.pitch) for j in self.joints or ()]
        return frozen(np.array(rows, dtype=float).reshape(len(rows), 5) + 0.0)

    @property
    def hand_from_seventh_joint(self) -> bool:
        """True when SET TWO's first three cards are all zero: the initial hand frame is x*(7)
        of the seventh (imaginary) joint of SET FOUR (App. I, option 2; MS = 0, 4, 6)."""
        return self.positions is not None and not np.any(self.positions[0])


def _as_tuple(value, what: str) -> tuple:
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise InputError(f"{what} must be a sequence, got {type(value).__name__}")
    return tuple(value)


def _as_joint(j) -> DeckJoint:
    if isinstance(j, DeckJoint):
        return j
    row = _as_tuple(j, "a joint")
    if len(row) not in (4, 5):
        raise InputError(
            f"a joint needs 4 or 5 values (r, alpha_deg, a, theta_deg[, pitch]), got {len(row)}"
        )
    return DeckJoint(*row)


def _as_command(c) -> OperatorCommand:
    if isinstance(c, OperatorCommand):
        return c
    row = _as_tuple(c, "a command")
    if len(row) != 4:
        raise InputError(
            "a command needs 4 values (nty, (dx, dy, dz), distance, angle_deg), "
            f"got {len(row)}"
        )
    return OperatorCommand(*row)


def deck_warnings(deck: DispDeck) -> tuple[str, ...]:
    """Advice on a valid deck that DISP would still mishandle or that looks unintended.

    - Nadkarni App. I: when the seventh joint defines the hand (all-zero first position, or
      MS = 5), a7 must be positive: the hand's third point is the x(7) origin, a7 along the
      seventh normal, so a7 = 0 collapses it onto the hand origin.
    - SET THREE directions that are not unit vectors (DC gives the unit vector R of eq. 4-21).
    """
    out: list[str] = []
    uses_hand7 = deck.hand_from_seventh_joint or deck.ms == 5
    if uses_hand7 and deck.joints is not None and len(deck.joints) >= 7:
        a7 = deck.joints[6].a
        if a7 <= 0.0:
            out.append(
                f"a7 = {a7:g}: the seventh joint defines the hand, and Nadkarni App. I requires "
                "a7 > 0 (the hand's x point is a7 along the seventh normal); e.g. a7 = 1.00"
            )
    for i, c in enumerate(deck.commands or (), start=1):
        norm = math.hypot(*c.direction)
        if abs(norm - 1.0) > 1e-3:
            out.append(
                f"SET THREE command {i}: direction DC = {c.direction} has length {norm:.6g}, "
                "not 1 (eq. 4-21's R is a unit vector)"
            )
    return tuple(out)
