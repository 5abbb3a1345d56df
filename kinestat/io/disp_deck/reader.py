"""Reading a DISP deck: :func:`read_deck` (path, text or bytes) and :func:`parse_deck`."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kinestat.errors import InputError, KinestatError, ParseError
from kinestat.io.disp_deck.cards import (
    _cards,
    _Cursor,
    _spec_five,
    _spec_joint,
    _spec_n,
    _spec_one,
    _spec_three,
    _spec_two,
)
from kinestat.io.disp_deck.commands import OperatorCommand
from kinestat.io.disp_deck.model import DeckJoint, DispDeck
from kinestat.io.disp_deck.validate import (
    _HAND7_MS,
    SETS_BY_MS,
    _direction_problem,
    _frame_problem,
    _io_problem,
    _it_problem,
    _ms_problem,
    _n_problem,
    _np_problem,
    _pitch_problem,
)


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


def _set_cards(cur: _Cursor, spec, count: int, ends: str):
    """Cards 1..``count`` of one SET, read one at a time (``spec(i)``: card i's format);
    ``ends`` words a deck that ends early, ``{done}`` standing for the cards read."""
    for i in range(1, count + 1):
        yield cur.take(spec(i), ends.format(done=i - 1))


def _read_set_two(cur: _Cursor, ms: int, np_: int) -> np.ndarray:
    """SET TWO: 3 × NP cards, three points per position (3F10.2)."""
    n_cards = 3 * np_
    pts = np.zeros((n_cards, 3))
    reads = list(_set_cards(
        cur, _spec_two, n_cards,
        f"the deck ends after {{done}} of the {n_cards} SET TWO cards (3 x NP, NP = {np_}); "
        "add the missing cards or fix NP in SET ONE",
    ))
    for c, r in enumerate(reads):
        pts[c] = r.values
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
                file=cur.source, line=reads[3 * k].card.line,
                card=f"SET TWO, cards {3 * k + 1}-{3 * k + 3} (position {k + 1})",
            )
    return positions


def _read_set_three(cur: _Cursor, np_: int) -> tuple[OperatorCommand, ...]:
    """SET THREE: NP operator command cards (I10,5F10.3)."""
    cmds = []
    for r in _set_cards(
        cur, _spec_three, np_,
        f"the deck ends after {{done}} of the {np_} SET THREE cards (NP = {np_}); add the "
        "missing commands or fix NP in SET ONE",
    ):
        nty, dx, dy, dz, dd, tha = r.values
        if nty not in (0, 1):
            raise cur.fail(
                r, 0, f"NTY = {nty}: use 0 (global frame) or 1 (frame fixed on the hand)"
            )
        if problem := _direction_problem((dx, dy, dz)):
            raise cur.fail(r, None, problem)
        cmds.append(OperatorCommand(nty, (dx, dy, dz), dd, tha))
    return tuple(cmds)


def _read_set_four(cur: _Cursor, ms: int, hand7: bool) -> tuple[DeckJoint, ...]:
    """SET FOUR: N (I5), then N joint cards (5F10.3)."""
    rn = cur.take(
        _spec_n(),
        "the deck ends before SET FOUR: expected the card with N, the number of joints (I5)",
    )
    (n,) = rn.values
    if problem := _n_problem(ms, n, hand7):
        raise cur.fail(rn, 0, problem)
    js = []
    for r in _set_cards(
        cur, _spec_joint, n,
        f"the deck ends after {{done}} of the N = {n} SET FOUR joint cards; add the missing "
        "joints or fix N",
    ):
        if problem := _pitch_problem(r.values[4]):
            raise cur.fail(r, 4, problem)
        js.append(DeckJoint(*r.values))
    return tuple(js)


def _read_set_five(cur: _Cursor) -> np.ndarray:
    """SET FIVE: three points on x*(1) (3F10.3)."""
    reads = list(_set_cards(
        cur, _spec_five, 3,
        "the deck ends after {done} of the 3 SET FIVE cards (three points on x*(1))",
    ))
    frame_points = np.array([r.values for r in reads], dtype=float)
    if problem := _frame_problem(frame_points):
        raise ParseError(
            f"the three points do not fix the x*(1) frame: {problem}",
            file=cur.source, line=reads[0].card.line, card="SET FIVE",
        )
    return frame_points


def parse_deck(text: str, *, source: str = "<string>") -> DispDeck:
    r"""Parse the text of a DISP deck (Nadkarni App. I, SET ONE to SET FIVE).

    See the package docstring for the reading rules. Every problem raises :class:`ParseError`
    naming ``source``, the line, the SET and card, the field and its columns.

    >>> deck = parse_deck("    2    0    0    0\n    1\n 0 90 0 70 0\n"
    ...                   " 0 0 0\n 0 0 1\n 1 0 0\n")
    >>> deck.ms, deck.joint_kinds
    (2, ('revolute',))
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
    positions = _read_set_two(cur, ms, np_) if "TWO" in sets else None
    commands = _read_set_three(cur, np_) if "THREE" in sets else None
    hand7 = positions is not None and not np.any(positions[0])
    joints = _read_set_four(cur, ms, hand7) if "FOUR" in sets else None
    frame_points = _read_set_five(cur) if "FIVE" in sets else None
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
