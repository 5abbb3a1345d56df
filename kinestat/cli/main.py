"""The ``kinestat`` command.

Each command group lives in its own module ``kinestat.cli.<name>`` exposing
``register(app: typer.Typer) -> None``; the modules are listed in ``COMMAND_MODULES``.
Errors derived from :class:`kinestat.errors.KinestatError` are printed as one clear message
(no traceback) and exit with status 2.
"""

from __future__ import annotations

import importlib
import sys

import typer

from kinestat.errors import KinestatError

# Order is the order of the help listing.
COMMAND_MODULES: list[str] = [
    "fk",
    "demo",
    "screw",
    "disp",
    "guide",
    "ik",
    "sim",
    "dh_from_axes",
    "platform",
    "control",
    "view",
    "home",
    "sweep",
]

app = typer.Typer(
    name="kinestat",
    help="Kinematics and statics of robot manipulators (kinestat).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


@app.callback()
def _root() -> None:
    """Kinematics and statics of robot manipulators."""


for _name in COMMAND_MODULES:
    importlib.import_module(f"kinestat.cli.{_name}").register(app)


def main(argv: list[str] | None = None) -> int:
    """Console-script entry point; returns the exit status.

    Usage errors and ``--help`` are handled by Typer (usage errors exit with status 2); a
    :class:`KinestatError`, or an ``OSError`` from the file system or network, is printed as
    one line on stderr and exits with status 2.
    """
    try:
        app(args=argv, standalone_mode=True)
    except SystemExit as exc:
        code = exc.code
        return code if isinstance(code, int) else (0 if code is None else 1)
    except KinestatError as exc:
        typer.echo(f"kinestat: error: {exc}", err=True)
        return 2
    except OSError as exc:  # the file system or the network said no: not a kinestat bug
        where = f": {exc.filename}" if exc.filename is not None else ""
        typer.echo(f"kinestat: error: {exc.strerror or exc}{where}", err=True)
        return 2
    except KeyboardInterrupt:
        typer.echo("kinestat: interrupted", err=True)
        return 130
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
