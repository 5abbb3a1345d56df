"""Numba's cache locators, with the check of a cache directory done once per directory.

For every cached kernel it sets up (at its module's import), Numba checks that the kernel's cache
directory exists and is writable: a directory creation and a temporary file, about 0.07 ms a
kernel, tens of kernels before a first ``ik_all`` call. These locators check a directory the
first time a kernel of it is set up and trust it for the others; saving a compiled kernel checks
again, as Numba does.

``import kinestat`` names them in ``NUMBA_CACHE_LOCATOR_CLASSES`` (Numba reads it when it is
first imported, and imports this module when it sets up the first cached kernel), followed by
Numba's other locators in Numba's order; a value the user set is kept (and with it Numba's own
cache handling throughout). Importing this module also installs the library class of
:mod:`kinestat.serial._numba_load`, so that every kernel loads from the cache without parsing
its LLVM bitcode until another kernel links it.
"""

from __future__ import annotations

from numba.core import caching

from kinestat.serial import _numba_load

_numba_load.install()

__all__ = ["UserProvidedCacheLocator", "InTreeCacheLocator", "LOCATORS"]

#: cache directories found writable in this process
_WRITABLE: set[str] = set()


class _CheckedOnce:
    """The set-up check (a locator's first ``ensure_cache_path``) skipped for a directory found
    writable before; later calls (before a save) check as Numba does."""

    _set_up = False

    def ensure_cache_path(self) -> None:
        if not self._set_up:
            self._set_up = True
            path = self.get_cache_path()
            if path in _WRITABLE:
                return
            super().ensure_cache_path()
            _WRITABLE.add(path)
            return
        super().ensure_cache_path()


class UserProvidedCacheLocator(_CheckedOnce, caching.UserProvidedCacheLocator):
    """Numba's locator for ``NUMBA_CACHE_DIR``, checked once per directory."""


class InTreeCacheLocator(_CheckedOnce, caching.InTreeCacheLocator):
    """Numba's locator for the ``__pycache__`` beside the source, checked once per directory."""


#: the value of ``NUMBA_CACHE_LOCATOR_CLASSES``: Numba's default order
LOCATORS = ",".join([f"{__name__}.UserProvidedCacheLocator", f"{__name__}.InTreeCacheLocator",
                     "UserWideCacheLocator", "IPythonCacheLocator", "ZipCacheLocator"])
