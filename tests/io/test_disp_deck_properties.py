"""DISP decks, property tests: write/read round trips and fuzzing (only kinestat errors escape)."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinestat.errors import InputError, KinestatError, ParseError
from kinestat.io.disp_deck import (
    DeckJoint,
    DispDeck,
    OperatorCommand,
    embedded_deck_text,
    format_deck,
    list_embedded_decks,
    parse_deck,
    read_deck,
)

# Numbers a 10-column field holds exactly: card values with 2-3 decimals, and floats rounded
# to four significant digits (d.dddE±XX fits 10 columns with its sign).
_cards = st.integers(-999_999, 999_999).map(lambda k: k / 100)
_sig4 = st.floats(-1e30, 1e30, allow_nan=False).map(
    lambda x: float(f"{x:.3e}") if abs(x) > 1e-30 else 0.0
)
number = st.one_of(_cards, st.integers(-99_999, 99_999).map(lambda k: k / 1000), _sig4,
                   st.sampled_from([0.0, 999999.0, -999999.0, 123456789.0, 1e-7, -2.5e-20]))


_vec = st.tuples(*[st.integers(-9, 9)] * 3).map(np.array)


@st.composite
def frames(draw):
    """Three points fixing a frame (origin, +z point, +x-side point), 2-decimal card values."""
    origin = np.array([draw(_cards) for _ in range(3)])
    scale = draw(st.sampled_from([0.01, 0.5, 1.0, 25.0, 1000.0]))
    dz = draw(_vec.filter(np.any))
    dx = draw(_vec)
    if not np.any(np.cross(dz, dx)):
        dx = np.cross(dz, [1, 0, 0]) if np.any(np.cross(dz, [1, 0, 0])) else np.array([0, 1, 0])
    pts = np.array([origin, origin + scale * dz, origin + scale * dx])
    return np.array([[float(f"{v:.2f}") for v in p] for p in pts])


joint = st.builds(
    DeckJoint, number, number, number, number,
    st.one_of(st.just(0.0), st.just(999999.0), st.integers(-10**5, 10**5).map(float),
              number.filter(lambda p: -1e5 <= p)),
)
command = st.builds(
    OperatorCommand, st.sampled_from([0, 1]),
    st.tuples(number, number, number).filter(lambda d: any(d)), number, number,
)


@st.composite
def decks(draw):
    ms = draw(st.integers(0, 6))
    kw = {"it": draw(st.integers(0, 99_999)), "io": draw(st.sampled_from([0, 1]))}
    hand7 = False
    if ms in (0, 1, 3, 4, 6):
        n = draw(st.integers(2, 5))
        pos = [draw(frames()) for _ in range(n)]
        if ms in (0, 4, 6) and draw(st.booleans()):
            pos[0] = np.zeros((3, 3))
            hand7 = True
        kw["positions"] = np.array(pos)
    if ms == 5:
        kw["commands"] = draw(st.lists(command, min_size=1, max_size=4))
    if ms == 2:
        kw["np_"] = draw(st.integers(-9999, 99_999))
    if ms != 1:
        lo = 7 if (hand7 or ms == 5) else (6 if ms in (0, 4, 6) else 1)
        kw["joints"] = draw(st.lists(joint, min_size=lo, max_size=15))
        kw["frame_points"] = draw(frames())
    return DispDeck(ms, **kw)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(decks())
def test_read_of_write_is_the_deck(deck):
    text = format_deck(deck)
    back = parse_deck(text)
    assert back == deck
    assert format_deck(back) == text
    assert all(len(line) <= 60 for line in text.splitlines())


def _blank_separated(deck: DispDeck) -> str:
    """The deck as blank-separated numbers, one card a line (Python's shortest float repr)."""
    cards = [(deck.ms, deck.np_, deck.it, deck.io)]
    if deck.positions is not None:
        cards += [tuple(p) for p in deck.positions.reshape(-1, 3)]
    cards += [(c.nty, *c.direction, c.distance, c.angle_deg) for c in deck.commands or ()]
    if deck.joints is not None:
        cards.append((len(deck.joints),))
        cards += [(j.r, j.alpha_deg, j.a, j.theta_deg, j.pitch) for j in deck.joints]
    if deck.frame_points is not None:
        cards += [tuple(p) for p in deck.frame_points]
    def text(v):
        if isinstance(v, int):
            return repr(v)
        r = repr(float(v))
        # a decimal point in every real, as Fortran wants when the card happens to fit columns
        return r if "." in r or "e" not in r else r.replace("e", ".e", 1)

    return "\n".join("  ".join(text(v) for v in card) for card in cards)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(decks())
def test_blank_separated_form_reads_the_same(deck):
    assert parse_deck(_blank_separated(deck)) == deck


# ---------------------------------------------------------------------------------------------
# Fuzzing: mutations, truncations and random bytes give a deck or a KinestatError
# ---------------------------------------------------------------------------------------------
TEXTS = [embedded_deck_text(n) for n in list_embedded_decks()]
_chars = st.sampled_from(list(" 0123456789.-+eEdD#\t\nx\r\x00é,"))


def _outcome(text: str):
    try:
        deck = parse_deck(text, source="fuzz.dat")
    except KinestatError as exc:
        if isinstance(exc, ParseError) and exc.line is not None:
            assert 1 <= exc.line <= text.count("\n") + 1
        return exc
    assert isinstance(deck, DispDeck)
    try:
        text = format_deck(deck)
    except InputError:  # a blank-separated number longer than 10 columns
        return deck
    assert parse_deck(text) == deck
    return deck


@settings(max_examples=150, deadline=None)
@given(st.sampled_from(TEXTS), st.data())
def test_mutated_decks_raise_only_kinestat_errors(text, data):
    chars = list(text)
    for _ in range(data.draw(st.integers(1, 4))):
        op = data.draw(st.sampled_from(["replace", "insert", "delete", "truncate", "line"]))
        i = data.draw(st.integers(0, max(len(chars) - 1, 0)))
        if op == "replace" and chars:
            chars[i] = data.draw(_chars)
        elif op == "insert":
            chars.insert(i, data.draw(_chars))
        elif op == "delete" and chars:
            del chars[i]
        elif op == "truncate":
            chars = chars[:i]
        else:
            lines = "".join(chars).split("\n")
            j = data.draw(st.integers(0, len(lines) - 1))
            k = data.draw(st.integers(0, len(lines) - 1))
            if data.draw(st.booleans()):
                lines.insert(k, lines[j])
            else:
                lines[j], lines[k] = lines[k], lines[j]
            chars = list("\n".join(lines))
    _outcome("".join(chars))


@settings(max_examples=100, deadline=None)
@given(st.binary(max_size=400))
def test_random_bytes_raise_only_kinestat_errors(data):
    try:
        read_deck(data)
    except KinestatError:
        pass


@settings(max_examples=100, deadline=None)
@given(st.lists(st.text(_chars, max_size=40), min_size=1, max_size=12))
def test_random_card_text_raises_only_kinestat_errors(lines):
    _outcome("\n".join(["    1    2    0    0", *lines]))
