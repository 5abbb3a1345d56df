"""Human output never hides what a user needs (issue 16): narrow consoles fold long cells
instead of cutting them, summaries are key: value lines, COLUMNS is honoured when piped."""

from __future__ import annotations

import json
import re

import pytest
from rich.console import Console

from kinestat.cli import _output
from kinestat.cli.main import main


def _events_from_json(capsys) -> list[dict]:
    assert main(["disp", "illustration4", "--json"]) == 0
    return json.loads(capsys.readouterr().out)["events"]


@pytest.mark.parametrize("columns", [80, 60])
def test_disp_illustration4_shows_the_singular_event_in_full_when_piped(capsys, monkeypatch,
                                                                       columns):
    events = _events_from_json(capsys)
    singular = [e for e in events if e["kind"] == "singular"]
    assert singular, "illustration 4 passes a singular configuration"
    monkeypatch.setenv("COLUMNS", str(columns))
    assert main(["disp", "illustration4"]) == 0
    out = capsys.readouterr().out
    assert max(len(line) for line in out.splitlines()) <= columns
    for ev in singular:
        assert re.search(rf"│\s+{ev['step']}\s+│\s+singular\s+│", out), out[-3000:]
    assert "…" not in out
    # the summary's labels are whole, each on its own line
    for label in ("final hand origin", "max deviation from the ideal path", "final pose error"):
        assert re.search(rf"^\s*{re.escape(label)}:", out, re.M), label


def test_piped_width_follows_columns(monkeypatch):
    monkeypatch.setenv("COLUMNS", "97")
    assert _output.console.width == 97
    monkeypatch.delenv("COLUMNS")
    if not _output.console.is_terminal:
        assert _output.console.width == _output.PIPE_WIDTH


def test_a_long_cell_folds_and_short_columns_stay_whole():
    long = " ".join(f"word{i}=value{i}" for i in range(40))
    t = _output.table("T", ["step", "kind", "details"], [[123456, "singular", long]])
    con = Console(width=50, record=True, file=open("/dev/null", "w"))  # noqa: SIM115
    con.print(t)
    text = con.export_text()
    assert "123456" in text and "singular" in text and "…" not in text
    flat = re.sub(r"[│\s]+", "", text)
    assert re.sub(r"\s+", "", long) in flat  # every character of the long cell is printed


def test_print_pairs_never_cuts_a_value(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "40")
    value = "a note that is much longer than forty columns and must wrap, not end in dots"
    _output.print_pairs("Summary", [("a rather long label", value), ("x", 1.5)])
    out = capsys.readouterr().out
    assert "…" not in out
    assert " ".join(out.split()).count(value.split()[-1]) == 1
    assert "a rather long label:" in out and "1.5000" in out
