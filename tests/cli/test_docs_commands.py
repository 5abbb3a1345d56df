"""Every command in the README and docs runs as written (issue 16).

The README's ```sh blocks and the ``kinestat …`` lines of the fenced blocks in docs/*.md are run
in-process through :func:`kinestat.cli.main.main`, in order per file, with a temporary
directory as the working directory (so a ``> pose.json`` of one line feeds the next). A few
commands cannot run here; each is listed in ``SKIP`` with the reason.
"""

from __future__ import annotations

import contextlib
import functools
import io
import re
import shlex
from importlib.metadata import PackageNotFoundError, distribution
from pathlib import Path

import pytest

from kinestat.cli.main import main

ROOT = Path(__file__).resolve().parents[2]

#: (substring of the command, reason): commands not run here
SKIP: list[tuple[str, str]] = [
    ("control --galil", "needs the real cell (Galil DMC on the network, the encoder box)"),
    ("sim galil", "starts a server that runs until interrupted"),
    ("sim encoders", "streams to a pseudo-terminal until interrupted"),
    ("kinestat control", "a long run (the kinestatic loop on the simulated cell, tens of "
                         "seconds); tests/cli/test_control.py runs it"),
    ("my-deck.dat", "a user's own deck file"),
    ("robot.urdf", "a user's own URDF file"),
    ("arm.toml --samples 1000000", "a user's own model file, and a long run (10^6 samples); "
                                   "tests/studies runs every study"),
    ("--samples 100000", "a long run (10^5 random inputs, the studies' scale); the same study "
                         "runs small from the line before it, and tests/studies runs it"),
    ("home --galil", "needs a Galil controller on the network (a real DMC, or the "
                     "`kinestat sim galil` server, which runs until interrupted)"),
    ("view --log", "replays the cycle log of a `kinestat control` run (a long run, skipped)"),
    ("--serve", "serves the page until interrupted"),
]
#: commands that match a SKIP entry but are quick and run here (docs/control.md, "Another arm")
RUN: tuple[str, ...] = ("control --arm ur5 --no-plot", "control --arm puma560 --task follow")
#: a synopsis, not a command: placeholders or alternatives
SYNOPSIS = re.compile(r"\[|…|\||\bFILE\b|\bMODEL\b|\bTOL\b|--pose P\b|\bW0\b")


def _blocks(text: str, readme: bool):
    """(line number, language, lines) of every fenced block."""
    lang, start, lines = None, 0, []
    for i, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            if lang is None:
                lang, start, lines = line[3:].strip(), i, []
            else:
                yield start, lang, lines
                lang = None
        elif lang is not None:
            lines.append(line)


def _commands(path: Path) -> list[tuple[int, str]]:
    readme = path.name == "README.md"
    out = []
    for start, lang, lines in _blocks(path.read_text(encoding="utf-8"), readme):
        if readme and lang != "sh":
            continue
        joined, first = "", None
        for k, line in enumerate(lines):
            text = line.strip()
            if first is None:
                text = re.sub(r"^\$ ", "", text)
                if not (text.startswith("kinestat ") or text.startswith("$K ")):
                    continue
                first = start + 1 + k
            joined += " " + text.rstrip("\\").strip()
            if not text.endswith("\\"):
                out.append((first, joined.strip().replace("$K ", "kinestat ", 1)))
                joined, first = "", None
    return out


def _toml_blocks(path: Path) -> list[str]:
    return ["\n".join(lines) for _, lang, lines in _blocks(path.read_text(encoding="utf-8"),
                                                           False) if lang == "toml"]


@functools.cache
def _erd_urdfs() -> dict[str, Path]:
    """The URDF files of the example-robot-data test dependency, by file name."""
    try:
        robots = Path(str(distribution("example-robot-data").locate_file(
            "cmeel.prefix/share/example-robot-data/robots")))
    except PackageNotFoundError:
        return {}
    return {p.name: p for p in robots.rglob("*.urdf")}


FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
CASES = [(p, n, c) for p in FILES for n, c in _commands(p)]


def test_the_docs_hold_commands():
    assert len(CASES) >= 20
    assert {p.name for p, _, _ in CASES} >= {"README.md", "guidance.md", "ik.md"}


@pytest.mark.parametrize("doc", FILES, ids=[p.name for p in FILES])
def test_every_documented_command_runs(doc, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("COLUMNS", "120")
    ran, skipped = 0, []
    for line_no, command in [(n, c) for p, n, c in CASES if p == doc]:
        where = f"{doc.name}:{line_no}: {command}"
        reason = (None if any(r in command for r in RUN)
                  else next((r for s, r in SKIP if s in command), None))
        bare = re.sub(r"\s*\[[^\[\]]*\]", "", command)  # a synopsis without its options
        if reason is None and SYNOPSIS.search(bare):
            reason = "a synopsis with placeholders"
        command = bare
        if reason is not None:
            skipped.append((where, reason))
            continue
        args = shlex.split(command, comments=True)[1:]
        target = None
        if ">" in args:
            k = args.index(">")
            args, target = args[:k], args[k + 1]
        for a in args:  # a real arm's URDF file that docs/urdf.md copies from example-robot-data
            if a.endswith(".urdf") and not Path(a).exists() and a in _erd_urdfs():
                Path(a).write_bytes(_erd_urdfs()[a].read_bytes())
        for a in args:  # a model file written in the same document's ```toml block
            if a.endswith(".toml") and not Path(a).exists():
                stem = Path(a).stem
                block = next((b for b in _toml_blocks(doc) if f'name = "{stem}"' in b), None)
                if block is not None:
                    Path(a).write_text(block, encoding="utf-8")
        buf, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(err):
            status = main(args)
        assert status == 0, f"{where}\nexit {status}\n{err.getvalue()[-2000:]}"
        if target is not None:
            Path(target).write_text(buf.getvalue(), encoding="utf-8")
        ran += 1
    if ran == 0 and not skipped:
        pytest.skip(f"{doc.name} shows no kinestat command")
    assert ran or skipped


def test_every_timing_in_the_docs_is_from_the_benchmark_record_or_dated():
    """A µs/ms figure outside docs/performance.md (the benchmarks' record) must appear there or
    sit in a paragraph that dates it (YYYY-MM-DD): no stale, undated speed claims."""
    record = (ROOT / "docs" / "performance.md").read_text(encoding="utf-8")
    stale = []
    for doc in FILES:
        if doc.name == "performance.md":
            continue
        for para in re.split(r"\n\s*\n", doc.read_text(encoding="utf-8")):
            dated = re.search(r"20\d\d-\d\d-\d\d", para)
            for m in re.finditer(r"(\d+(?:\.\d+)?)\s?(µs|ms)\b", para):
                if not dated and not re.search(rf"(?<![\d.]){re.escape(m.group(1))}\s?"
                                               rf"{m.group(2)}", record):
                    stale.append(f"{doc.name}: {m.group(0)} in {para[:80]!r}")
    assert not stale, "\n".join(stale)
