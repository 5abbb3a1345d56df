"""A command group that imports a command's module only when the command runs (issue 16).

``kinestat --help`` lists every command with its one-line summary. Building that list from the
command modules would import all of them, and with them NumPy, the domain packages and the
simulators: ``kinestat --help`` took 3.5x ``import numpy``. :class:`LazyGroup` lists the
commands from a table of :class:`CommandEntry` (name, module, summary) instead, and imports a
module the first time one of its commands is resolved to run (``kinestat fk ...``,
``kinestat fk --help``) or looked up in :attr:`LazyGroup.commands`.

The group also tidies every ``--help`` flag (:func:`tidy_help_option`): no ``<bool>`` value
placeholder, and the default ``False`` (Typer leaves ``None``, and coercing that ``None`` imports
pydantic): ``kinestat fk --help`` then costs NumPy's import plus Typer's, not pydantic's too.

The table is written by hand in :mod:`kinestat.cli.main`; tests/cli/test_lazy_commands.py checks
it against what the modules register (names, order, summaries, hidden flags) and the rendered
help against an eagerly built app, so it cannot drift.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator, MutableMapping, Sequence
from typing import Any, NamedTuple

import typer
from typer._click.core import Command, Context, Parameter
from typer.core import TyperCommand, TyperGroup


class CommandEntry(NamedTuple):
    """One command of the top-level listing.

    ``summary`` is the first paragraph of the command's help, exactly as the command module
    writes it (the listing shows only that paragraph); ``module`` is the name of the module
    under ``package`` whose ``register(app)`` adds the command.
    """

    name: str
    module: str
    summary: str
    hidden: bool = False


def register_module(module: str, package: str = "kinestat.cli") -> dict[str, Command]:
    """The Click commands ``package.module``'s ``register(app)`` adds, by name, in the order it
    adds them (built the way Typer builds them for a parent app)."""
    app = typer.Typer()
    importlib.import_module(f"{package}.{module}").register(app)
    group = typer.main.get_group(app)
    return dict(group.commands)


class _LazyCommands(MutableMapping):
    """``name -> command``, importing a command's module at the first ``[name]``; iterating,
    ``len`` and ``in`` read only the table. Commands added later (``add_command``) follow."""

    def __init__(self, entries: Sequence[CommandEntry], package: str,
                 loaded: MutableMapping[str, Command]) -> None:
        self._entries = {e.name: e for e in entries}
        self._package = package
        self._loaded: dict[str, Command] = dict(loaded)

    def is_loaded(self, name: str) -> bool:
        return name in self._loaded or name not in self._entries

    def summary(self, name: str) -> Command | None:
        """The command itself if loaded, else a help-only stand-in carrying the table's row."""
        if self.is_loaded(name):
            return self._loaded.get(name)
        e = self._entries[name]
        return TyperCommand(name=e.name, help=e.summary, hidden=e.hidden)

    def __getitem__(self, name: str) -> Command:
        if not self.is_loaded(name):
            module = self._entries[name].module
            for cmd_name, cmd in register_module(module, self._package).items():
                self._loaded.setdefault(cmd_name, cmd)
            if name not in self._loaded:
                raise LookupError(f"{self._package}.{module} registered no command {name!r}")
        return self._loaded[name]

    def __setitem__(self, name: str, cmd: Command) -> None:
        self._loaded[name] = cmd

    def __delitem__(self, name: str) -> None:
        self._entries.pop(name, None)
        self._loaded.pop(name, None)

    def __iter__(self) -> Iterator[str]:
        yield from self._entries
        yield from (n for n in self._loaded if n not in self._entries)

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def __contains__(self, name: object) -> bool:
        return name in self._entries or name in self._loaded


def tidy_help_option(option: Parameter | None) -> Parameter | None:
    """``option`` (a ``--help`` flag) shown without a value placeholder (no ``<bool>``: it is a
    flag) and defaulting to ``False`` instead of Typer's ``None``.

    Typer coerces a flag's value unless it is already a bool, and its first coercion imports
    pydantic and builds a validator: a group's ``--help``, absent (``None``) whenever a
    subcommand is given, cost ``kinestat fk --help`` as much again as importing NumPy.
    """
    if option is not None:
        if option.default is None:
            option.default = False
        if option.metavar is None:
            option.metavar = ""
    return option


def tidy_help_options(cmd: Command, ctx: Context) -> None:
    """:func:`tidy_help_option` on the ``--help`` of ``cmd`` and of every command under it
    (their contexts inherit ``ctx``'s help option names)."""
    tidy_help_option(cmd.get_help_option(ctx))
    for sub in getattr(cmd, "commands", {}).values():
        tidy_help_options(sub, ctx)


class LazyGroup(TyperGroup):
    """A Typer group whose commands come from :attr:`entries` (set by a subclass) and load on
    demand. ``get_command`` (what help listings call) returns a help-only stand-in for a command
    not yet loaded; ``resolve_command`` (what running a command calls) loads the real one;
    ``commands[name]`` loads it too, so code walking the command tree sees real commands."""

    entries: Sequence[CommandEntry] = ()
    package: str = "kinestat.cli"

    def __init__(self, **attrs: Any) -> None:
        super().__init__(**attrs)
        self.commands = _LazyCommands(self.entries, self.package, self.commands)

    def get_help_option(self, ctx: Context) -> Parameter | None:
        return tidy_help_option(super().get_help_option(ctx))

    def list_commands(self, ctx: Context) -> list[str]:
        return list(self.commands)  # the names only (Typer's own walks the items)

    def get_command(self, ctx: Context, cmd_name: str) -> Command | None:
        commands = self.commands
        if isinstance(commands, _LazyCommands) and cmd_name in commands:
            return commands.summary(cmd_name)
        return super().get_command(ctx, cmd_name)

    def resolve_command(self, ctx: Context, args: list[str]
                        ) -> tuple[str | None, Command | None, list[str]]:
        name, cmd, rest = super().resolve_command(ctx, args)
        if name is not None and name in self.commands:
            cmd = self.commands[name]
            tidy_help_options(cmd, ctx)
        return name, cmd, rest
