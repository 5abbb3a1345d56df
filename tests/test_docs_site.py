"""The documentation site's own rules (the site itself is built with --strict by make test).

Pages stay readable (no page over 600 lines, the control guide within 400), the API reference
lists every public module (scripts/api_pages.py), and the docs site's doctest fencing works.
"""

from __future__ import annotations

import doctest
import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = sorted((ROOT / "docs").rglob("*.md"))


def _script(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_no_page_is_over_600_lines():
    long = {p.relative_to(ROOT).as_posix(): n for p in PAGES
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > 600}
    assert PAGES and not long, long


def test_the_control_guide_stays_within_400_lines():
    assert len((ROOT / "docs" / "control.md").read_text(encoding="utf-8").splitlines()) <= 400


def test_the_api_reference_pages_are_current():
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "api_pages.py"), "--check"],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_the_api_reference_lists_the_public_modules():
    pages = _script("api_pages").pages()
    text = "\n".join(pages.values())
    assert "::: kinestat.serial.fk\n" in text and "::: kinestat.spatial.transforms\n" in text
    assert "kinestat.cli" not in text and "._" not in text


def test_doctest_paragraphs_are_fenced_for_the_site():
    module = _script("griffe_doctest_blocks")
    assert doctest.testmod(module).failed == 0
    fenced = module.fence_doctests("```python\n>>> x\n```\n\n>>> 1\n1")
    assert fenced == "```python\n>>> x\n```\n\n```pycon\n>>> 1\n1\n```"


def test_the_user_docs_do_not_link_the_notes():
    linked = [p.name for p in PAGES if "](../notes/" in p.read_text(encoding="utf-8")
              or "](notes/" in p.read_text(encoding="utf-8")]
    assert not linked, linked
