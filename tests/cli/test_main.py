"""``kinestat.cli.main.main``: exit statuses and one-line errors."""

from __future__ import annotations

import os

import pytest

import kinestat
from kinestat.cli.main import main


def test_kinestat_error_is_one_line_exit_2(capsys):
    assert main(["fk", "puma762", "--q", "1,2,3"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("kinestat: error: --q:") and len(err.splitlines()) == 1


def test_os_error_is_one_line_exit_2(capsys, monkeypatch):
    # an OSError (permissions, a full disk, a vanished file) used to escape as a traceback
    def refuse(name):
        raise PermissionError(13, "Permission denied", "/models/arm.toml")

    monkeypatch.setattr(kinestat, "load", refuse)
    assert main(["fk", "arm.toml", "--q", "0"]) == 2
    err = capsys.readouterr().err
    assert err == "kinestat: error: Permission denied: /models/arm.toml\n"


def test_help_and_usage_errors(capsys):
    assert main(["--help"]) == 0
    assert "fk" in capsys.readouterr().out
    assert main(["fk", "puma762", "--no-such-option"]) == 2


# ------------------------------------------------------------ usage errors: one line, status 2

@pytest.mark.parametrize("argv, says", [
    (["control", "--forse", "4"], "No such option: --forse"),
    (["fk"], "Missing argument"),
    (["fk", "puma762", "--q"], "requires an argument"),
    (["control", "--force", "abc"], "Invalid value for '--force'"),
    (["no-such-command"], "No such command"),
])
def test_usage_error_is_one_line_exit_2(capsys, argv, says):
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert err.startswith("kinestat: error: ") and says in err
    assert len(err.splitlines()) == 1, err
    assert "╭" not in err and "Usage:" not in err


def test_usage_error_points_at_the_command_help(capsys):
    assert main(["control", "--forse", "4"]) == 2
    assert "(see 'kinestat control --help')" in capsys.readouterr().err


@pytest.mark.parametrize("argv", [["fk", "--help"], ["control", "--help"], ["sim", "--help"]])
def test_command_help_still_works(capsys, argv):
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "Usage:" in out and f"kinestat {argv[0]}" in out


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"kinestat {kinestat.__version__}\n"


# ------------------------------------------------------------- user text is printed literally

NASTY = "arm[/] [link=http://example.invalid]x[/link] [bold]y"


def test_model_name_with_markup_is_printed_literally(tmp_path, capsys):
    from kinestat.io import load, write_model

    model = load("puma560")
    object.__setattr__(model, "name", NASTY)  # as if the TOML file said name = "..."
    path = tmp_path / "arm[bold].toml"
    write_model(model, path)
    assert main(["fk", str(path), "--q", "0,0,0,0,0,0"]) == 0
    out = capsys.readouterr().out
    assert NASTY in out and "\x1b]8;" not in out  # no hyperlink escape sequence
    assert main(["ik", str(path), "--pose", ",".join(["1", "0", "0", "0.4", "0", "1", "0", "0.1",
                                                     "0", "0", "1", "0.4", "0", "0", "0", "1"])]
                ) in (0, 2)
    assert NASTY in capsys.readouterr().out


def test_platform_name_with_markup_is_printed_literally(tmp_path, capsys):
    from kinestat.io import dumps_platform, prototype
    from kinestat.parallel.platform import Platform

    p0 = prototype()
    plat = Platform(base_points=p0.base_points, top_points=p0.top_points,
                    stiffness=p0.stiffness, free_lengths=p0.free_lengths,
                    home_pose=p0.home_pose, name=NASTY)
    path = tmp_path / "plat.toml"
    path.write_text(dumps_platform(plat))
    assert main(["platform", "info", "--platform", str(path)]) == 0
    assert NASTY in capsys.readouterr().out


def test_axes_name_and_output_path_with_markup_are_printed_literally(tmp_path, capsys):
    axes = tmp_path / "axes.toml"
    axes.write_text(f'name = "{NASTY}"\nlength_unit = "mm"\n'
                    '[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 1]\n'
                    '[[axes]]\npoint = [0, 0, 1]\ndirection = [1, 0, 0]\n')
    target = tmp_path / "out[bold]x.toml"
    assert main(["dh-from-axes", str(axes), "--write-model", str(target)]) == 0
    out = capsys.readouterr().out
    assert NASTY in out and str(target) in out


def test_table_cells_and_titles_are_literal():
    from rich.console import Console

    from kinestat.cli._output import literal, table

    console = Console(width=200, record=True, file=open(os.devnull, "w"))  # noqa: SIM115
    console.print(table(f"title {NASTY}", ["[/]", "x"], [[NASTY, 1.5]]))
    text = console.export_text()
    assert f"title {NASTY}" in text and NASTY in text and "[/]" in text
    console.print(f"[bold]{literal(NASTY)}[/]")
    assert NASTY in console.export_text()


def test_binary_commands_file_is_one_line_exit_2(tmp_path, capsys):
    cmds = tmp_path / "cmds.txt"
    cmds.write_bytes(bytes(range(256)))
    assert main(["guide", "puma762", "--commands", str(cmds)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"kinestat: error: {cmds}: not a text file") and err.count("\n") == 1


def test_bare_command_prints_help_not_an_error(capsys):
    assert main([]) == 2  # as before: Click's no-arguments-is-help status
    out, err = capsys.readouterr()
    assert "Usage:" in out and "--version" in out and err == ""


def test_os_error_on_a_file_name_with_a_line_break_stays_one_line(capsys, monkeypatch):
    # found by the campaign: "File name too long: <a name with a newline>" printed two lines
    def refuse(name):
        raise OSError(36, "File name too long", "a\nb.toml")

    monkeypatch.setattr(kinestat, "load", refuse)
    assert main(["fk", "x.toml", "--q", "0"]) == 2
    assert capsys.readouterr().err == "kinestat: error: File name too long: 'a\\nb.toml'\n"
