"""The cycle log: one JSON object per line, flushed (and fsync'ed) as each line is written.

A run's log holds, in order: a ``start`` record (settings), one ``cycle`` record per
measurement (measured and commanded state, the decision, the true state when simulated),
``fault`` records for anything that went wrong, and an ``end`` record with the final report.
Because every line reaches the disk before the next command is sent, a safe stop (or a crash)
never loses the cycles that led to it. Read it back with :func:`read_log`.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from kinestat.errors import InputError
from kinestat.io.jsonable import to_jsonable

__all__ = ["CycleLog", "read_log", "jsonable"]


#: kept under its earlier name for the control package
jsonable = to_jsonable


class CycleLog:
    """Append JSON-lines records to ``path`` (created with its directories; truncated).

    ``fsync`` (default True) forces each line to the disk, not just to the OS.
    """

    def __init__(self, path: str | os.PathLike, *, fsync: bool = True) -> None:
        self.path = Path(path)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._f = open(self.path, "w", encoding="utf-8")  # noqa: SIM115
        except OSError as exc:
            raise InputError(f"cannot write the cycle log {str(self.path)!r}: {exc}") from exc
        self.fsync = fsync
        self.records = 0

    def write(self, record: dict) -> None:
        """Write one record as a line, then flush it to the disk."""
        if self._f.closed:
            raise InputError(f"cycle log {str(self.path)!r} is closed")
        try:
            self._f.write(json.dumps(jsonable(record), separators=(",", ":")) + "\n")
            self._f.flush()
        except OSError as exc:
            raise InputError(f"cannot write the cycle log {str(self.path)!r}: "
                             f"{exc.strerror or exc}") from exc
        if self.fsync:
            try:
                os.fsync(self._f.fileno())
            except OSError:  # pragma: no cover - e.g. a pipe
                pass
        self.records += 1

    def close(self) -> None:
        if not self._f.closed:
            try:
                self._f.close()
            except OSError as exc:  # the last buffered line could not be written
                raise InputError(f"cannot write the cycle log {str(self.path)!r}: "
                                 f"{exc.strerror or exc}") from exc

    def __enter__(self) -> CycleLog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_log(path: str | os.PathLike) -> list[dict]:
    """All records of a cycle log (JSON objects, one per line); raises :class:`InputError` on
    an unreadable file or line (not UTF-8, not JSON, not an object, nested too deeply)."""
    out = []
    p = Path(path)
    try:
        lines = p.read_bytes().splitlines()
    except OSError as exc:
        raise InputError(f"cannot read the cycle log {str(p)!r}: {exc}") from exc
    for i, raw in enumerate(lines, 1):
        if not raw.strip():
            continue
        try:
            rec = json.loads(raw.decode("utf-8"))
        except UnicodeDecodeError as exc:
            raise InputError(f"{p}: line {i} is not UTF-8 text (byte {exc.start + 1}); is this "
                             "a cycle log?") from None
        except json.JSONDecodeError as exc:
            raise InputError(f"{p}: line {i} is not JSON: {exc}") from exc
        except (ValueError, RecursionError) as exc:  # the digit limit, deep nesting
            raise InputError(f"{p}: line {i} is not a cycle record: {type(exc).__name__}: "
                             f"{str(exc)[:80]}") from None
        if not isinstance(rec, dict):
            raise InputError(f"{p}: line {i} is not a cycle record (a JSON object)")
        out.append(rec)
    return out
