"""DISP card decks: the embedded thesis decks, the reading rules, errors and the writer."""

from __future__ import annotations

import dataclasses
import math
import os

import numpy as np
import pytest

from kinestat.errors import InputError, KinestatError, ParseError
from kinestat.io.disp_deck import (
    SETS_BY_MS,
    DeckJoint,
    DispDeck,
    OperatorCommand,
    deck_warnings,
    embedded_deck,
    embedded_deck_text,
    format_deck,
    list_embedded_decks,
    parse_deck,
    read_deck,
    write_deck,
)

# ---------------------------------------------------------------------------------------------
# The thesis's tables, typed from Nadkarni 1977 App. II (independent of the .dat files)
# ---------------------------------------------------------------------------------------------
A2_1_SET_TWO = [
    [25.00, 0.00, 20.00], [30.00, 0.00, 20.00], [25.00, 0.00, 10.00],
    [-20.30, -7.83, -6.66], [-20.65, -8.29, -5.85], [-21.06, -7.18, -6.62],
    [-24.50, 5.30, 4.00], [-24.67, 5.47, 4.97], [-25.00, 6.00, 4.00],
]
A2_3_SET_FOUR = [  # Table A2-2 / A2-3: r, alpha, a, theta, PH
    [0.00, 90.00, 0.00, 70.00, 0.00], [0.00, -90.00, 0.375, 80.00, 0.00],
    [12.20, 90.00, 0.375, 40.00, 0.00], [0.00, -90.00, 0.00, 0.00, 0.00],
    [9.50, 90.00, 0.00, 60.00, 0.00], [0.00, 0.00, 5.90, 30.00, 0.00],
    [0.00, 0.00, 1.00, 0.00, 0.00],
]
A2_3_SET_FIVE = [[0, 0, 0], [0, 0, 1], [1, 0, 0]]
A2_5_SET_TWO = [[0, 0, 0]] * 3 + [[-20.30, -7.83, -6.66], [-20.65, -8.29, -5.85],
                                  [-21.06, -7.18, -6.62]]
A2_8_SET_TWO = [[0, 0, 0]] * 3 + [[10.00, -10.00, 20.00], [11.00, -10.00, 20.00],
                                  [10.00, -10.00, 19.00]]
A2_8_SET_FOUR = [  # as printed: joint 7 has a7 = 0.00 and no pitch field
    [0.00, 90.00, 0.00, 0.00, 999999.00], [25.00, 90.00, 0.00, 90.00, 999999.00],
    [8.00, 0.00, 0.00, 180.00, 999999.00], [0.00, 90.00, 0.00, 0.00, 0.00],
    [0.00, 90.00, 0.00, 90.00, 0.00], [10.00, 90.00, 0.00, 0.00, 0.00],
    [0.00, 0.00, 0.00, 0.00, 0.00],
]
A2_8_SET_FIVE = [[25.00, 0.00, 20.00], [30.00, 0.00, 20.00], [25.00, 0.00, 10.00]]
A2_10_SET_THREE = [(0, (0.0, 0.0, 1.0), 4.00, -30.00), (1, (1.0, 0.0, 0.0), -1.00, 15.00)]

EXPECTED = {  # name: (MS, NP, SET TWO, SET THREE, SET FOUR, SET FIVE)
    "illustration1": (1, 3, A2_1_SET_TWO, None, None, None),
    "illustration2": (2, 0, None, None, A2_3_SET_FOUR, A2_3_SET_FIVE),
    "illustration3": (3, 3, A2_1_SET_TWO, None, A2_3_SET_FOUR, A2_3_SET_FIVE),
    "illustration4": (0, 2, A2_5_SET_TWO, None, A2_3_SET_FOUR, A2_3_SET_FIVE),
    "illustration5": (4, 2, A2_8_SET_TWO, None, A2_8_SET_FOUR, A2_8_SET_FIVE),
    "illustration6": (5, 2, None, A2_10_SET_THREE, A2_8_SET_FOUR, A2_8_SET_FIVE),
    "illustration7": (6, 2, A2_8_SET_TWO, None, A2_8_SET_FOUR, A2_8_SET_FIVE),
}


def _with_a7(rows, a7):
    rows = [list(r) for r in rows]
    rows[6][2] = a7
    return rows


for _n in (5, 6, 7):
    _ms, _np, _two, _three, _four, _five = EXPECTED[f"illustration{_n}"]
    EXPECTED[f"illustration{_n}-corrected"] = (_ms, _np, _two, _three, _with_a7(_four, 1.0),
                                               _five)


# ---------------------------------------------------------------------------------------------
# An independent forward kinematics in Nadkarni's notation (ch. II), only for checking data
# ---------------------------------------------------------------------------------------------
def _frame(a, b, c):
    a, b, c = (np.asarray(p, float) for p in (a, b, c))
    z = (b - a) / np.linalg.norm(b - a)
    x = (c - a) - np.dot(c - a, z) * z
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, a
    return T


def _screw_z(r, theta):  # Tz(r) Rz(theta)
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, r], [0, 0, 0, 1.0]])


def _screw_x(a, alpha):  # Tx(a) Rx(alpha)
    c, s = math.cos(alpha), math.sin(alpha)
    return np.array([[1, 0, 0, a], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def _nadkarni_frames(rows, five):
    """x*(i) and x(i) in the global frame; x*(1) is the SET FIVE frame (eqs. 2-1 .. 2-12)."""
    star, xs = [_frame(*five)], []
    for i, (r, alpha_deg, a, theta_deg, _) in enumerate(rows):
        if i > 0:
            star.append(xs[-1] @ _screw_z(r, math.radians(theta_deg)))
        xs.append(star[-1] @ _screw_x(a, math.radians(alpha_deg)))
    return star, xs


# ---------------------------------------------------------------------------------------------
# Embedded decks
# ---------------------------------------------------------------------------------------------
def test_list_embedded_decks_names_all_seven_illustrations():
    names = list_embedded_decks()
    for n in range(1, 8):
        assert f"illustration{n}" in names
        assert names[f"illustration{n}"]
    assert set(names) == set(EXPECTED) | {"illustration5-published"}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_embedded_deck_matches_the_thesis_tables(name):
    ms, np_, two, three, four, five = EXPECTED[name]
    deck = embedded_deck(name)
    assert (deck.ms, deck.np_, deck.it, deck.io) == (ms, np_, 0, 0)
    assert deck.sets == SETS_BY_MS[ms]
    if two is None:
        assert deck.positions is None
    else:
        np.testing.assert_array_equal(deck.positions, np.reshape(two, (np_, 3, 3)))
    if three is None:
        assert deck.commands is None
    else:
        assert deck.commands == tuple(OperatorCommand(*c) for c in three)
    if four is None:
        assert deck.joints is None
    else:
        got = [[j.r, j.alpha_deg, j.a, j.theta_deg, j.pitch] for j in deck.joints]
        np.testing.assert_array_equal(got, four)
    if five is None:
        assert deck.frame_points is None
    else:
        np.testing.assert_array_equal(deck.frame_points, five)
    assert name in deck.source


def test_embedded_decks_are_fixed_width_card_images():
    for name in list_embedded_decks():
        for line in embedded_deck_text(name).splitlines():
            assert "\t" not in line and "#" not in line and len(line) <= 60
            assert line == line.rstrip()


def test_illustration2_deck_reproduces_the_published_transm_results():
    """Table A2-3 through Nadkarni's ch. II transformations gives the printed summary."""
    deck = embedded_deck("illustration2")
    rows = [[j.r, j.alpha_deg, j.a, j.theta_deg, j.pitch] for j in deck.joints]
    star, xs = _nadkarni_frames(rows, deck.frame_points)
    origin_star = [[0, 0, 0], [0, 0, 0], [-11.95, 0.00, 2.488], [-11.90, 0.241, 2.771],
                   [-21.255, 0.241, 4.42], [-21.255, 0.241, 4.42], [-24.315, 5.273, 4.059]]
    origin = [[0, 0, 0], [0.065, 0.00, 0.369], [-11.90, 0.241, 2.771], [-11.90, 0.241, 2.771],
              [-21.255, 0.241, 4.42], [-24.315, 5.273, 4.059], [-24.833, 6.126, 3.998]]
    axis = [[0, 0, 1], [0, -1, 0], [-0.985, 0, 0.174], [0.112, -0.766, 0.633],
            [-0.985, 0, 0.174], [0.171, 0.174, 0.970], [0.171, 0.174, 0.970]]
    np.testing.assert_allclose([T[:3, 3] for T in star], origin_star, atol=6e-3)
    np.testing.assert_allclose([T[:3, 3] for T in xs], origin, atol=6e-3)
    np.testing.assert_allclose([T[:3, 2] for T in star], axis, atol=6e-3)


def _hand_points(deck):
    """Origin, +z unit point and x(7) origin of the hand joint x*(7) (App. I, option 2)."""
    rows = [[j.r, j.alpha_deg, j.a, j.theta_deg, j.pitch] for j in deck.joints]
    star, xs = _nadkarni_frames(rows, deck.frame_points)
    h = star[6]
    return np.array([h[:3, 3], h[:3, 3] + h[:3, 2], xs[6][:3, 3]])


def test_illustration4_hand_from_seventh_joint_is_the_printed_initial_position():
    deck = embedded_deck("illustration4")
    assert deck.hand_from_seventh_joint
    printed = [[-24.315, 5.273, 4.059], [-24.144, 5.447, 5.029], [-24.833, 6.126, 3.998]]
    np.testing.assert_allclose(_hand_points(deck), printed, atol=6e-3)


@pytest.mark.parametrize("n", [5, 6, 7])
def test_a7_of_table_a2_7_reproduces_the_printed_initial_hand(n):
    """a1, b1, c1 of Illustrations 5-7 need a7 = 1.00 (Table A2-7); the printed 0.00 of
    Table A2-8 puts the hand's x point on its origin (a degenerate frame)."""
    printed = np.array([[15.00, -25.00, 12.00], [15.00, -24.00, 12.00], [15.00, -25.00, 11.00]])
    corrected = embedded_deck(f"illustration{n}-corrected")
    np.testing.assert_allclose(_hand_points(corrected), printed, atol=1e-9)
    as_printed = _hand_points(embedded_deck(f"illustration{n}"))
    np.testing.assert_allclose(as_printed[2], as_printed[0], atol=1e-9)
    assert deck_warnings(embedded_deck(f"illustration{n}"))
    assert not deck_warnings(corrected)


@pytest.mark.parametrize("name", ["illustration4", "illustration5", "illustration7"])
def test_target_hand_points_are_unit_orthogonal(name):
    """The target hand points are a frame at unit distances (b2 = -8.29 in Table A2-5, not
    the -9.29 of the Illustration 4 text; b2 = [11 -10 20], not Illustration 5's text)."""
    a, b, c = embedded_deck(name).positions[1]
    assert abs(np.linalg.norm(b - a) - 1) < 6e-3
    assert abs(np.linalg.norm(c - a) - 1) < 6e-3
    assert abs(np.dot(b - a, c - a)) < 2e-3


def test_embedded_deck_name_rules():
    assert embedded_deck("Illustration2.dat") == embedded_deck("illustration2")
    with pytest.raises(InputError, match="illustration1"):
        embedded_deck("illustration8")
    with pytest.raises(InputError):
        embedded_deck(3)


def test_joint_kinds_and_table():
    deck = embedded_deck("illustration5")
    assert deck.joint_kinds == ("prismatic",) * 3 + ("revolute",) * 4
    table = deck.joint_table
    assert table.shape == (7, 5) and not table.flags.writeable
    np.testing.assert_allclose(table[:, 1], np.radians([90, 90, 0, 90, 90, 90, 0]))
    np.testing.assert_allclose(table[:, 3], np.radians([0, 90, 180, 0, 90, 0, 0]))
    assert embedded_deck("illustration1").joint_kinds == ()
    assert embedded_deck("illustration1").joint_table.shape == (0, 5)
    screw = DeckJoint(0, 0, 0, 0, pitch=-2.5)
    assert screw.kind == "screw"
    assert DeckJoint(0, 0, 0, 0, pitch=100000.0).kind == "screw"
    assert DeckJoint(0, 0, 0, 0, pitch=100000.01).kind == "prismatic"


# ---------------------------------------------------------------------------------------------
# Reading rules
# ---------------------------------------------------------------------------------------------
SMALL = """\
    2    0    0    0
    2
      1.50     90.00      0.25     10.00      0.00
     -3.00      0.00      1.00      0.00 999999.00
      0.00      0.00      0.00
      0.00      0.00      1.00
      1.00      0.00      0.00
"""


def test_touching_fields_blank_fields_and_short_cards():
    text = SMALL.replace("     -3.00      0.00      1.00      0.00 999999.00",
                         "     -3.00" + " " * 10 + "       1.0" + "     0.000999999.000")
    text = text.replace("      1.50     90.00      0.25     10.00      0.00",
                        "      1.50     90.00      0.25     10.00")
    assert parse_deck(text) == parse_deck(SMALL)
    deck = parse_deck(text)
    assert deck.joints[1] == DeckJoint(-3.0, 0.0, 1.0, 0.0, 999999.0)
    assert deck.joints[0].pitch == 0.0


def test_blank_separated_cards_read_like_fixed_columns():
    ws = "\n".join(" ".join(line.split()) for line in SMALL.splitlines())
    assert parse_deck(ws) == parse_deck(SMALL)
    ints = ws.replace("1.00 0.00 0.00", "1 0 0").replace("-3.00 0.00 1.00", "-3 0 1")
    assert parse_deck(ints) == parse_deck(SMALL)
    tabs = SMALL.replace("      1.50     90.00", "1.5\t90")
    assert parse_deck(tabs) == parse_deck(SMALL)


def test_comments_blank_lines_crlf_bom_and_exponents():
    text = "# a DISP deck\n\n" + SMALL.replace("\n", "   # note\r\n", 1) + "\n\n  \n"
    text = "\ufeff" + text.replace("     90.00", "   9.0E+01").replace("      0.25", "   2.5D-01")
    assert parse_deck(text) == parse_deck(SMALL)


def test_fortran_blanks_around_a_number_inside_its_field_are_ignored():
    left = SMALL.replace("    2    0    0    0", "2    0    0    0    ")
    assert parse_deck(left).ms == 2


def test_read_deck_accepts_paths_text_and_bytes(tmp_path):
    p = tmp_path / "deck.dat"
    p.write_text(SMALL)
    assert read_deck(p) == read_deck(str(p)) == read_deck(SMALL) == read_deck(SMALL.encode())
    assert read_deck(p).source == str(p)


def _err(text, **kw) -> ParseError:
    with pytest.raises(ParseError) as info:
        parse_deck(text, source=kw.pop("source", "deck.dat"))
    return info.value


@pytest.mark.parametrize(
    ("old", "new", "line", "card", "field", "columns", "words"),
    [
        ("    2    0    0    0", "    9    0    0    0", 1, "SET ONE", "MS", (1, 5), "0..6"),
        ("    2    0    0    0", "    2    0    0    2", 1, "SET ONE", "IO", (16, 20), "IO"),
        ("    2    0    0    0", "    2    0   -1    0", 1, "SET ONE", "IT", (11, 15), "IT"),
        ("    2    0    0    0", "  2.0    0    0    0", 1, "SET ONE", "MS", (1, 5),
         "integer"),
        ("    2\n", "   16\n", 2, "SET FOUR, first card", "N", (1, 5), "1..15"),
        ("     90.00", "     9O.00", 3, "SET FOUR, joint card 1", "ALPHA(1)", (11, 20),
         "9O.00"),
        ("     90.00", "        90", 3, "SET FOUR, joint card 1", "ALPHA(1)", (11, 20),
         "implied decimal"),
        ("     90.00", "       nan", 3, "SET FOUR, joint card 1", "ALPHA(1)", (11, 20), "nan"),
        ("     90.00", "    1E9999", 3, "SET FOUR, joint card 1", "ALPHA(1)", (11, 20),
         "finite"),
        (" 999999.00", "-999999.00", 4, "SET FOUR, joint card 2", "PH(2)", (41, 50),
         "prismatic"),
        ("      1.00      0.00      0.00\n", "      1.00      0.00      0.00 x\n", 7,
         "SET FIVE, card 3", None, None, "3F10.3"),
        ("      1.50     90.00      0.25     10.00      0.00",
         "1.5 90 0.25 10", 3, "SET FOUR, joint card 1", None, None, "5 numbers"),
        ("      1.50     90.00      0.25     10.00      0.00",
         "1.5 90 0.25 10 x", 3, "SET FOUR, joint card 1", "PH(1)", (16, 16), "'x'"),
    ],
)
def test_parse_errors_say_where(old, new, line, card, field, columns, words):
    assert old in SMALL
    e = _err(SMALL.replace(old, new, 1))
    assert (e.file, e.line, e.field, e.columns) == ("deck.dat", line, field, columns)
    assert e.card.startswith(card)
    assert words in str(e)
    assert str(e).startswith("deck.dat, line")


def test_card_count_errors_name_the_set_and_count():
    deck = embedded_deck_text("illustration1")
    lines = deck.splitlines()
    e = _err("\n".join(lines[:6]))
    assert e.card.startswith("SET TWO, card 6") and "5 of the 9 SET TWO cards" in str(e)
    assert e.line == 6
    e = _err(deck + "      1.00      2.00      3.00\n")
    assert e.line == 11 and "unexpected card" in str(e) and "SET TWO" in str(e)
    e = _err(embedded_deck_text("illustration2").replace("    7\n", "    8\n"))
    # the eighth "joint" card is SET FIVE's first, so SET FIVE runs short
    assert e.card.startswith("SET FIVE, card 3") and "2 of the 3 SET FIVE cards" in str(e)
    assert _err("").card == "SET ONE"
    assert "empty" in str(_err("\n# nothing\n\n"))


def test_semantic_errors():
    one = embedded_deck_text("illustration1")
    e = _err(one.replace("    1    3", "    1    1"))
    assert e.field == "NP" and "NP >= 2" in str(e)
    e = _err(one.replace("    1    3", "    1  100"))
    assert e.field == "NP" and "99" in str(e)
    zero_first = one.replace("     25.00      0.00     20.00", "      0.00      0.00      0.00")
    zero_first = zero_first.replace("     30.00      0.00     20.00", "      0.0")
    zero_first = zero_first.replace("     25.00      0.00     10.00", "      0.0")
    e = _err(zero_first)
    assert e.line == 2 and "seventh joint" in str(e) and "MS = 0, 4, 6" in str(e)
    e = _err(one.replace("    -20.65     -8.29     -5.85", "    -20.30     -7.83     -6.66"))
    assert e.card == "SET TWO, cards 4-6 (position 2)" and "coincides" in str(e)
    five = embedded_deck_text("illustration2").replace("      1.00      0.00      0.00",
                                                        "      0.00      0.00      2.00")
    e = _err(five)
    assert e.card == "SET FIVE" and "collinear" in str(e)
    four = embedded_deck_text("illustration4")
    e = _err(four.replace("    7\n", "    6\n").replace(
        "      0.00      0.00      1.00      0.00      0.00\n", "", 1))
    assert e.field == "N" and "seventh joint" in str(e)
    six = embedded_deck_text("illustration6")
    e = _err(six.replace("         1      1.00", "         2      1.00"))
    assert e.field == "NTY(2)" and e.line == 3
    e = _err(six.replace("      1.00      4.00", "      0.00      4.00"))
    assert e.card == "SET THREE, command card 1" and "zero vector" in str(e)


def test_undecodable_bytes_and_unreadable_paths(tmp_path):
    with pytest.raises(ParseError) as info:
        read_deck(b"    1    3    0    0\n\xff\xfe\n")
    assert info.value.line == 2
    with pytest.raises(InputError, match="cannot read DISP deck"):
        read_deck(tmp_path / "missing.dat")
    with pytest.raises(InputError):
        read_deck(tmp_path)
    with pytest.raises(InputError):
        read_deck(12)


# ---------------------------------------------------------------------------------------------
# The data model
# ---------------------------------------------------------------------------------------------
def test_deck_defaults_np_and_validates():
    pts = np.reshape(A2_1_SET_TWO, (3, 3, 3))
    deck = DispDeck(1, positions=pts)
    assert deck.np_ == 3 and deck == embedded_deck("illustration1")
    assert hash(deck) == hash(embedded_deck("illustration1"))
    assert not deck.positions.flags.writeable
    with pytest.raises(dataclasses.FrozenInstanceError):
        deck.ms = 2
    two = DispDeck(2, joints=A2_3_SET_FOUR, frame_points=A2_3_SET_FIVE)
    assert two == embedded_deck("illustration2") and two.np_ == 0
    six = DispDeck(5, commands=A2_10_SET_THREE, joints=A2_8_SET_FOUR,
                   frame_points=A2_8_SET_FIVE)
    assert six == embedded_deck("illustration6")
    assert "operator commands" in six.analysis


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"ms": 7}, "0..6"),
        ({"ms": 1}, "need SET TWO"),
        ({"ms": 1, "positions": np.reshape(A2_1_SET_TWO, (3, 3, 3)), "joints": A2_3_SET_FOUR},
         "no SET FOUR"),
        ({"ms": 1, "positions": np.reshape(A2_1_SET_TWO, (3, 3, 3)), "np_": 2}, "shape"),
        ({"ms": 1, "positions": np.full((2, 3, 3), np.nan)}, "NaN"),
        ({"ms": 1, "positions": np.zeros((2, 3, 3))}, "only for MS = 0, 4, 6"),
        ({"ms": 1, "positions": np.reshape(A2_1_SET_TWO, (3, 3, 3)), "io": 3}, "IO"),
        ({"ms": 1, "positions": np.reshape(A2_1_SET_TWO, (3, 3, 3)), "it": -2}, "IT"),
        ({"ms": 2, "joints": [[0, 0, 0]], "frame_points": A2_3_SET_FIVE}, "4 or 5"),
        ({"ms": 2, "joints": [[0, 0, 0, 0]] * 16, "frame_points": A2_3_SET_FIVE}, "1..15"),
        ({"ms": 2, "joints": [[0, 0, 0, 0, "1"]], "frame_points": A2_3_SET_FIVE}, "number"),
        ({"ms": 2, "joints": [[0, 0, 0, 0, -2e5]], "frame_points": A2_3_SET_FIVE}, "999999"),
        ({"ms": 2, "joints": [[0, 0, 0, 0]], "frame_points": np.zeros((3, 3))}, "SET FIVE"),
        ({"ms": 5, "commands": [(3, (0, 0, 1), 1.0, 0.0)], "joints": A2_8_SET_FOUR,
          "frame_points": A2_8_SET_FIVE}, "NTY"),
        ({"ms": 5, "commands": [(0, (0, 0), 1.0, 0.0)], "joints": A2_8_SET_FOUR,
          "frame_points": A2_8_SET_FIVE}, "3 components"),
        ({"ms": 5, "commands": [(0, (0, 0, 1), 1.0, 0.0)], "joints": A2_8_SET_FOUR[:6],
          "frame_points": A2_8_SET_FIVE}, "N >= 7"),
        ({"ms": 5, "commands": [], "joints": A2_8_SET_FOUR,
          "frame_points": A2_8_SET_FIVE}, "NP >= 1"),
    ],
)
def test_deck_validation_errors(kwargs, words):
    with pytest.raises(InputError, match=words):
        DispDeck(**kwargs)


def test_command_helpers_and_direction_warning():
    c = OperatorCommand(1, [2, 0, 0], -1, 15)
    assert c.frame == "hand" and c.direction == (2.0, 0.0, 0.0)
    assert math.isclose(c.angle, math.radians(15))
    deck = DispDeck(5, commands=[c], joints=_with_a7(A2_8_SET_FOUR, 1.0),
                    frame_points=A2_8_SET_FIVE)
    (warning,) = deck_warnings(deck)
    assert "length 2" in warning


# ---------------------------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------------------------
def test_writer_uses_the_thesis_formats():
    text = format_deck(embedded_deck("illustration6"))
    lines = text.splitlines()
    assert lines[0] == "    5    2    0    0"
    assert lines[1] == "         0     0.000     0.000     1.000     4.000   -30.000"
    assert lines[3] == "    7"
    assert lines[4] == "     0.000    90.000     0.000     0.000999999.000"
    two = format_deck(embedded_deck("illustration1")).splitlines()
    assert two[4] == "    -20.30     -7.83     -6.66"


def test_writer_widens_precision_and_refuses_inexact_values():
    deck = DispDeck(1, positions=[[[0.125, 1e-7, 2.0], [0.125, 1e-7, 1.5e9], [1, 0, 0]],
                                  [[-999999.0, 0, 123456789.0], [-999999.0, 0, 0], [0, 1, 0]],
                                  [[0, 0, 0], [0, 0, 1], [1, 0, 0]]])
    text = format_deck(deck)
    assert parse_deck(text) == deck
    assert "-999999.00" in text and "123456789." in text
    awkward = DispDeck(1, positions=[[[0.1 + 0.2, 0, 0], [1, 0, 0], [0, 1, 0]],
                                     [[0, 0, 0], [0, 0, 1], [1, 0, 0]]])
    with pytest.raises(InputError, match="exact=False"):
        format_deck(awkward)
    rounded = parse_deck(format_deck(awkward, exact=False))
    assert rounded.positions[0, 0, 0] == 0.3


def test_write_deck_is_atomic(tmp_path):
    path = tmp_path / "deck.dat"
    deck = embedded_deck("illustration3")
    text = write_deck(deck, path)
    assert path.read_text() == text and read_deck(path) == deck
    awkward = DispDeck(1, positions=[[[0.1 + 0.2, 0, 0], [1, 0, 0], [0, 1, 0]],
                                     [[0, 0, 0], [0, 0, 1], [1, 0, 0]]])
    with pytest.raises(InputError):
        write_deck(awkward, path)
    assert path.read_text() == text
    assert os.listdir(tmp_path) == ["deck.dat"]
    with pytest.raises(InputError, match="cannot write"):
        write_deck(deck, tmp_path / "no" / "such" / "dir.dat")
    with pytest.raises(InputError, match="cannot write"):
        write_deck(deck, tmp_path)
    assert os.listdir(tmp_path) == ["deck.dat"]


def test_errors_are_kinestat_errors():
    assert issubclass(ParseError, KinestatError)
    with pytest.raises(InputError):
        format_deck("not a deck")


def test_user_guide_examples_run():
    import doctest
    from pathlib import Path

    guide = Path(__file__).resolve().parents[2] / "docs" / "disp-decks.md"
    result = doctest.testfile(str(guide), module_relative=False, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 10 and result.failed == 0
