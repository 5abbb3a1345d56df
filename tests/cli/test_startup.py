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

import kinestat.cli  # noqa: E402  (the command modules, listed below)

CLI_MODULES = sorted(m.name for m in pkgutil.iter_modules(kinestat.cli.__path__))
#: a command that runs compiled kernels (the PUMA 762 closed form, Vibhute App. C example)
IK_CLOSED_FORM = ["ik", "puma762", "--tool-point", "725,190,650", "--s6", "1,0,0", "--a67",
                  "0,0,1"]


def _loaded_after(statement: str) -> list[str]:
    code = (f"import sys\n{statement}\nimport json\n"
            f"print(json.dumps([h for h in {HEAVY!r} if h in sys.modules]))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def test_import_kinestat_loads_neither_numba_nor_scipy():
    assert _loaded_after("import kinestat") == []


@pytest.mark.parametrize("module", CLI_MODULES)
def test_cli_modules_register_without_numba_or_scipy(module):
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


def _ik_in_a_fresh_process(cache_dir) -> subprocess.CompletedProcess:
    code = "import sys; from kinestat.cli.main import main; sys.exit(main(sys.argv[1:]))"
    env = {**__import__("os").environ, "NUMBA_CACHE_DIR": str(cache_dir)}
    return subprocess.run([sys.executable, "-c", code, *IK_CLOSED_FORM, "--json"],
                          capture_output=True, text=True, timeout=600, env=env)


def test_the_first_run_says_it_compiles_and_the_second_does_not(tmp_path):
    first = _ik_in_a_fresh_process(tmp_path)
    assert first.returncode == 0, first.stderr
    assert "compiling kernels (first run only)" in first.stderr
    json.loads(first.stdout)  # stdout stays clean JSON
    second = _ik_in_a_fresh_process(tmp_path)
    assert second.returncode == 0, second.stderr
    assert "compiling" not in second.stderr
    assert json.loads(second.stdout) == json.loads(first.stdout)


def test_warmup_reports_the_groups_make_run_uses_and_all_of_them_with_all(capsys):
    from kinestat.cli._compile import KERNELS, RUN_GROUPS, is_cold
    from kinestat.cli.main import main

    assert main(["warmup", "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert set(rec["seconds"]) == set(RUN_GROUPS)
    assert not any(is_cold(g) for g in RUN_GROUPS)
    assert main(["warmup", "--all", "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert set(rec["seconds"]) == set(KERNELS)
    assert set(rec["compiled"]) <= set(KERNELS)
    assert not any(is_cold(g) for g in KERNELS)  # after a warm-up nothing is cold
