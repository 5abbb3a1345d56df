"""Cached kernels loaded without parsing their bitcode (kinestat.serial._numba_load): the symbols
read from the object file are those Numba reads from the bitcode, a loaded kernel runs, and a
kernel compiled later links it (its bitcode parsed then)."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import kinestat  # noqa: F401  (sets NUMBA_CACHE_LOCATOR_CLASSES before Numba's first import)

_KERNELS = textwrap.dedent("""\
    import math
    import numba as nb
    import numpy as np

    @nb.njit(cache=True)
    def one(x, out):
        for i in range(x.shape[0]):
            out[i] = math.atan2(x[i], 1.0 + i)
        if x.shape[0] > 8:
            raise ValueError("too many")
        return out.sum()

    @nb.njit(cache=True)
    def two(x):
        return np.linalg.norm(x) + 1.0
""")

#: the second process: load both kernels from the cache, then compile one that calls them
_LOAD = textwrap.dedent("""\
    import sys, numpy as np
    import kinestat
    from kinestat.serial import _numba_cache, _numba_load
    import ks_cached as k
    x = np.array([0.5, -1.0, 2.0])
    s, n = k.one(x, np.empty(3)), k.two(x)
    lib = k.one.overloads[k.one.signatures[0]].library
    assert k.one.stats.cache_hits and k.two.stats.cache_hits, "not loaded from the cache"
    assert isinstance(lib, _numba_load.LazyLinkLibrary)
    lazy = lib._shared_module is None and lib._shared_bitcode is not None
    import numba as nb

    @nb.njit
    def three(x):
        return k.one(x, np.empty(x.shape[0])) + k.two(x)

    t = three(x)
    print(repr(s), repr(n), repr(t), lazy, lib._shared_module is not None)
""")


def _run(code: str, cwd: Path, cache: Path) -> str:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache),
               PYTHONPATH=os.pathsep.join([str(cwd), str(Path(kinestat.__file__).parents[1])]))
    out = subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout


@pytest.fixture(scope="module")
def cached(tmp_path_factory):
    """A module of two cached kernels, compiled once into a fresh cache directory."""
    root = tmp_path_factory.mktemp("ks_load")
    (root / "ks_cached.py").write_text(_KERNELS)
    cache = root / "cache"
    _run("import kinestat, numpy as np, ks_cached as k; "
         "k.one(np.zeros(3), np.empty(3)); k.two(np.zeros(3))", root, cache)
    return root, cache


def test_a_loaded_kernel_runs_and_a_new_kernel_links_it(cached):
    import numpy as np

    root, cache = cached
    s, n, t, lazy, parsed = _run(_LOAD, root, cache).split()
    x = np.array([0.5, -1.0, 2.0])
    want_s = float(np.sum(np.arctan2(x, 1.0 + np.arange(3))))
    want_n = float(np.linalg.norm(x)) + 1.0
    assert float(s) == pytest.approx(want_s, rel=1e-15)
    assert float(n) == pytest.approx(want_n, rel=1e-15)
    assert float(t) == pytest.approx(want_s + want_n, rel=1e-15)
    assert lazy == "True"  # the load left the bitcode unparsed
    assert parsed == "True"  # linking into `three` parsed it


def test_the_object_files_symbols_are_the_bitcodes(cached, monkeypatch):
    """Every cached kernel's defined symbols read from its object file equal those Numba reads
    from its bitcode (functions and globals that are not declarations)."""
    from llvmlite import binding as ll

    from kinestat.serial._numba_load import defined_symbols

    root, cache = cached
    monkeypatch.syspath_prepend(str(root))  # the cache entries name the kernels' module
    files = sorted(cache.rglob("*.nbc"))
    assert len(files) >= 2
    try:
        for f in files:
            name, kind, (obj, bitcode) = pickle.loads(f.read_bytes())[0]
            assert kind == "object"
            mod = ll.parse_bitcode(bitcode)
            want = {g.name for gs in (mod.functions, mod.global_variables) for g in gs
                    if not g.is_declaration}
            got = defined_symbols(obj)
            if sys.platform.startswith("linux"):
                assert got == want, f.name
            else:  # Mach-O, COFF: Numba's own load
                assert got is None
    finally:
        sys.modules.pop("ks_cached", None)


def test_what_is_not_an_elf_object_is_left_to_numba():
    from kinestat.serial._numba_load import defined_symbols

    assert defined_symbols(b"") is None
    assert defined_symbols(b"\xcf\xfa\xed\xfe" + bytes(60)) is None  # Mach-O 64
    assert defined_symbols(b"\x7fELF\x02\x01\x01" + bytes(20)) is None  # truncated


def test_numbas_cpu_code_generator_uses_the_class():
    from numba.core import codegen

    from kinestat.serial import _numba_cache  # noqa: F401  (installs it)
    from kinestat.serial._numba_load import LazyLinkLibrary

    assert codegen.JITCPUCodegen._library_class is LazyLinkLibrary


def test_an_unchecked_numba_release_keeps_numbas_own_load(monkeypatch):
    import numba
    from numba.core import codegen

    from kinestat.serial import _numba_load

    monkeypatch.setattr(codegen.JITCPUCodegen, "_library_class", codegen.JITCodeLibrary)
    monkeypatch.setattr(numba, "__version__", "0.99.0")
    _numba_load.install()
    assert codegen.JITCPUCodegen._library_class is codegen.JITCodeLibrary
    monkeypatch.setattr(numba, "__version__", _numba_load.CHECKED_NUMBA[0] + ".1")
    _numba_load.install()
    assert codegen.JITCPUCodegen._library_class is _numba_load.LazyLinkLibrary
