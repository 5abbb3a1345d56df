"""docs/cli.md lists every command and every option (issue 16)."""

from __future__ import annotations

from pathlib import Path

import pytest
import typer

from kinestat.cli.main import app

DOC = (Path(__file__).resolve().parents[2] / "docs" / "cli.md").read_text(encoding="utf-8")


def _commands(cmd, path=()):
    if hasattr(cmd, "commands"):
        for name, sub in cmd.commands.items():
            yield from _commands(sub, (*path, name))
    elif not getattr(cmd, "hidden", False):
        yield path, cmd


COMMANDS = list(_commands(typer.main.get_command(app)))


def test_there_are_commands():
    assert len(COMMANDS) >= 10


@pytest.mark.parametrize("path, cmd", COMMANDS, ids=[" ".join(p) for p, _ in COMMANDS])
def test_every_command_and_option_is_documented(path, cmd):
    row = next((ln for ln in DOC.splitlines() if ln.startswith(f"| `kinestat {' '.join(path)}`")),
               None)
    assert row is not None, f"docs/cli.md has no row for kinestat {' '.join(path)}"
    for p in cmd.params:
        if getattr(p, "hidden", False) or p.param_type_name != "option" or p.name == "help":
            continue
        for opt in [*p.opts, *p.secondary_opts]:
            assert f"`{opt}" in row or f"/{opt}" in row, f"{opt} of {' '.join(path)}"
