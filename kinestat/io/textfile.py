"""Reading and writing text files with clear errors; writes are atomic.

Every kinestat file format (TOML models and platforms, DISP decks, pose and axes files, URDF)
goes through these functions, so a missing directory, a binary file or a full disk gives the
same one-line error naming the file, and an interrupted write never leaves a half-written file.

:func:`parse_toml` and :func:`parse_json` are the one place TOML and JSON text is decoded: every
failure of the decoder — a syntax error, an integer over Python's 4300-digit conversion limit,
arrays nested deeper than the interpreter's recursion limit — becomes a ParseError naming the
file, never a bare ``ValueError`` or ``RecursionError``.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import tempfile
import tomllib
from pathlib import Path

from kinestat.errors import InputError, ParseError

__all__ = ["read_text_file", "write_text_atomic", "parse_toml", "parse_json"]


def read_text_file(path: str | os.PathLike, what: str = "file") -> str:
    """The UTF-8 text of ``path``; unreadable or binary files raise a ParseError naming it."""
    p = Path(path)
    try:
        return p.read_text(encoding="utf-8")
    except OSError as exc:
        raise ParseError(f"cannot read the {what}: {exc.strerror}", file=str(p)) from exc
    except UnicodeDecodeError as exc:
        raise ParseError(f"not a text file (byte {exc.object[exc.start]:#04x} at offset "
                         f"{exc.start} is not UTF-8); a {what} is text", file=str(p)) from exc


def _value_error(exc: ValueError) -> str:
    """A decoder's ValueError in the user's terms (the digit limit names no interpreter knob)."""
    text = str(exc)
    if "digits" in text:
        return f"an integer has too many digits (at most {sys.get_int_max_str_digits()})"
    return text


def parse_toml(text: str, source: str) -> dict:
    """The TOML document in ``text``; any decoding failure is a ParseError naming ``source``.

    >>> parse_toml("x = [[1]]", "a.toml")
    {'x': [[1]]}
    >>> parse_toml("x = " + "[" * 100_000, "a.toml")
    Traceback (most recent call last):
    kinestat.errors.ParseError: a.toml: not valid TOML: arrays or tables nested too deeply
    """
    try:
        return tomllib.loads(text)
    except RecursionError:
        msg = "arrays or tables nested too deeply"
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
    except ValueError as exc:  # the interpreter's 4300-digit integer limit
        msg = _value_error(exc)
    raise ParseError(f"not valid TOML: {msg}", file=source)


def parse_json(text: str, source: str):
    """The JSON document in ``text``; any decoding failure is a ParseError naming ``source``
    (and the line, for a syntax error)."""
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ParseError(f"not valid JSON: {exc.msg}", file=source, line=exc.lineno) from None
    except RecursionError:
        msg = "arrays or objects nested too deeply"
    except ValueError as exc:  # the interpreter's 4300-digit integer limit
        msg = _value_error(exc)
    raise ParseError(f"not valid JSON: {msg}", file=source)


def write_text_atomic(path: str | os.PathLike, text: str, what: str = "file", *,
                      encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically: a temporary file in the same directory, flushed to
    the disk and renamed over ``path`` (keeping an existing file's permissions). Any failure
    raises an InputError naming the file and leaves ``path`` as it was."""
    target = Path(path)
    try:
        mode = target.stat().st_mode & 0o777 if target.exists() else 0o644
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp",
                                   dir=target.parent)
    except OSError as exc:
        raise InputError(f"cannot write {what} {str(target)!r}: {exc.strerror or exc}; check "
                         "the directory") from None
    try:
        with os.fdopen(fd, "w", encoding=encoding, newline="\n") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise InputError(f"cannot write {what} {str(target)!r}: {exc.strerror or exc}"
                             ) from None
        raise
