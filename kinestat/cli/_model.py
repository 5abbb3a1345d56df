"""The MODEL argument shared by ``fk``, ``ik``, ``guide`` and ``view model``: an embedded name,
a TOML model or a URDF file, with the URDF's options ``--tip``, ``--base``, ``--scale`` and
``--length-unit`` (docs/urdf.md). Warnings of the loader (a URDF whose lengths look like
millimetres) are printed as one line on stderr.
"""

from __future__ import annotations

import warnings
from typing import Any

import typer

from kinestat.cli._options import help_text
from kinestat.errors import InputError, KinestatWarning

MODEL_HELP = "Embedded model name (e.g. puma762), a TOML model file or a URDF file (.urdf)."


def tip_option() -> Any:
    return typer.Option(None, "--tip", metavar="LINK", help=help_text(
        "URDF: the end link of the chain (default: the end of the only chain)."))


def base_option() -> Any:
    return typer.Option(None, "--base", metavar="LINK", help=help_text(
        "URDF: the link the chain starts from (default: the root link)."))


def scale_option() -> Any:
    return typer.Option(None, "--scale", help=help_text(
        "URDF: multiply the file's lengths by this (a file written in millimetres: 0.001); "
        "default: URDF metres, converted to --length-unit."))


def length_unit_option() -> Any:
    return typer.Option(None, "--length-unit", metavar="mm|cm|m|in|ft", help=help_text(
        "URDF: the length unit of the loaded model (default m, URDF's own unit)."))


def load_model(model: str, tip: str | None = None, base: str | None = None,
               scale: float | None = None, length_unit: str | None = None):
    """``kinestat.load`` with the URDF options; its warnings as ``kinestat: warning: ...``."""
    import kinestat  # lazy: start-up (`kinestat --help`)

    options = {k: v for k, v in (("tip", tip), ("base", base), ("scale", scale),
                                 ("length_unit", length_unit)) if v is not None}
    if options and not model.lower().endswith(".urdf"):  # named as the command line has them
        named = ", ".join(f"--{k.replace('_', '-')}" for k in options)
        raise InputError(f"{named}: options of URDF models, but {model!r} is not a .urdf file")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", KinestatWarning)
        m = kinestat.load(model, **options)
    for w in caught:
        if issubclass(w.category, KinestatWarning):
            typer.echo(f"kinestat: warning: {' '.join(str(w.message).split())}", err=True)
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    return m
