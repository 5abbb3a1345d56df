"""Start-up stays cheap: importing kinestat or registering the CLI commands loads no Numba or
SciPy (issue 16), and every lazily exported name of a package still resolves."""

from __future__ import annotations

import importlib
import json
import pkgutil
import subprocess
import sys

import pytest

import kinestat

HEAVY = ("numba", "scipy")
PACKAGES = ["kinestat"] + sorted(
    f"kinestat.{m.name}" for m in pkgutil.iter_modules(kinestat.__path__) if m.ispkg
    and m.name != "data")

# `kinestat control` belongs to the cell's helpers; its module imports kinestat.app at the top
# (see the issue-16 report for the change that makes it lazy too).
EAGER_CLI = {"control"}


def _loaded_after(statement: str) -> list[str]:
    code = (f"import sys\n{statement}\nimport json\n"
            f"print(json.dumps([h for h in {HEAVY!r} if h in sys.modules]))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def test_import_kinestat_loads_neither_numba_nor_scipy():
    assert _loaded_after("import kinestat") == []


@pytest.mark.parametrize("module", ["_output", "_guidance", "fk", "ik", "disp", "guide",
                                    "platform", "screw", "dh_from_axes", "demo", "sim"])
def test_cli_modules_register_without_numba_or_scipy(module):
    assert module not in EAGER_CLI
    assert _loaded_after(f"import kinestat.cli.{module}") == []


@pytest.mark.parametrize("package", PACKAGES)
def test_every_public_name_of_a_package_resolves(package):
    mod = importlib.import_module(package)
    lazy = getattr(mod, "_LAZY", {})
    for name in getattr(mod, "__all__", []):
        assert getattr(mod, name) is not None, f"{package}.{name}"
    for name, (where, attr) in lazy.items():
        target = importlib.import_module(where)
        expected = target if attr is None else getattr(target, attr)
        assert getattr(mod, name) is expected, f"{package}.{name} is not {where}.{attr}"
    assert set(getattr(mod, "__all__", [])) <= set(dir(mod))


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no_such_name"):
        kinestat.no_such_name  # noqa: B018
