"""The examples of docs/kinestatic.md run and print what the page says; its figure script runs."""

from __future__ import annotations

import doctest
import runpy
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_kinestatic_page_examples_run():
    result = doctest.testfile(str(ROOT / "docs" / "kinestatic.md"), module_relative=False,
                              optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 25 and result.failed == 0


def test_figure_script_writes_a_png(tmp_path):
    out = tmp_path / "wheel.png"
    main = runpy.run_path(str(ROOT / "docs" / "examples" / "kinestatic_wheel_figure.py"))["main"]
    main(str(out))
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 20_000
