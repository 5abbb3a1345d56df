"""kinestat's Numba cache locators: Numba's default order, the set-up check of a cache directory
done once per directory, and saving that still checks (and recreates) the directory."""

from __future__ import annotations

import importlib
import os
import shutil
import sys

import pytest

import kinestat  # noqa: F401  (sets NUMBA_CACHE_LOCATOR_CLASSES before Numba's first import)

# a Numba without NUMBA_CACHE_LOCATOR_CLASSES ignores the variable (kinestat's locators unused)
pytestmark = pytest.mark.skipif(
    not hasattr(importlib.import_module("numba.core.config"), "CACHE_LOCATOR_CLASSES"),
    reason="this Numba has no NUMBA_CACHE_LOCATOR_CLASSES")


def test_the_value_set_at_import_is_numbas_default_order_with_kinestats_first_two():
    from numba.core import caching, config

    from kinestat.serial import _numba_cache

    names = [n.strip().rsplit(".", 1)[-1] for n in _numba_cache.LOCATORS.split(",")]
    assert names == [c.__name__ for c in caching.CacheImpl._locator_classes]
    assert os.environ["NUMBA_CACHE_LOCATOR_CLASSES"] == _numba_cache.LOCATORS
    assert config.CACHE_LOCATOR_CLASSES == _numba_cache.LOCATORS


def test_one_check_per_directory_at_set_up_and_saving_checks_again(tmp_path, monkeypatch):
    from numba.core import caching

    from kinestat.serial import _numba_cache

    src = tmp_path / "ks_two_kernels.py"
    src.write_text("import numba as nb\n\n"
                   "@nb.njit(cache=True)\ndef one(x):\n    return x + 1.0\n\n"
                   "@nb.njit(cache=True)\ndef two(x):\n    return x * 2.0\n")
    checks = []
    base = caching._CacheLocator.ensure_cache_path

    def counted(self):
        checks.append(self.get_cache_path())
        return base(self)

    monkeypatch.setattr(caching._CacheLocator, "ensure_cache_path", counted)
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        mod = importlib.import_module("ks_two_kernels")
        locators = [f._cache._impl.locator for f in (mod.one, mod.two)]
        assert all(isinstance(loc, _numba_cache._CheckedOnce) for loc in locators)
        path = locators[0].get_cache_path()
        assert checks == [path] and path in _numba_cache._WRITABLE  # the second trusted it
        shutil.rmtree(path)  # a save checks again: the directory is made anew
        assert mod.one(1.0) == 2.0 and mod.two(1.0) == 2.0
        assert checks.count(path) == 3
        assert any(name.endswith(".nbi") for name in os.listdir(path))
    finally:
        sys.modules.pop("ks_two_kernels", None)
        _numba_cache._WRITABLE.discard(str(tmp_path))


@pytest.mark.parametrize("cls", ["UserProvidedCacheLocator", "InTreeCacheLocator"])
def test_locators_are_numbas(cls):
    from numba.core import caching

    from kinestat.serial import _numba_cache

    assert issubclass(getattr(_numba_cache, cls), getattr(caching, cls))
