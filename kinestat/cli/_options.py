"""The CLI's shared option vocabulary and help text (issue 16; docs/cli.md).

One place for what every command spells the same way: ``--json``, flags without a value
placeholder, the metavars of comma-separated values (``--q-deg A,B,C,...``), and command help
from a docstring (paragraphs unwrapped so the help wraps once, at the terminal's width, and
square brackets kept: rich would take ``[dx; dphi]`` for markup and drop it).
"""

from __future__ import annotations

import inspect
import os
import re
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from kinestat.errors import InputError

#: metavars: what a comma-separated option expects
Q_METAVAR = "A,B,C,..."
XYZ_METAVAR = "X,Y,Z"
POINTS3_METAVAR = "X,Y,Z,X,Y,Z,X,Y,Z"
LEGS_METAVAR = "L1,L2,L3,L4,L5,L6"
WRENCH_METAVAR = "FX,FY,FZ,MX,MY,MZ"
TWIST_METAVAR = "WX,WY,WZ,VX,VY,VZ"
POSE_METAVAR = "home|FILE|T11,...,T44"
POSE_FILE_METAVAR = "FILE|T11,...,T44"
STEPS_METAVAR = "N|N1,N2,..."
JSON_HELP = "Machine-readable JSON output."


def help_text(text: str) -> str:
    """Option or command help as rich shows it as written: ``[...]`` escaped."""
    return escape(text)


def command_help(fn: Callable[..., Any]) -> str:
    """A command's help from its docstring: each paragraph on one line (rich re-wraps it at the
    terminal's width, so it is wrapped once), brackets escaped.

    >>> def f():
    ...     '''First line
    ...     continues. [dx; dphi]
    ...
    ...     Second paragraph.'''
    >>> command_help(f)
    'First line continues. \\\\[dx; dphi]\\n\\nSecond paragraph.'
    """
    doc = inspect.cleandoc(fn.__doc__ or "")
    paragraphs = [re.sub(r"\s*\n\s*", " ", p.strip()) for p in re.split(r"\n\s*\n", doc)]
    return escape("\n\n".join(p for p in paragraphs if p))


def flag(default: bool, *names: str, help: str) -> Any:
    """A boolean flag: shown without a value placeholder (no ``<bool>``)."""
    return typer.Option(default, *names, help=help_text(help), metavar="")


def json_option() -> Any:
    """``--json``: the same flag on every command."""
    return flag(False, "--json", help=JSON_HELP)


def units(length: str | None = None, force: str | None = None) -> dict[str, str]:
    """The ``units`` object every JSON record carries (docs/cli.md): the length and force units
    of its numbers; angles are radians except in keys ending ``_deg`` (degrees).

    >>> units("mm", "N")
    {'length': 'mm', 'force': 'N', 'angle': 'rad', 'angle_deg_keys': 'deg'}
    """
    out = {}
    if length is not None:
        out["length"] = length
    if force is not None:
        out["force"] = force
    return {**out, "angle": "rad", "angle_deg_keys": "deg"}


def check_seed(seed: int | None, option: str = "--seed") -> None:
    """A random seed is a non-negative integer (NumPy's generators refuse others with a
    ``ValueError``): refuse it as one usage error, before anything starts.

    >>> check_seed(0); check_seed(None)
    """
    if seed is not None and seed < 0:
        raise InputError(f"{option} must be a non-negative integer, got {seed}")


def path_value(text: str) -> Path:
    """Typer ``parser=`` of a path option or argument: an empty or blank name is refused (as a
    usage error naming the option) instead of becoming ``Path("")``, the current folder."""
    if not str(text).strip():
        raise ValueError("an empty path; give a file or folder name")
    return Path(text)


def name_value(text: str) -> str:
    """Typer ``parser=`` of an option or argument naming a file or an embedded item (a model,
    a deck, a platform): an empty or blank value is refused, naming the option."""
    if not str(text).strip():
        raise ValueError("an empty name; give a file path (or an embedded name)")
    return str(text)


def _probe_writable(folder: Path, option: str, path: Path) -> None:
    """Create and remove a file in ``folder``: the one test that holds for every file system
    (``os.access`` says yes to root, also under /proc)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".kinestat-probe-", dir=folder)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise InputError(f"{option} {str(path)!r}: cannot write in {str(folder)!r} "
                         f"({exc.strerror or exc})") from None


def check_output_file(path: Path | None, option: str, *, makes_folders: bool = False,
                      what: str = "file") -> None:
    """An output file option (``--html``, ``--log``, ``--write-model``): refused before any
    work when it names a folder, or when its folder does not exist (unless the writer creates
    it: ``makes_folders``, as the cycle log does) or cannot be written. ``what`` names the
    file in the message (``"model file"``).

    >>> check_output_file(None, "--html")
    """
    if path is None:
        return
    if path.is_dir():
        raise InputError(f"{option} {str(path)!r} is a directory; give a file name")
    if makes_folders:
        _check_creatable(path.parent, option, path)
        return
    folder = path.parent
    if not folder.is_dir():
        raise InputError(f"{option}: cannot write {what} {str(path)!r}: the folder "
                         f"{str(folder)!r} does not exist or is not a folder")
    _probe_writable(folder, option, path)


def check_output_dir(path: Path | None, option: str) -> None:
    """An output folder option (``--plot``, ``--output``): refused before any work when it is
    a file, or when neither it nor the folder it would be created in can be written."""
    if path is None:
        return
    if path.exists() and not path.is_dir():
        raise InputError(f"{option} {str(path)!r} exists and is not a directory; give a "
                         "directory")
    _check_creatable(path, option, path)


def _check_creatable(folder: Path, option: str, path: Path) -> None:
    """``folder`` exists and can be written, or can be created: its nearest existing ancestor
    is a folder that can be written."""
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise InputError(f"{option} {str(path)!r}: {str(folder)!r} is not a folder")
    _probe_writable(folder, option, path)
