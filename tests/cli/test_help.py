"""Help texts show what is written (issue 16): square brackets survive rich's markup, flags take
no value placeholder, comma-separated options name what they expect, docstrings wrap once."""

from __future__ import annotations

import re

import pytest
import typer

from kinestat.cli.main import app, main

WIDE = "250"


def _commands(cmd, path: tuple[str, ...] = ()):
    if hasattr(cmd, "commands"):  # a group (typer may vendor its own click)
        for name, sub in cmd.commands.items():
            yield from _commands(sub, (*path, name))
    else:
        yield path, cmd


COMMANDS = list(_commands(typer.main.get_command(app)))


def _help(capsys, monkeypatch, path, columns=WIDE) -> str:
    monkeypatch.setenv("COLUMNS", columns)
    monkeypatch.setenv("TERMINAL_WIDTH", columns)
    assert main([*path, "--help"]) == 0
    return capsys.readouterr().out


def _flat(text: str) -> str:
    return " ".join(re.sub(r"[│╭╮╰╯─]", " ", text).split())


def test_stiffness_help_shows_the_twist_orders(capsys, monkeypatch):
    out = _flat(_help(capsys, monkeypatch, ("platform", "stiffness")))
    assert "'ray': dD = [dx; dphi] (default); 'axis': [dphi; dx]." in out


@pytest.mark.parametrize("path, cmd", COMMANDS, ids=[" ".join(p) for p, _ in COMMANDS])
def test_every_bracket_in_a_help_text_is_shown(capsys, monkeypatch, path, cmd):
    texts = [cmd.help or ""] + [getattr(p, "help", None) or "" for p in cmd.params]
    wanted = {re.sub(r"\s+", " ", m) for t in texts
              for m in re.findall(r"\\?\[([^\]\[]+)\]", t.replace("\\[", "["))}
    out = _flat(_help(capsys, monkeypatch, path))
    missing = [w for w in wanted if f"[{w}]" not in out]
    assert not missing, f"kinestat {' '.join(path)} --help drops {missing}"


@pytest.mark.parametrize("path, cmd", COMMANDS, ids=[" ".join(p) for p, _ in COMMANDS])
def test_flags_show_no_value_placeholder(capsys, monkeypatch, path, cmd):
    out = _help(capsys, monkeypatch, path)
    flags = [o for p in cmd.params if getattr(p, "is_flag", False) for o in p.opts]
    for line in out.splitlines():
        for opt in flags:
            if re.search(rf"{re.escape(opt)}\b(?![-\w])", line) and "<bool>" in line:
                pytest.fail(f"kinestat {' '.join(path)}: {opt} shown as taking a value: {line}")


@pytest.mark.parametrize("path, option", [(("fk",), "--q-deg"), (("guide", ), "--q0-deg"),
                                          (("ik",), "--q0-deg"), (("platform", "fk"), "--legs")])
def test_comma_separated_options_say_what_they_expect(capsys, monkeypatch, path, option):
    out = _help(capsys, monkeypatch, path)
    line = next(ln for ln in out.splitlines() if option in ln)
    assert re.search(rf"{re.escape(option)}\s+[A-Z0-9]+,[A-Z0-9]+,", line), line


def test_docstring_paragraphs_wrap_once_at_the_terminal_width(capsys, monkeypatch):
    # the fk docstring is wrapped at ~95 columns in the source; at 60 columns every help line
    # but a paragraph's last must be nearly full (no short lines from a second wrap)
    out = _help(capsys, monkeypatch, ("fk",), columns="60")
    body = out.split("Usage:")[1].split("╭")[0]
    paragraphs = [p for p in re.split(r"\n\s*\n", body) if p.strip()][1:]
    for p in paragraphs:
        lines = [ln.rstrip() for ln in p.splitlines()]
        for ln in lines[:-1]:
            assert len(ln) >= 45, f"ragged help line {ln!r} in\n{p}"
