"""Shared output helpers for the CLI: JSON for machines, rich tables for people.

The one output layer of every command. Human output never cuts what a user needs: table cells
wrap (``overflow="fold"``) instead of ending in "…", short columns (step numbers, kinds, numbers)
keep their full width, and summaries are ``key: value`` lines (:func:`print_pairs`), which wrap
at the console width. The width is ``COLUMNS`` when set (also when piped), else the terminal's,
else :data:`PIPE_WIDTH` for files and pipes.

Rich reads ``[...]`` in printed strings as markup. Text that comes from the user — a model,
platform, deck or device name, a file path, a message quoting a file — is printed literally: the
cells and titles of :func:`table` are escaped here, and a command that interpolates user text in
its own ``console.print`` line wraps it in :func:`literal`. (A name such as ``arm[/]`` used to
crash the command with a MarkupError, and ``[link=...]`` put hyperlinks in the terminal.)
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.console import Console, ConsoleDimensions
from rich.markup import escape
from rich.table import Table
from rich.text import Text

from kinestat.errors import InputError

if TYPE_CHECKING:
    import numpy as np

#: the width of human output going to a file or pipe when ``COLUMNS`` is not set
PIPE_WIDTH = 160
#: a column whose longest cell is at most this wide is never squeezed (steps, kinds, numbers)
KEEP_WHOLE = 14


def _columns_env() -> int | None:
    cols = os.environ.get("COLUMNS", "").strip()
    return int(cols) if cols.isdigit() and int(cols) > 0 else None


class _Console(Console):
    """A rich console whose width is read at every print: ``COLUMNS`` (also when piped), else
    the terminal's width, else :data:`PIPE_WIDTH` (rich alone would assume 80 for a pipe)."""

    @property
    def size(self) -> ConsoleDimensions:
        dims = super().size
        cols = _columns_env()
        if cols is None and not self.is_terminal:
            cols = PIPE_WIDTH
        return ConsoleDimensions(cols or dims.width, dims.height)

    @size.setter
    def size(self, new_size: tuple[int, int]) -> None:
        self._width, self._height = new_size


console = _Console()
err_console = _Console(stderr=True)


def to_jsonable(obj: Any) -> Any:
    """``obj`` with NumPy arrays and scalars as lists and numbers
    (:func:`kinestat.io.jsonable.to_jsonable`)."""
    from kinestat.io.jsonable import to_jsonable as convert  # lazy: NumPy only when printing

    return convert(obj)


def print_json(obj: Any) -> None:
    """Print ``obj`` as JSON on stdout (no rich markup, no wrapping)."""
    print(json.dumps(to_jsonable(obj), indent=2))


def literal(value: Any) -> str:
    """``str(value)`` escaped so that rich prints it as it is (no markup, no hyperlinks).

    >>> print(literal("arm[/]"), literal("[link=http://x]a[/link]"))
    arm\\[/] \\[link=http://x]a\\[/link]
    """
    return escape(str(value))


def _cell(v: Any, fmt: str) -> str:
    np = sys.modules.get("numpy")  # a NumPy scalar implies NumPy is loaded: no import here
    is_float = isinstance(v, float) or (np is not None and isinstance(v, np.floating))
    return fmt.format(v) if is_float else str(v)


def _plain_len(cell: str) -> int:
    """The printed width of a cell's longest line (cells are printed literally)."""
    return max(len(line) for line in (cell.splitlines() or [""]))


def table(title: str, columns: list[str], rows: list[list[Any]], fmt: str = "{:.4f}") -> Table:
    """A rich table that never truncates; floats formatted with ``fmt``.

    Cells wrap (fold) rather than end in "…"; a column whose cells are all short (at most
    :data:`KEEP_WHOLE` characters, e.g. a step number or an event kind) keeps its full width, so
    only the long columns give way on a narrow console. The title, headers and cells are printed
    literally (they may hold names from the user's files).
    """
    cells = [[_cell(v, fmt) for v in r] for r in rows]
    t = Table(title=literal(title))
    for j, c in enumerate(columns):
        widest = max([_plain_len(c)] + [_plain_len(r[j]) for r in cells if j < len(r)])
        t.add_column(literal(c), justify="right" if widest <= KEEP_WHOLE else "left",
                     no_wrap=False, overflow="fold",
                     min_width=widest if widest <= KEEP_WHOLE else KEEP_WHOLE)
    for r in cells:
        t.add_row(*[literal(x) for x in r])
    return t


def print_pairs(title: str | None, pairs: Iterable[tuple[str, Any]], fmt: str = "{:.4f}",
                out: Console | None = None) -> None:
    """A summary as ``key: value`` lines; values wrap under themselves, never cut.

    Values are plain text (rich markup in them is not interpreted)."""
    out = out or console
    grid = Table.grid(padding=(0, 1))
    grid.add_column(style="bold", no_wrap=True)
    grid.add_column(overflow="fold")
    for k, v in pairs:
        grid.add_row(Text(f"  {k}:"), Text(_cell(v, fmt)))
    if title:
        out.print(Text(title, style="bold"))
    out.print(grid)


def parse_floats(text: str, n: int | None = None, name: str = "value") -> np.ndarray:
    """Parse ``"1,2,3"`` into floats, checking the count and that every number is finite and
    within :data:`kinestat.io._fields.MAX_MAGNITUDE` (the bound the file readers apply: no
    length, angle, force or count comes near it); raises InputError."""
    items = [v.strip() for v in text.split(",")] if text.strip() else []
    if "" in items:
        raise InputError(f"--{name}: empty value at position {items.index('') + 1} in "
                         f"{text!r}; give the numbers separated by single commas")
    try:
        # float() accepts blanks around a number but not inside one: '1 2' is an error, not 12
        vals = [float(v) for v in items]
    except ValueError as exc:
        raise InputError(f"--{name}: cannot read {text!r} as comma-separated numbers") from exc
    if n is not None and len(vals) != n:
        raise InputError(f"--{name}: expected {n} comma-separated numbers, got {len(vals)}")
    import numpy as np  # lazy: a command's --help needs no NumPy

    arr = np.asarray(vals)
    if not np.all(np.isfinite(arr)):
        raise InputError(f"--{name}: values must be finite, got {text!r}")
    from kinestat.io._fields import MAX_MAGNITUDE  # lazy: a command's --help needs no reader

    big = np.flatnonzero(np.abs(arr) > MAX_MAGNITUDE)
    if big.size:
        raise InputError(f"--{name}: value {big[0] + 1} ({arr[big[0]]:.3g}) is implausibly "
                         f"large (the limit is {MAX_MAGNITUDE:.0e})")
    return arr


def parse_pose(value: str, option: str = "pose", *, allow_batch: bool = False) -> np.ndarray:
    """A pose option's value: a pose file (JSON, TOML or numbers; :mod:`kinestat.io.posefile`)
    or 16 comma-separated numbers (a 4x4 matrix, row by row)."""
    p = Path(value)
    try:
        is_file = p.is_file()
    except OSError:  # e.g. 16 numbers written in full are too long for a file name
        is_file = False
    if is_file or p.suffix.lower() in (".json", ".toml"):
        if not p.exists():
            raise InputError(f"--{option}: file {value!r} does not exist")
        from kinestat.io.posefile import read_pose_file  # lazy: NumPy only when parsing

        return read_pose_file(p, allow_batch=allow_batch)
    if "," not in value:
        raise InputError(f"--{option}: {value!r} is neither a file nor 16 comma-separated "
                         "numbers (a 4x4 pose, row by row)")
    return parse_floats(value, 16, option).reshape(4, 4)
