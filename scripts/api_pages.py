"""Write the API reference pages of the docs site (docs/reference/api/*.md), one per package.

Each page lists the package's public modules (names not starting with ``_``) as mkdocstrings
blocks, so the reference is generated from the docstrings when the site builds. The command
line has its own reference (docs/cli.md), so ``kinestat.cli`` is left out.

    python scripts/api_pages.py            # (re)write the pages
    python scripts/api_pages.py --check    # exit 1 when a page is missing or out of date
"""

from __future__ import annotations

import argparse
import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "kinestat"
OUT = ROOT / "docs" / "reference" / "api"
SKIP = {"cli", "data"}


def _public(path: Path) -> bool:
    return not any(part.startswith("_") for part in path.relative_to(PACKAGE).with_suffix("").parts
                   if part != "__init__")


def _summary(init: Path) -> str:
    doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or ""
    return doc.strip().split("\n\n")[0].replace("\n", " ")


def pages() -> dict[str, str]:
    """Page name -> Markdown text, for the top-level module and every package."""
    result = {"kinestat": "# kinestat\n\nThe stable top-level API.\n\n::: kinestat\n"
                          "    options:\n      show_root_heading: false\n"}
    for package in sorted(p for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()):
        if package.name in SKIP:
            continue
        name = f"kinestat.{package.name}"
        lines = [f"# {name}", "", _summary(package / "__init__.py"), ""]
        for module in sorted(package.rglob("*.py")):
            if module.name == "__init__.py" and module.parent == package:
                continue
            if not _public(module) or "__pycache__" in module.parts:
                continue
            parts = module.relative_to(ROOT).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            lines.append(f"::: {'.'.join(parts)}\n")
        result[name] = "\n".join(lines).rstrip() + "\n"
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only check the pages")
    args = parser.parse_args(argv)
    wanted = {OUT / f"{name}.md": text for name, text in pages().items()}
    stale = [p for p, text in wanted.items()
             if not p.is_file() or p.read_text(encoding="utf-8") != text]
    extra = [p for p in OUT.glob("*.md") if p not in wanted]
    if args.check:
        for path in stale + extra:
            print(f"api_pages: {path.relative_to(ROOT)} is out of date "
                  "(run python scripts/api_pages.py)", file=sys.stderr)
        return 1 if stale or extra else 0
    OUT.mkdir(parents=True, exist_ok=True)
    for path in extra:
        path.unlink()
    for path in stale:
        path.write_text(wanted[path], encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
