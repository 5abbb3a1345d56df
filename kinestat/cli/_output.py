"""Shared output helpers for the CLI: JSON for machines, rich tables for people.

Rich reads ``[...]`` in printed strings as markup. Text that comes from the user — a model,
platform, deck or device name, a file path, a message quoting a file — is printed literally: the
cells and titles of :func:`table` are escaped here, and a command that interpolates user text in
its own ``console.print`` line wraps it in :func:`literal`. (A name such as ``arm[/]`` used to
crash the command with a MarkupError, and ``[link=...]`` put hyperlinks in the terminal.)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from kinestat.errors import InputError
from kinestat.io.jsonable import to_jsonable
from kinestat.io.posefile import read_pose_file

# Wide enough for the tables when output goes to a file or pipe (rich assumes 80 columns there).
console = Console(width=None if sys.stdout.isatty() else 160)
err_console = Console(stderr=True)


def print_json(obj: Any) -> None:
    """Print ``obj`` as JSON on stdout (no rich markup, no wrapping)."""
    print(json.dumps(to_jsonable(obj), indent=2))


def literal(value: Any) -> str:
    """``str(value)`` escaped so that rich prints it as it is (no markup, no hyperlinks).

    >>> print(literal("arm[/]"), literal("[link=http://x]a[/link]"))
    arm\\[/] \\[link=http://x]a\\[/link]
    """
    return escape(str(value))


def table(title: str, columns: list[str], rows: list[list[Any]], fmt: str = "{:.4f}") -> Table:
    """A rich table; floats formatted with ``fmt``. The title, headers and cells are printed
    literally (they may hold names from the user's files)."""
    t = Table(title=literal(title))
    for c in columns:
        t.add_column(literal(c), justify="right", no_wrap=True)
    for r in rows:
        t.add_row(*[fmt.format(v) if isinstance(v, (float, np.floating)) else literal(v)
                    for v in r])
    return t


def parse_floats(text: str, n: int | None = None, name: str = "value") -> np.ndarray:
    """Parse ``"1,2,3"`` into floats, checking the count; raises InputError."""
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
    arr = np.asarray(vals)
    if not np.all(np.isfinite(arr)):
        raise InputError(f"--{name}: values must be finite, got {text!r}")
    return arr


def parse_pose(value: str, option: str = "pose", *, allow_batch: bool = False) -> np.ndarray:
    """A pose option's value: a pose file (JSON, TOML or numbers; :mod:`kinestat.io.posefile`)
    or 16 comma-separated numbers (a 4x4 matrix, row by row)."""
    p = Path(value)
    if p.is_file() or p.suffix.lower() in (".json", ".toml"):
        if not p.exists():
            raise InputError(f"--{option}: file {value!r} does not exist")
        return read_pose_file(p, allow_batch=allow_batch)
    if "," not in value:
        raise InputError(f"--{option}: {value!r} is neither a file nor 16 comma-separated "
                         "numbers (a 4x4 pose, row by row)")
    return parse_floats(value, 16, option).reshape(4, 4)
