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

The package: :mod:`.validate` (the rules, one place), :mod:`.commands` (SET THREE), :mod:`.model`,
:mod:`.cards` (layouts), :mod:`.reader`, :mod:`.writer`, :mod:`.embedded`.
"""

from __future__ import annotations

from kinestat.io.disp_deck.commands import OperatorCommand, parse_operator_command
from kinestat.io.disp_deck.embedded import (
    embedded_deck,
    embedded_deck_text,
    list_embedded_decks,
)
from kinestat.io.disp_deck.model import DeckJoint, DispDeck, deck_warnings
from kinestat.io.disp_deck.reader import parse_deck, read_deck
from kinestat.io.disp_deck.validate import (
    MAX_JOINTS,
    MAX_POSITIONS,
    PRISMATIC_MARKER,
    SETS_BY_MS,
)
from kinestat.io.disp_deck.writer import format_deck, write_deck

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
    "parse_operator_command",
]
