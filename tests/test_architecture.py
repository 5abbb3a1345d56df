"""The architecture rules of docs/architecture.md that the import contract cannot state.

The layer contract itself is `.importlinter`, checked by `lint-imports` in `make test` (and here,
so that a plain `pytest` run checks it too)."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "kinestat"
SOURCES = sorted(PACKAGE.rglob("*.py"))
MAX_FUNCTION_LINES = 120
MAX_MODULE_LINES = 600


def _tree(path: Path) -> tuple[ast.Module, list[str]]:
    text = path.read_text(encoding="utf-8")
    return ast.parse(text), text.splitlines()


def _functions(tree: ast.Module):
    return [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)]


def _unexplained_imports(fn: ast.AST, lines: list[str]) -> list[int]:
    """Line numbers of the imports in ``fn`` with no ``# lazy: <reason>``: on the import itself,
    or on the comment line right above the run of consecutive imports it belongs to."""
    imports = sorted((n for n in ast.walk(fn) if isinstance(n, ast.Import | ast.ImportFrom)),
                     key=lambda n: n.lineno)
    missing, first = [], None
    for k, node in enumerate(imports):
        if k == 0 or node.lineno != imports[k - 1].end_lineno + 1:
            first = node  # a new run of consecutive imports starts here
        above = lines[first.lineno - 2].strip() if first.lineno >= 2 else ""
        own = lines[node.lineno - 1:node.end_lineno]
        if not (above.startswith("# lazy:") or any("# lazy:" in line for line in own)):
            missing.append(node.lineno)
    return missing


def test_the_import_contract_holds():
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    if exe is None:
        pytest.skip("lint-imports is not installed (requirements/dev.txt installs it)")
    run = subprocess.run([exe, "--no-cache"], cwd=PACKAGE.parent, capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]


def test_function_local_imports_say_why():
    missing = []
    for path in SOURCES:
        tree, lines = _tree(path)
        for fn in _functions(tree):
            missing += [f"{path.relative_to(PACKAGE.parent)}:{line}"
                        for line in _unexplained_imports(fn, lines)]
    missing = sorted(set(missing))
    assert not missing, "function-local imports without a '# lazy: <reason>' comment: " + \
        ", ".join(missing)


def _body_lines(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Lines of a function's body after its docstring: a command's signature of option
    declarations is not logic."""
    body = fn.body[1:] if (fn.body and isinstance(fn.body[0], ast.Expr)
                           and isinstance(fn.body[0].value, ast.Constant)
                           and isinstance(fn.body[0].value.value, str)) else fn.body
    return 0 if not body else fn.end_lineno - body[0].lineno + 1


def test_functions_are_short():
    long = []
    for path in SOURCES:
        tree, _ = _tree(path)
        for fn in _functions(tree):
            size = _body_lines(fn)
            if size > MAX_FUNCTION_LINES:
                long.append(f"{path.relative_to(PACKAGE.parent)}:{fn.lineno} {fn.name} ({size})")
    assert not long, f"function bodies over {MAX_FUNCTION_LINES} lines: " + ", ".join(long)


def test_long_modules_say_why_at_the_top():
    unexplained = []
    for path in SOURCES:
        tree, lines = _tree(path)
        doc = ast.get_docstring(tree) or ""
        if len(lines) > MAX_MODULE_LINES and f"{MAX_MODULE_LINES} lines" not in doc:
            unexplained.append(f"{path.relative_to(PACKAGE.parent)} ({len(lines)} lines)")
    assert not unexplained, (
        f"modules over {MAX_MODULE_LINES} lines without a reason in their docstring "
        "(write 'Over 600 lines on purpose: <why>'): " + ", ".join(unexplained))


CONTROL = PACKAGE / "control"
CONTROL_MAX_MODULE_LINES, CONTROL_MAX_FUNCTION_LINES = 400, 60
#: packages of control/ exempt from the limits: none (the follow task keeps them too)
CONTROL_SIZE_EXEMPT: tuple[str, ...] = ()


def test_control_modules_and_functions_are_small():
    """Issue 41: kinestat/control/ modules within 400 lines and whole functions within 60."""
    big = []
    for path in sorted(CONTROL.rglob("*.py")):
        if path.relative_to(CONTROL).parts[0].removesuffix(".py") in CONTROL_SIZE_EXEMPT:
            continue
        tree, lines = _tree(path)
        where = path.relative_to(PACKAGE.parent)
        if len(lines) > CONTROL_MAX_MODULE_LINES:
            big.append(f"{where} ({len(lines)} lines)")
        big += [f"{where}:{fn.lineno} {fn.name} ({fn.end_lineno - fn.lineno + 1})"
                for fn in _functions(tree)
                if fn.end_lineno - fn.lineno + 1 > CONTROL_MAX_FUNCTION_LINES]
    assert not big, "over the control package's size limits: " + ", ".join(big)
