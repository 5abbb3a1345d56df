"""Writing figures: the one place that creates a plot directory and saves PNGs into it."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from kinestat.errors import InputError

__all__ = ["save_figures"]


def save_figures(directory: str | os.PathLike, figures: Iterable[tuple[str, object]],
                 dpi: int = 110) -> list[Path]:
    """Save each ``(file name, matplotlib figure)`` into ``directory`` (created); return the
    paths written. A directory or file that cannot be written is an ``InputError``."""
    d = Path(directory)
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create the plot directory {str(d)!r}: {exc}") from exc
    out = []
    for name, fig in figures:
        path = d / name
        try:
            fig.savefig(path, dpi=dpi)
        except OSError as exc:
            raise InputError(f"cannot write the plot {str(path)!r}: {exc}") from exc
        out.append(path)
    return out
