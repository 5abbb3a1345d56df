"""Reading poses given on the command line or in files, the same way for every command.

A pose argument is one of:

- 16 comma-separated numbers: a 4x4 homogeneous matrix, row by row;
- a file of numbers (spaces or commas, ``#`` comments): 16 (4x4) or 12 (its top three rows);
- a JSON file: a 4x4 array, 16 or 12 numbers, an object with a ``"pose"`` key (what
  ``kinestat fk --json`` writes), or — where a command takes several — a list of 4x4 arrays;
- a TOML file with ``pose = [[…], […], […], […]]``.

Content errors raise :class:`~kinestat.errors.ParseError` naming the file (and line where
known); :func:`kinestat.cli._output.parse_pose` handles a command-line value (a file or 16
numbers). Rigidity is checked by the caller (each command knows its tolerance).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kinestat.errors import ParseError
from kinestat.io._fields import MAX_MAGNITUDE
from kinestat.io.textfile import parse_json, parse_toml, read_text_file

__all__ = ["read_text_file", "pose_from_document", "read_pose_file"]


def pose_from_document(doc, source: str, *, allow_batch: bool = False) -> np.ndarray:
    """A pose ``(4, 4)`` (or ``(N, 4, 4)`` with ``allow_batch``) from parsed JSON/TOML data."""
    if isinstance(doc, dict):
        if "pose" not in doc:
            raise ParseError('expected a "pose" key holding a 4x4 array', file=source,
                             field="pose")
        doc = doc["pose"]
    try:
        arr = np.asarray(doc, dtype=float)
    except OverflowError:
        raise ParseError("the pose must be a 4x4 array of finite numbers: an integer is too "
                         "large for a float", file=source) from None
    except (TypeError, ValueError, RecursionError):
        raise ParseError("the pose must be a 4x4 array of numbers", file=source) from None
    if arr.shape in ((16,), (12,)):
        arr = arr.reshape(-1, 4)
    if arr.shape == (3, 4):
        arr = np.vstack([arr, [0.0, 0.0, 0.0, 1.0]])
    ok = arr.shape == (4, 4) or (allow_batch and arr.ndim == 3 and arr.shape[1:] == (4, 4))
    if not ok:
        many = " (or a list of them)" if allow_batch else ""
        raise ParseError(f"the pose must be a 4x4 array{many}, got shape {arr.shape}",
                         file=source)
    if not np.all(np.isfinite(arr)):
        raise ParseError("the pose contains NaN or infinity", file=source)
    big = float(np.max(np.abs(arr)))
    if big > MAX_MAGNITUDE:
        raise ParseError(f"the pose has an entry of magnitude {big:.3g}: implausibly large (the "
                         f"limit is {MAX_MAGNITUDE:.0e})", file=source)
    return arr


def read_pose_file(path: str | os.PathLike, *, allow_batch: bool = False) -> np.ndarray:
    """Read a pose file (JSON, TOML or plain numbers; see the module docstring)."""
    p = Path(path)
    text = read_text_file(p, "pose file")
    suffix = p.suffix.lower()
    if suffix == ".toml":
        return pose_from_document(parse_toml(text, str(p)), str(p), allow_batch=allow_batch)
    if suffix == ".json" or text.lstrip()[:1] in ("{", "["):
        doc = parse_json(text, str(p))
        return pose_from_document(doc, str(p), allow_batch=allow_batch)
    vals = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        for tok in line.split("#", 1)[0].replace(",", " ").split():
            try:
                vals.append(float(tok))
            except ValueError as exc:
                raise ParseError(f"{tok!r} is not a number", file=str(p), line=lineno) from exc
    if len(vals) not in (12, 16):
        raise ParseError(f"expected 16 numbers (a 4x4 pose, row by row) or 12 (its top three "
                         f"rows), got {len(vals)}", file=str(p))
    return pose_from_document(vals, str(p))
