"""The ``kinestat`` command.

Each command group lives in its own module ``kinestat.cli.<name>`` exposing
``register(app: typer.Typer) -> None``. The commands are listed in :data:`COMMANDS` (name,
module, the summary ``kinestat --help`` shows) and a module is imported only when one of its
commands runs or shows its own help (:mod:`kinestat.cli._lazy`): ``kinestat --help`` and
``kinestat --version`` import neither NumPy nor any command module (issue 16, start-up).
A test checks :data:`COMMANDS` against what the modules register, so it cannot drift.
Errors derived from :class:`kinestat.errors.KinestatError`, and usage errors (an unknown option,
a missing argument, a bad choice), are printed as one line ``kinestat: error: ...`` on stderr (no
traceback, no box) and exit with status 2.
"""

from __future__ import annotations

import sys

import typer

# Typer (0.29, pinned in requirements/run.txt) carries its own copy of Click: its usage errors
# are these classes, not ``click``'s. ``typer.BadParameter`` is the public face of the same module.
from typer._click.exceptions import ClickException, NoArgsIsHelpError, UsageError

import kinestat
from kinestat.cli._compile_watch import announce_compiles
from kinestat.cli._lazy import CommandEntry, LazyGroup
from kinestat.errors import KinestatError

# Order is the order of the help listing; ``summary`` is the first paragraph of the command's
# help as its module writes it (tests/cli/test_lazy_commands.py checks every row).
COMMANDS: tuple[CommandEntry, ...] = (
    CommandEntry("fk", "fk", "Pose of the end frame T_base_end and the tool point; for the PUMA "
                 "762 also P_tool_F, S6_F and a67_F in the thesis's words (Vibhute eq. 2-34)."),
    CommandEntry("demo", "demo", "Run the thesis illustrations on the embedded data and print "
                 "their results."),
    CommandEntry("warmup", "demo", "Compile the kernels `kinestat control` runs now (first run "
                 "only; later runs load them from the cache); `--all` every group.", hidden=True),
    CommandEntry("screw", "screw", "Screw axis of the displacement between two positions of a "
                 "body (Nadkarni ch. III)."),
    CommandEntry("disp", "disp", "Run a DISP deck (Nadkarni 1977): MS 1 screw axes, 2 mechanism "
                 "data, 3 both, 0/4/5/6 guidance of types II/III/IV/I."),
    CommandEntry("guide", "guide", "Guide a manipulator's hand to targets, along commands or moves "
                 "(Nadkarni ch. IV)."),
    CommandEntry("ik", "ik", "Joint angles that reach a pose."),
    CommandEntry("dh-from-axes", "dh_from_axes", "Standard DH table (θ, d, a, α) from the joint "
                 "axes, by the lecture notes' frame assignment."),
    CommandEntry("control", "control", "Kinestatic control: press the tool on the workpiece with "
                 "|F_req| along the force."),
    CommandEntry("home", "home", "Power-on checks, pot-based coarse positioning, index search and "
                 "home definition\n(startup_initialize.m). Refuses (amplifiers off via MO) when a "
                 "check fails."),
    CommandEntry("sim", "sim", "Simulated hardware: the Galil DMC controller and the platform's "
                 "encoder stream."),
    CommandEntry("platform", "platform", "The compliant special 6-6 platform: info, fk, ik, "
                 "statics, stiffness."),
    CommandEntry("view", "view", "3D views in the browser: MODEL (or model MODEL), platform, "
                 "screw, disp, log (or --log FILE)."),
    CommandEntry("sweep", "sweep", "Studies at scale on Dask: workspace, platform-range, "
                 "platform-design, tolerance."),
)
#: the command modules, in the order of :data:`COMMANDS`
COMMAND_MODULES: list[str] = list(dict.fromkeys(e.module for e in COMMANDS))


class _KinestatGroup(LazyGroup):
    entries = COMMANDS
    package = "kinestat.cli"

    def invoke(self, ctx):
        """Run the command; a Ctrl-C that no command handled itself ends it with one line and
        status 130 (Typer alone would exit 130 printing only a blank line)."""
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            where = " ".join(str(exc).split())
            typer.echo(f"kinestat: interrupted{': ' + where if where else ''}", err=True)
            raise typer.Exit(130) from None


app = typer.Typer(
    cls=_KinestatGroup,
    name="kinestat",
    help="Kinematics and statics of robot manipulators (kinestat).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"kinestat {kinestat.__version__}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: bool = typer.Option(False, "--version", help="Print the version and exit.",
                                 callback=_print_version, is_eager=True, metavar=""),
) -> None:
    """Kinematics and statics of robot manipulators."""


MAX_ARGS = 1000
"""Most arguments one call takes: the longest real command line has a few dozen; 200,000
arguments kept Click's parser busy for 10 s before its error."""

MAX_MESSAGE = 1000
"""Longest error line printed (characters): a message quoting a huge bad value is cut."""


def _one_line(text: str) -> str:
    """``text`` on one line (blank runs, line breaks included, become one blank), at most
    :data:`MAX_MESSAGE` characters."""
    line = " ".join(text.split())
    return line if len(line) <= MAX_MESSAGE else line[:MAX_MESSAGE - 1] + "…"


def _usage_error(exc: UsageError) -> str:
    """The one-line message of a usage error, pointing at the command's ``--help``."""
    # pydantic, which Typer converts values with, puts "Value error, " before a parser's message
    msg = _one_line(exc.format_message()).replace(": Value error, ", ": ")
    path = exc.ctx.command_path if exc.ctx is not None else "kinestat"
    return f"kinestat: error: {msg} (see '{path} --help')"


def main(argv: list[str] | None = None) -> int:
    """Console-script entry point; returns the exit status.

    ``--help`` prints help and exits with 0. A usage error, a :class:`KinestatError`, or an
    ``OSError`` from the file system or network, is printed as one line on stderr and exits with
    status 2. Click runs with ``standalone_mode=False`` so that its errors reach this function
    instead of being drawn as a box.
    """
    n_args = len(sys.argv) - 1 if argv is None else len(argv)
    if n_args > MAX_ARGS:
        typer.echo(f"kinestat: error: {n_args} arguments, more than the {MAX_ARGS} a call takes "
                   "(see 'kinestat --help')", err=True)
        return 2
    announce_compiles()  # a command's first-run compilation says so on stderr
    try:
        code = app(args=argv, prog_name="kinestat", standalone_mode=False)
    except SystemExit as exc:
        code = exc.code
        return code if isinstance(code, int) else (0 if code is None else 1)
    except NoArgsIsHelpError as exc:  # bare ``kinestat``: the help on stdout, status 2
        text = exc.format_message()  # empty when rich has already printed the help
        if text.strip():
            typer.echo(text)
        return 2
    except UsageError as exc:
        typer.echo(_usage_error(exc), err=True)
        return 2
    except ClickException as exc:  # e.g. a file option Click could not open: a bad call
        typer.echo(f"kinestat: error: {_one_line(exc.format_message())}", err=True)
        return 2
    except typer.Abort:
        typer.echo("kinestat: aborted", err=True)
        return 1
    except KinestatError as exc:
        typer.echo(f"kinestat: error: {_one_line(str(exc))}", err=True)
        return 2
    except OSError as exc:  # the file system or the network said no: not a kinestat bug
        name = "" if exc.filename is None else str(exc.filename)
        where = f": {name if name.isprintable() else repr(name)}" if name else ""
        typer.echo(f"kinestat: error: {_one_line(str(exc.strerror or exc))}{where}", err=True)
        return 2
    except KeyboardInterrupt:
        typer.echo("kinestat: interrupted", err=True)
        return 130
    # without standalone mode ``typer.Exit(n)`` arrives as the return value ``n`` (commands
    # return None, which is status 0)
    return code if isinstance(code, int) and not isinstance(code, bool) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
