"""Card layouts (4I5, 3F10.2, (I10,5F10.3), I5, 5F10.3, 3F10.3) and reading one card."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from kinestat.errors import ParseError
from kinestat.io.disp_deck.validate import _FIVE_NAMES, _POINT_NAMES


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
