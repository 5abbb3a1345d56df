"""Writing a DISP deck as fixed-width card images: :func:`format_deck`, :func:`write_deck`."""

from __future__ import annotations

import os
from collections.abc import Sequence

from kinestat.errors import InputError
from kinestat.io.disp_deck.cards import (
    _Field,
    _Spec,
    _spec_five,
    _spec_joint,
    _spec_n,
    _spec_one,
    _spec_three,
    _spec_two,
)
from kinestat.io.disp_deck.model import DispDeck
from kinestat.io.textfile import write_text_atomic


def _format_int(value: int, f: _Field, where: str) -> str:
    s = str(value)
    if len(s) > f.width:
        raise InputError(f"{where}: {f.name} = {value} does not fit the I{f.width} field")
    return s.rjust(f.width)


def _format_real(value: float, f: _Field, where: str, exact: bool) -> str:
    """The shortest-precision text of ``value`` that fits the field and reads back exactly."""
    w = f.width
    # the format's decimals first, then more, then fewer ('#' keeps the point of "25."), then
    # scientific notation
    texts = [*(f"{value:#.{dec}f}" for dec in [*range(f.decimals, w),
                                               *range(f.decimals - 1, -1, -1)]),
             *(f"{value:#.{p}E}" for p in range(w))]
    candidates = [s for s in texts if len(s) <= w]
    for s in candidates:
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
