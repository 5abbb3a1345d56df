"""The lazily loaded command list (issue 16, start-up): ``kinestat --help`` lists the commands from
the table in kinestat.cli.main instead of importing every command module. The table must say
exactly what the modules register, and the help must read as an eagerly built app's would."""

from __future__ import annotations

import copy
import importlib
import json
import re
import subprocess
import sys

import pytest
import typer
from typer._click.core import Context
from typer.core import TyperGroup

from kinestat.cli._lazy import tidy_help_options
from kinestat.cli.main import COMMAND_MODULES, COMMANDS, app, main


def _eager_app() -> typer.Typer:
    """The app as it was built before the lazy group: every module registered up front."""
    eager = copy.copy(app)
    eager.info = copy.copy(app.info)
    eager.info.cls = TyperGroup
    eager.registered_commands, eager.registered_groups = [], []
    for module in COMMAND_MODULES:
        importlib.import_module(f"kinestat.cli.{module}").register(eager)
    return eager


EAGER = typer.main.get_command(_eager_app())
tidy_help_options(EAGER, Context(EAGER))  # the lazy group does this to the commands it loads


def _paths(cmd, path=()):
    yield path
    for name, sub in getattr(cmd, "commands", {}).items():
        yield from _paths(sub, (*path, name))


def test_the_table_lists_every_registered_command_in_the_listing_order():
    assert [e.name for e in COMMANDS] == list(EAGER.commands)


@pytest.mark.parametrize("entry", COMMANDS, ids=[e.name for e in COMMANDS])
def test_each_row_matches_its_command(entry):
    module = importlib.import_module(f"kinestat.cli.{entry.module}")
    own = typer.Typer()
    module.register(own)
    assert entry.name in typer.main.get_group(own).commands, f"{entry.module} lacks {entry.name}"
    real = EAGER.commands[entry.name]
    assert entry.summary == (real.help or "").split("\n\n")[0]
    assert entry.hidden == bool(real.hidden)
    assert not real.short_help  # the listing shows the help's first paragraph, not short_help


@pytest.mark.parametrize("path", list(_paths(EAGER)), ids=lambda p: " ".join(p) or "kinestat")
@pytest.mark.parametrize("columns", ["80", "250"])
def test_help_reads_as_the_eager_apps(capsys, monkeypatch, path, columns):
    # COLUMNS only: typer reads TERMINAL_WIDTH once, when its help renderer is first imported,
    # and keeps it for the session (an 80 here would narrow test_help.py's wide help)
    monkeypatch.setenv("COLUMNS", columns)
    EAGER.main([*path, "--help"], prog_name="kinestat", standalone_mode=False)
    eager_out = capsys.readouterr().out
    assert main([*path, "--help"]) == 0
    assert capsys.readouterr().out == eager_out
    assert eager_out.strip()
    for line in eager_out.splitlines():  # flags take no value
        assert not re.search(r"--(help|version)\s+<bool>", line), line


def test_the_command_tree_holds_the_real_commands():
    lazy = typer.main.get_command(app)
    assert list(_paths(lazy)) == list(_paths(EAGER))
    for name in lazy.commands:
        assert [p.name for p in lazy.commands[name].params] == \
            [p.name for p in EAGER.commands[name].params], name


def _modules_after(argv: list[str]) -> dict:
    """Run ``kinestat ARGV`` in a fresh process; which heavy modules it imported."""
    code = ("import json, sys\n"
            "from kinestat.cli.main import main\n"
            f"status = main({argv!r})\n"
            "print(json.dumps({'status': status, 'modules': sorted(m for m in sys.modules if "
            "m in ('numpy', 'pydantic') or m.startswith('kinestat.cli.'))}), file=sys.stderr)\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    return json.loads(run.stderr.strip().splitlines()[-1])


COMMAND_MODULE_NAMES = {f"kinestat.cli.{m}" for m in COMMAND_MODULES}


@pytest.mark.parametrize("argv", [["--help"], ["--version"], [], ["fkk"]],
                         ids=["--help", "--version", "bare", "typo"])
def test_the_top_level_imports_no_command_module_and_no_numpy(argv):
    got = _modules_after(argv)
    assert got["status"] == (0 if argv in (["--help"], ["--version"]) else 2)
    assert "numpy" not in got["modules"]
    assert "pydantic" not in got["modules"]
    assert not COMMAND_MODULE_NAMES & set(got["modules"])


@pytest.mark.parametrize("argv, module", [(["screw", "--help"], "screw"),
                                          (["platform", "stiffness", "--help"], "platform")])
def test_a_commands_help_imports_only_its_own_module(argv, module):
    got = _modules_after(argv)
    assert got["status"] == 0
    assert COMMAND_MODULE_NAMES & set(got["modules"]) == {f"kinestat.cli.{module}"}
    # the groups' absent --help flags are not coerced (Typer's first coercion loads pydantic)
    assert "pydantic" not in got["modules"]


def test_a_typo_still_suggests_the_command(capsys):
    assert main(["plattform"]) == 2
    assert "Did you mean 'platform'?" in capsys.readouterr().err
