"""Every tutorial in docs/tutorials/ runs top to bottom, as a reader would run it.

The fenced blocks of a page run in order in one temporary directory: ```python blocks in one
namespace (their ``assert`` lines are the checks), and the ``$ kinestat …`` lines of ```console
blocks through the CLI's entry point (exit status 0 required; ``> FILE`` keeps the output). A
URDF file a page names is copied there from the example-robot-data test dependency first.
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
from importlib.metadata import distribution
from pathlib import Path

import pytest

from kinestat.cli.main import main

ROOT = Path(__file__).resolve().parents[1]
PAGES = sorted(p for p in (ROOT / "docs" / "tutorials").glob("*.md") if p.name != "index.md")


def blocks(text: str) -> list[tuple[int, str, str]]:
    """(line number, language, body) of every fenced block of a Markdown page."""
    out, lang, start, body = [], None, 0, []
    for i, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            if lang is None:
                lang, start, body = line[3:].strip(), i, []
            else:
                out.append((start, lang, "\n".join(body) + "\n"))
                lang = None
        elif lang is not None:
            body.append(line)
    return out


def _run_console(body: str, where: str) -> None:
    for line in body.splitlines():
        if not line.startswith("$ "):
            continue
        args = shlex.split(line[2:], comments=True)
        assert args[0] == "kinestat", f"{where}: only kinestat commands run here: {line}"
        target = None
        if ">" in args:
            k = args.index(">")
            args, target = args[1:k], args[k + 1]
        else:
            args = args[1:]
        buf, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(err):
            status = main(args)
        assert status == 0, f"{where}: {line}\nexit {status}\n{err.getvalue()[-2000:]}"
        if target is not None:
            Path(target).write_text(buf.getvalue(), encoding="utf-8")


def test_the_tutorials_are_there():
    assert len(PAGES) == 5, [p.name for p in PAGES]
    for page in PAGES:
        langs = {lang for _, lang, _ in blocks(page.read_text(encoding="utf-8"))}
        assert langs & {"python", "console"}, f"{page.name} runs nothing"


def test_blocks_reads_fences_in_order():
    text = "a\n```python\nx = 1\n```\n\n```console\n$ kinestat --version\n```\n"
    assert blocks(text) == [(2, "python", "x = 1\n"), (6, "console", "$ kinestat --version\n")]


@pytest.mark.parametrize("page", PAGES, ids=[p.stem for p in PAGES])
def test_tutorial_runs_top_to_bottom(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("COLUMNS", "120")
    text = page.read_text(encoding="utf-8")
    for name in set(re.findall(r"[\w.-]+\.urdf", text)):
        robots = Path(str(distribution("example-robot-data").locate_file(
            "cmeel.prefix/share/example-robot-data/robots")))
        found = next(robots.rglob(name), None)
        if found is not None:
            (tmp_path / name).write_bytes(found.read_bytes())
    namespace: dict = {"__name__": f"tutorial_{page.stem}"}
    ran = 0
    for line_no, lang, body in blocks(text):
        where = f"{page.name}:{line_no}"
        if lang == "python":
            exec(compile(body, where, "exec"), namespace)  # noqa: S102 - the page's own code
        elif lang == "console":
            _run_console(body, where)
        else:
            continue
        ran += 1
    assert ran, f"{page.name}: no block ran"
