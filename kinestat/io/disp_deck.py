"""DISP card decks (Nadkarni 1977, Appendix I): the data model, a reader, a writer, and the
decks of the thesis's seven numerical illustrations (Appendix II).

A deck is a sequence of 80-column card images read by DISP's subroutine READM:

========== ============ ===================================================================
set        format       contents
========== ============ ===================================================================
SET ONE    4I5          MS (analysis type 0..6), NP (positions or commands), IT (steps, 0 =
                        automatic), IO (information level 0/1)
SET TWO    3F10.2       3 × NP cards: per body position the origin, a point on +z and a point
                        in the z-x half plane on the +x side
SET THREE  (I10,5F10.3) NP cards (MS = 5 only, replaces SET TWO): NTY, DC(1..3), DD, THA
SET FOUR   I5, 5F10.3   N (≤ 15), then N cards R, ALPHA (deg), A, THETA (deg), PH (pitch)
SET FIVE   3F10.3       three points on x*(1): origin, +z of joint 1, on the normal a1 (+x)
========== ============ ===================================================================

Which sets a deck holds depends on MS (Table A1-1, :data:`SETS_BY_MS`).

Reading rules (a superset of what a Fortran formatted READ accepts, never contradicting it):

- A card is read in fixed columns when its text fits the layout (each field blank or one number,
  nothing after the last field): I5 = columns 1-5, F10.x = 10 columns; numbers may touch
  (``     0.000999999.000`` is 0.000 and 999999.000); a blank field, or a short card, reads as 0;
  blanks around a number inside its field are ignored (Fortran 77 BN mode).
- Otherwise the card is read as numbers separated by blanks (or tabs), when there are exactly as
  many as the format has fields; there an integer such as ``25`` means 25.0.
- In fixed columns a non-zero F field must have a decimal point: Fortran would read ``25`` in an
  F10.2 field as 0.25 (implied decimal point), a trap, so it is refused with a message instead of
  being read either way.
- Exponents (``1.5E3``, ``1.5D3``) are accepted; NaN and infinity are not.
- Blank lines, lines whose first non-blank character is ``#``, and text after a ``#`` are
  ignored, so a blank line is never a card: write an all-zero card with its zeros.
- Cards left over after the last set are an error (they usually mean a wrong NP or N).

Joint kinds follow DISP: PH > 1e5 marks a prismatic joint (the thesis writes 999999.00), PH = 0 a
revolute joint, 0 < |PH| ≤ 1e5 a screw joint. A screw pitch is a length per **radian** (Nadkarni's
h_j in eqs. 2-14 and 4-1, δr = h δθ with θ in radians), even though the deck gives angles in
degrees; DISP was only exercised on revolute and prismatic joints, so the thesis never fixes the
unit in data.
"""

from __future__ import annotations

import math
import operator
import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from kinestat.errors import InputError, KinestatError, ParseError
from kinestat.io.textfile import write_text_atomic
from kinestat.mechanism.joints import PRISMATIC_PITCH_THRESHOLD

__all__ = [
    "DeckJoint",
    "OperatorCommand",
    "DispDeck",
    "SETS_BY_MS",
    "MAX_JOINTS",
    "MAX_POSITIONS",
    "PRISMATIC_MARKER",
    "parse_deck",
    "read_deck",
    "format_deck",
    "write_deck",
    "deck_warnings",
    "list_embedded_decks",
    "embedded_deck",
    "embedded_deck_text",
]

#: Data sets present in a deck for each analysis type MS (Nadkarni Table A1-1).
SETS_BY_MS: dict[int, tuple[str, ...]] = {
    0: ("ONE", "TWO", "FOUR", "FIVE"),
    1: ("ONE", "TWO"),
    2: ("ONE", "FOUR", "FIVE"),
    3: ("ONE", "TWO", "FOUR", "FIVE"),
    4: ("ONE", "TWO", "FOUR", "FIVE"),
    5: ("ONE", "THREE", "FOUR", "FIVE"),
    6: ("ONE", "TWO", "FOUR", "FIVE"),
}

_MS_MEANING = {
    0: "displacement analysis type II (screw path)",
    1: "screw axes between consecutive body positions",
    2: "mechanism position data in the global frame (TRANSM)",
    3: "MS = 1 and MS = 2 together",
    4: "displacement analysis type III (hand point on a straight line)",
    5: "displacement analysis type IV (operator commands)",
    6: "displacement analysis type I (general, Ex. 4)",
}

#: DISP's limit on the number of joints in SET FOUR (Nadkarni App. I).
MAX_JOINTS = 15
#: DISP's limit on the number of body positions in SET TWO (Nadkarni App. I).
MAX_POSITIONS = 99
#: The pitch the thesis's decks write for a prismatic joint (any PH > 1e5 means prismatic).
PRISMATIC_MARKER = 999999.0

_GUIDANCE_MS = (0, 4, 5, 6)  # analyses that move a six-joint manipulator
_HAND7_MS = (0, 4, 6)  # may give the first hand position by the seventh joint (all-zero cards)
_I5_RANGE = (-9999, 99999)
_POINT_NAMES = ("origin", "point on +z", "point on +x side")
_FIVE_NAMES = ("origin of x*(1)", "point on +z of joint 1", "point on the normal a1 (+x)")


# --------------------------------------------------------------------------------------------
# The data model
# --------------------------------------------------------------------------------------------


def _finite_float(value, what: str) -> float:
    if isinstance(value, (str, bytes, bool)):
        raise InputError(f"{what} must be a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise InputError(f"{what} must be finite, got {x!r}")
    return x + 0.0  # -0.0 -> 0.0


def _int_value(value, what: str) -> int:
    if isinstance(value, bool):
        raise InputError(f"{what} must be an integer, got {value!r}")
    try:
        return operator.index(value)
    except TypeError:
        raise InputError(f"{what} must be an integer, got {value!r}") from None


def _pitch_problem(pitch: float) -> str | None:
    if pitch < -PRISMATIC_PITCH_THRESHOLD:
        return (
            f"pitch {pitch:g} is neither a screw pitch (|PH| <= 1e5) nor DISP's prismatic "
            "marker (PH > 1e5): write 999999.00 for a prismatic joint"
        )
    return None


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


@dataclass(frozen=True)
class OperatorCommand:
    """One SET THREE card (MS = 5): NTY, DC(1..3), DD, THA (Nadkarni App. I, eqs. 4-21, 4-22).

    ``nty`` 0: ``direction`` R is in the global frame; 1: in the frame fixed on the hand.
    ``distance`` is d (deck length unit), ``angle_deg`` is θ in degrees.
    """

    nty: int
    direction: tuple[float, float, float]
    distance: float
    angle_deg: float

    def __post_init__(self) -> None:
        nty = _int_value(self.nty, "command NTY")
        if nty not in (0, 1):
            raise InputError(
                f"command NTY must be 0 (global frame) or 1 (hand frame), got {nty}"
            )
        object.__setattr__(self, "nty", nty)
        try:
            comps = tuple(self.direction)
        except TypeError:
            raise InputError(
                f"command direction must be three numbers, got {self.direction!r}"
            ) from None
        if len(comps) != 3:
            raise InputError(f"command direction must have 3 components, got {len(comps)}")
        d = tuple(_finite_float(c, "command direction") for c in comps)
        problem = _direction_problem(d)
        if problem:
            raise InputError(f"command {problem}")
        object.__setattr__(self, "direction", d)
        object.__setattr__(self, "distance", _finite_float(self.distance, "command distance"))
        object.__setattr__(self, "angle_deg", _finite_float(self.angle_deg, "command angle"))

    @property
    def frame(self) -> str:
        """'global' (NTY = 0) or 'hand' (NTY = 1)."""
        return "global" if self.nty == 0 else "hand"

    @property
    def angle(self) -> float:
        """θ in radians."""
        return math.radians(self.angle_deg)


def _direction_problem(d: Sequence[float]) -> str | None:
    if max(abs(c) for c in d) == 0.0:
        return "direction DC is the zero vector: give the direction R of the motion"
    return None


def _frame_problem(points: np.ndarray) -> str | None:
    """Why three points (origin, +z point, +x-side point) do not fix a frame, or None."""
    scale = float(np.max(np.abs(points)))
    if scale == 0.0:
        return "all three points are zero"
    q = points / scale
    z = q[1] - q[0]
    nz = float(np.linalg.norm(z))
    if nz <= 1e-12:  # distances below ~1e4 rounding errors of the largest coordinate
        return "the point on +z coincides with the origin point"
    if float(np.linalg.norm(np.cross(z / nz, q[2] - q[0]))) <= 1e-12:
        return "the third point lies on the z axis (the three points are collinear)"
    return None


def _np_problem(ms: int, np_: int) -> str | None:
    lo, hi = _I5_RANGE
    if not lo <= np_ <= hi:
        return f"NP = {np_} does not fit the I5 field ({lo}..{hi})"
    if ms == 5 and np_ < 1:
        return f"NP = {np_}: MS = 5 needs NP >= 1 operator commands (SET THREE cards)"
    if ms in (0, 1, 3, 4, 6):
        what = "body positions" if ms in (1, 3) else "hand positions (initial and targets)"
        if np_ < 2:
            return f"NP = {np_}: MS = {ms} needs NP >= 2 {what}"
        if np_ > MAX_POSITIONS:
            return f"NP = {np_} exceeds DISP's limit of {MAX_POSITIONS} positions"
    return None


def _it_problem(it: int) -> str | None:
    if not 0 <= it <= _I5_RANGE[1]:
        return f"IT = {it}: the number of steps must be 0 (automatic) .. {_I5_RANGE[1]}"
    return None


def _io_problem(io: int) -> str | None:
    if io not in (0, 1):
        return f"IO = {io}: the information level must be 0 (complete) or 1 (restricted)"
    return None


def _ms_problem(ms: int) -> str | None:
    if ms not in SETS_BY_MS:
        return f"MS = {ms} is not an analysis type: use 0..6 (Table A1-1)"
    return None


def _n_problem(ms: int, n: int, hand7: bool) -> str | None:
    if not 1 <= n <= MAX_JOINTS:
        return f"N = {n}: the number of joints must be 1..{MAX_JOINTS} (DISP's limit)"
    if ms == 5 and n < 7:
        return (
            f"N = {n}: MS = 5 has no SET TWO, so the hand must be defined by a seventh "
            "(imaginary) joint: give N >= 7"
        )
    if hand7 and n < 7:
        return (
            f"N = {n}: SET TWO's first three cards are zero, which means 'initial hand given "
            "by the seventh joint': give N >= 7 or the first hand position's points"
        )
    if ms in _GUIDANCE_MS and n < 6:
        return f"N = {n}: MS = {ms} moves a six-joint manipulator: give N >= 6"
    return None


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float) + 0.0  # own copy; -0.0 -> 0.0
    a.setflags(write=False)
    return a


def _points_array(value, shape: tuple[int, ...], what: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} must be an array of numbers of shape {shape}") from None
    if a.shape != shape:
        raise InputError(f"{what} must have shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{what} contains NaN or infinity")
    return _readonly(a)


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
        return _readonly(np.array(rows, dtype=float).reshape(len(rows), 5))

    @property
    def hand_from_seventh_joint(self) -> bool:
        """True when SET TWO's first three cards are all zero: the initial hand frame is x*(7)
        of the seventh (imaginary) joint of SET FOUR (App. I, option 2; MS = 0, 4, 6)."""
        return self.positions is not None and not np.any(self.positions[0])


def _raise_if(problem: str | None) -> None:
    if problem:
        raise InputError(problem)


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


# --------------------------------------------------------------------------------------------
# Card layouts
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Field:
    name: str
    kind: str  # "I" integer, "F" real
    width: int
    decimals: int = 0


@dataclass(frozen=True)
class _Spec:
    label: str  # e.g. "SET FOUR, joint card 3"
    fmt: str  # e.g. "5F10.3"
    fields: tuple[_Field, ...]

    @property
    def width(self) -> int:
        return sum(f.width for f in self.fields)


def _spec_one() -> _Spec:
    return _Spec("SET ONE", "4I5", tuple(_Field(n, "I", 5) for n in ("MS", "NP", "IT", "IO")))


def _spec_two(card: int) -> _Spec:
    k, j = divmod(card - 1, 3)
    label = f"SET TWO, card {card} (position {k + 1}, {_POINT_NAMES[j]})"
    return _Spec(label, "3F10.2", tuple(_Field(n, "F", 10, 2) for n in ("x", "y", "z")))


def _spec_three(i: int) -> _Spec:
    fields = (
        _Field(f"NTY({i})", "I", 10),
        *(_Field(f"DC({j},{i})", "F", 10, 3) for j in (1, 2, 3)),
        _Field(f"DD({i})", "F", 10, 3),
        _Field(f"THA({i})", "F", 10, 3),
    )
    return _Spec(f"SET THREE, command card {i}", "(I10,5F10.3)", fields)


def _spec_n() -> _Spec:
    return _Spec("SET FOUR, first card", "I5", (_Field("N", "I", 5),))


def _spec_joint(i: int) -> _Spec:
    names = ("R", "ALPHA", "A", "THETA", "PH")
    return _Spec(
        f"SET FOUR, joint card {i}", "5F10.3",
        tuple(_Field(f"{n}({i})", "F", 10, 3) for n in names),
    )


def _spec_five(card: int) -> _Spec:
    return _Spec(
        f"SET FIVE, card {card} ({_FIVE_NAMES[card - 1]})", "3F10.3",
        tuple(_Field(n, "F", 10, 3) for n in ("x", "y", "z")),
    )


# --------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------

_INT_RE = re.compile(r"[+-]?[0-9]{1,12}", re.ASCII)
_REAL_RE = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[EeDd][+-]?[0-9]+)?", re.ASCII)
_TOKEN_RE = re.compile(r"\S+")


@dataclass(frozen=True)
class _Card:
    line: int  # 1-based line number in the file
    text: str  # without the comment and the line end


@dataclass(frozen=True)
class _Read:
    card: _Card
    spec: _Spec
    values: tuple
    columns: tuple[tuple[int, int], ...]


class _Cursor:
    def __init__(self, cards: list[_Card], source: str) -> None:
        self.cards = cards
        self.source = source
        self.i = 0

    def take(self, spec: _Spec, missing: str) -> _Read:
        if self.i >= len(self.cards):
            last = self.cards[-1].line if self.cards else None
            raise ParseError(missing, file=self.source, line=last, card=spec.label)
        card = self.cards[self.i]
        self.i += 1
        return _read_card(card, spec, self.source)

    def fail(self, read: _Read, index: int | None, message: str) -> ParseError:
        f = read.spec.fields[index] if index is not None else None
        return ParseError(
            message,
            file=self.source,
            line=read.card.line,
            card=read.spec.label,
            field=f.name if f else None,
            columns=read.columns[index] if index is not None else None,
        )


def _cards(text: str) -> list[_Card]:
    cards = []
    for n, raw in enumerate(text.split("\n"), start=1):
        line = raw.removesuffix("\r")
        body = line.split("#", 1)[0]
        if body.strip():
            cards.append(_Card(n, body))
    return cards


def _convert(token: str, f: _Field, *, fixed: bool) -> tuple[int | float | None, str | None]:
    """(value, None) or (None, why the token is not a valid value for the field)."""
    if f.kind == "I":
        if not _INT_RE.fullmatch(token):
            return None, f"expected an integer (I{f.width}), found {token!r}"
        return int(token), None
    if not _REAL_RE.fullmatch(token):
        return None, f"expected a number (F{f.width}.{f.decimals}), found {token!r}"
    x = float(token.replace("D", "E").replace("d", "e"))
    if not math.isfinite(x):
        return None, f"{token!r} is not a finite number"
    mantissa = re.split(r"[EeDd]", token, maxsplit=1)[0]
    if fixed and "." not in mantissa and x != 0.0:
        implied = x / 10**f.decimals
        return None, (
            f"{token!r} has no decimal point: Fortran F{f.width}.{f.decimals} would read it as "
            f"{implied:g} (implied decimal point); write {x:g}. or {implied:g} explicitly"
        )
    return x + 0.0, None


def _split_fixed(text: str, spec: _Spec) -> tuple[list[tuple[str, tuple[int, int]]] | None, str]:
    """Fields in fixed columns, or (None, why the text does not fit the column layout)."""
    if "\t" in text:
        return None, "it contains a tab"
    out = []
    start = 0
    for f in spec.fields:
        chunk = text[start : start + f.width]
        token = chunk.strip()
        if _TOKEN_RE.fullmatch(token) is None and token:
            return None, f"columns {start + 1}-{start + f.width} hold {chunk!r}, not one number"
        out.append((token, (start + 1, start + f.width)))
        start += f.width
    rest = text[start:]
    if rest.strip():
        return None, f"there is text after column {start}: {rest.strip()!r}"
    return out, ""


def _read_card(card: _Card, spec: _Spec, source: str) -> _Read:
    k = len(spec.fields)
    fixed, why = _split_fixed(card.text, spec)

    def error(index: int, cols: tuple[int, int], message: str) -> ParseError:
        return ParseError(
            message, file=source, line=card.line, card=spec.label,
            field=spec.fields[index].name, columns=cols,
        )

    if fixed is not None:
        values = []
        for i, (f, (token, cols)) in enumerate(zip(spec.fields, fixed, strict=True)):
            if not token:
                values.append(0 if f.kind == "I" else 0.0)
                continue
            v, problem = _convert(token, f, fixed=True)
            if problem:
                raise error(i, cols, problem)
            values.append(v)
        return _Read(card, spec, tuple(values), tuple(c for _, c in fixed))

    tokens = [(m.group(), (m.start() + 1, m.end())) for m in _TOKEN_RE.finditer(card.text)]
    if len(tokens) != k:
        names = ", ".join(f.name for f in spec.fields)
        raise ParseError(
            f"expected {spec.fmt} ({names} in columns 1-{spec.width}) or {k} numbers separated "
            f"by blanks; found {len(tokens)} blank-separated item(s), and the fixed columns do "
            f"not fit because {why}",
            file=source, line=card.line, card=spec.label,
        )
    values = []
    for i, (f, (token, cols)) in enumerate(zip(spec.fields, tokens, strict=True)):
        v, problem = _convert(token, f, fixed=False)
        if problem:
            raise error(i, cols, problem)
        values.append(v)
    return _Read(card, spec, tuple(values), tuple(c for _, c in tokens))


def _decode(data: bytes, source: str) -> str:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise ParseError(
            f"byte 0x{data[exc.start]:02x} at offset {exc.start} is not text (UTF-8); a DISP "
            "deck is plain ASCII card images",
            file=source, line=line,
        ) from None
    return text.removeprefix("\ufeff")


def read_deck(path_or_text: str | os.PathLike | bytes) -> DispDeck:
    """Read a DISP deck from a file path, from deck text (a str with a line break) or bytes.

    Raises :class:`ParseError` (file, line, card, field, columns) for a malformed deck and
    :class:`InputError` when the file cannot be read.
    """
    if isinstance(path_or_text, bytes):
        return parse_deck(_decode(path_or_text, "<bytes>"), source="<bytes>")
    if isinstance(path_or_text, str) and ("\n" in path_or_text or "\r" in path_or_text):
        return parse_deck(path_or_text)
    if not isinstance(path_or_text, (str, os.PathLike)):
        raise InputError(
            f"read_deck takes a path, deck text or bytes, got {type(path_or_text).__name__}"
        )
    path = Path(path_or_text)
    try:
        data = path.read_bytes()
    except (OSError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc)
        raise InputError(
            f"cannot read DISP deck {str(path)!r}: {reason}; check the path (deck text must "
            "contain line breaks)"
        ) from None
    return parse_deck(_decode(data, str(path)), source=str(path))


def parse_deck(text: str, *, source: str = "<string>") -> DispDeck:
    """Parse the text of a DISP deck (Nadkarni App. I, SET ONE to SET FIVE).

    See the module docstring for the reading rules. Every problem raises :class:`ParseError`
    naming ``source``, the line, the SET and card, the field and its columns.
    """
    if not isinstance(text, str):
        raise InputError(f"parse_deck takes the deck text (str), got {type(text).__name__}")
    cur = _Cursor(_cards(text.removeprefix("\ufeff")), source)

    one = cur.take(_spec_one(), "the deck is empty: expected SET ONE (MS, NP, IT, IO; 4I5)")
    ms, np_, it, io = one.values
    if problem := _ms_problem(ms):
        raise cur.fail(one, 0, problem)
    for index, problem in ((1, _np_problem(ms, np_)), (2, _it_problem(it)), (3, _io_problem(io))):
        if problem:
            raise cur.fail(one, index, problem)
    sets = SETS_BY_MS[ms]

    positions = None
    if "TWO" in sets:
        n_cards = 3 * np_
        pts = np.zeros((n_cards, 3))
        reads = []
        for c in range(1, n_cards + 1):
            r = cur.take(
                _spec_two(c),
                f"the deck ends after {c - 1} of the {n_cards} SET TWO cards (3 x NP, "
                f"NP = {np_}); add the missing cards or fix NP in SET ONE",
            )
            pts[c - 1] = r.values
            reads.append(r)
        positions = pts.reshape(np_, 3, 3)
        for k in range(np_):
            if k == 0 and not np.any(positions[0]):
                if ms in _HAND7_MS:
                    continue
                raise cur.fail(
                    reads[0], None,
                    "SET TWO's first three cards are all zero, which means 'initial hand given "
                    f"by the seventh joint'; that option is only for MS = 0, 4, 6, and MS = {ms} "
                    "needs the first body position's three points",
                )
            if problem := _frame_problem(positions[k]):
                raise ParseError(
                    f"the three points do not fix a frame: {problem}",
                    file=source, line=reads[3 * k].card.line,
                    card=f"SET TWO, cards {3 * k + 1}-{3 * k + 3} (position {k + 1})",
                )

    commands = None
    if "THREE" in sets:
        cmds = []
        for i in range(1, np_ + 1):
            r = cur.take(
                _spec_three(i),
                f"the deck ends after {i - 1} of the {np_} SET THREE cards (NP = {np_}); add "
                "the missing commands or fix NP in SET ONE",
            )
            nty, dx, dy, dz, dd, tha = r.values
            if nty not in (0, 1):
                raise cur.fail(
                    r, 0, f"NTY = {nty}: use 0 (global frame) or 1 (frame fixed on the hand)"
                )
            if problem := _direction_problem((dx, dy, dz)):
                raise cur.fail(r, None, problem)
            cmds.append(OperatorCommand(nty, (dx, dy, dz), dd, tha))
        commands = tuple(cmds)

    joints = None
    if "FOUR" in sets:
        rn = cur.take(
            _spec_n(),
            "the deck ends before SET FOUR: expected the card with N, the number of joints (I5)",
        )
        (n,) = rn.values
        hand7 = positions is not None and not np.any(positions[0])
        if problem := _n_problem(ms, n, hand7):
            raise cur.fail(rn, 0, problem)
        js = []
        for i in range(1, n + 1):
            r = cur.take(
                _spec_joint(i),
                f"the deck ends after {i - 1} of the N = {n} SET FOUR joint cards; add the "
                "missing joints or fix N",
            )
            if problem := _pitch_problem(r.values[4]):
                raise cur.fail(r, 4, problem)
            js.append(DeckJoint(*r.values))
        joints = tuple(js)

    frame_points = None
    if "FIVE" in sets:
        reads = [
            cur.take(
                _spec_five(c),
                f"the deck ends after {c - 1} of the 3 SET FIVE cards (three points on x*(1))",
            )
            for c in (1, 2, 3)
        ]
        frame_points = np.array([r.values for r in reads], dtype=float)
        if problem := _frame_problem(frame_points):
            raise ParseError(
                f"the three points do not fix the x*(1) frame: {problem}",
                file=source, line=reads[0].card.line, card="SET FIVE",
            )

    if cur.i < len(cur.cards):
        extra = cur.cards[cur.i]
        last = "SET " + sets[-1]
        raise ParseError(
            f"unexpected card {extra.text.strip()!r}: an MS = {ms} deck ends after {last} "
            f"(sets {', '.join(sets)}, Table A1-1); remove it or check NP and N",
            file=source, line=extra.line,
        )
    try:
        return DispDeck(ms, np_, it, io, positions, commands, joints, frame_points, source=source)
    except KinestatError as exc:  # every check above should have caught it first
        raise ParseError(str(exc), file=source) from None


# --------------------------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------------------------


def _format_int(value: int, f: _Field, where: str) -> str:
    s = str(value)
    if len(s) > f.width:
        raise InputError(f"{where}: {f.name} = {value} does not fit the I{f.width} field")
    return s.rjust(f.width)


def _format_real(value: float, f: _Field, where: str, exact: bool) -> str:
    """The shortest-precision text of ``value`` that fits the field and reads back exactly."""
    w = f.width
    candidates = []
    # the format's decimals first, then more, then fewer ('#' keeps the point of "25.")
    for dec in [*range(f.decimals, w), *range(f.decimals - 1, -1, -1)]:
        s = f"{value:#.{dec}f}"
        if len(s) > w:
            continue
        candidates.append(s)
        if float(s) == value:
            return s.rjust(w)
    for p in range(w):
        s = f"{value:#.{p}E}"
        if len(s) > w:
            break
        candidates.append(s)
        if float(s) == value:
            return s.rjust(w)
    if exact or not candidates:
        raise InputError(
            f"{where}: {f.name} = {value!r} cannot be written exactly in a {w}-column field; "
            "round it (e.g. to the format's decimals) or call write_deck(..., exact=False) "
            "to round to the field"
        )
    best = min(candidates, key=lambda s: (abs(float(s) - value), -len(s)))
    return best.rjust(w)


def _format_card(values: Sequence, spec: _Spec, exact: bool) -> str:
    parts = []
    for v, f in zip(values, spec.fields, strict=True):
        if f.kind == "I":
            parts.append(_format_int(int(v), f, spec.label))
        else:
            parts.append(_format_real(float(v), f, spec.label, exact))
    return "".join(parts)


def format_deck(deck: DispDeck, *, exact: bool = True) -> str:
    """The deck as fixed-width card images in the thesis's formats (4I5, 3F10.2, ...).

    Each number is written with the format's decimals when that is exact, else with more
    decimals or an exponent that still fits its 10 columns. With ``exact=True`` (default) a number
    that cannot be written exactly raises :class:`InputError`, so ``parse_deck(format_deck(d))
    == d``; ``exact=False`` rounds it to the field instead.
    """
    if not isinstance(deck, DispDeck):
        raise InputError(f"format_deck takes a DispDeck, got {type(deck).__name__}")
    cards = [_format_card((deck.ms, deck.np_, deck.it, deck.io), _spec_one(), exact)]
    if deck.positions is not None:
        for c, point in enumerate(deck.positions.reshape(-1, 3), start=1):
            cards.append(_format_card(point, _spec_two(c), exact))
    for i, cmd in enumerate(deck.commands or (), start=1):
        values = (cmd.nty, *cmd.direction, cmd.distance, cmd.angle_deg)
        cards.append(_format_card(values, _spec_three(i), exact))
    if deck.joints is not None:
        cards.append(_format_card((len(deck.joints),), _spec_n(), exact))
        for i, j in enumerate(deck.joints, start=1):
            values = (j.r, j.alpha_deg, j.a, j.theta_deg, j.pitch)
            cards.append(_format_card(values, _spec_joint(i), exact))
    if deck.frame_points is not None:
        for c, point in enumerate(deck.frame_points, start=1):
            cards.append(_format_card(point, _spec_five(c), exact))
    return "\n".join(cards) + "\n"


def write_deck(
    deck: DispDeck, path: str | os.PathLike | None = None, *, exact: bool = True
) -> str:
    """Format ``deck`` (see :func:`format_deck`) and, given ``path``, write it atomically.

    The text is written to a temporary file in the target directory and renamed over ``path``,
    so an error never leaves a half-written deck. Returns the text.
    """
    text = format_deck(deck, exact=exact)
    if path is None:
        return text
    write_text_atomic(path, text, "DISP deck", encoding="ascii")
    return text


# --------------------------------------------------------------------------------------------
# Embedded decks (Nadkarni 1977, Appendix II)
# --------------------------------------------------------------------------------------------

_EMBEDDED: dict[str, str] = {
    "illustration1": "MS = 1: screw axes between three body positions (Table A2-1)",
    "illustration2": "MS = 2: manipulator configuration #1 in the global frame (Table A2-3)",
    "illustration3": "MS = 3: Illustrations 1 and 2 in one run (Table A2-4, expanded)",
    "illustration4": "MS = 0: screw-path guidance of configuration #1 (Table A2-5, expanded)",
    "illustration5": "MS = 4: straight-line guidance of configuration #2 (Table A2-8, as printed)",
    "illustration5-corrected": "Illustration 5 with a7 = 1.00 (Table A2-7) for the printed 0.00",
    "illustration5-published": "Illustration 5 as Table A2-9 implies: b2 = (15, -10, 20), IT = 27",
    "illustration6": "MS = 5: two operator commands (Table A2-10, expanded, as printed)",
    "illustration6-corrected": "Illustration 6 with a7 = 1.00 (Table A2-7) for the printed 0.00",
    "illustration7": "MS = 6: general guidance to a target (Table A2-12, expanded; NP = 2)",
    "illustration7-corrected": "Illustration 7 with a7 = 1.00 (Table A2-7) for the printed 0.00",
}


def _decks_dir():
    return resources.files("kinestat").joinpath("data", "decks")


def list_embedded_decks() -> dict[str, str]:
    """Names of the embedded thesis decks, each with a one-line description."""
    present = {
        p.name.removesuffix(".dat") for p in _decks_dir().iterdir() if p.name.endswith(".dat")
    }
    return {name: desc for name, desc in _EMBEDDED.items() if name in present}


def _embedded_name(name: str) -> str:
    if not isinstance(name, str):
        raise InputError(f"an embedded deck name is a string, got {type(name).__name__}")
    key = name.strip().lower().removesuffix(".dat")
    if key not in _EMBEDDED:
        raise InputError(
            f"no embedded DISP deck named {name!r}; available: {', '.join(_EMBEDDED)}"
        )
    return key


def embedded_deck_text(name: str) -> str:
    """The card images of an embedded deck (e.g. ``"illustration5"``), as stored."""
    key = _embedded_name(name)
    return _decks_dir().joinpath(f"{key}.dat").read_text(encoding="ascii")


def embedded_deck(name: str) -> DispDeck:
    """Load an embedded thesis deck: ``"illustration1"`` … ``"illustration7"`` (Nadkarni
    App. II) or a ``"-corrected"``/``"-published"`` variant (see :func:`list_embedded_decks`)."""
    key = _embedded_name(name)
    return parse_deck(embedded_deck_text(key), source=f"kinestat/data/decks/{key}.dat")
