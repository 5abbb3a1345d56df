"""kinestat: kinematics and statics (kinestatics) of robot manipulators.

The stable top-level API::

    import kinestat
    model = kinestat.load("puma762")          # an embedded model or a TOML file
    T = kinestat.fk(model, q)                 # (..., 4, 4) for q of shape (..., n)
    J = kinestat.jacobian(model, q)           # (..., 6, n), twists [w; v_O]
    res = kinestat.ik(model, poses)           # numerical IK, batched, honest success flags
"""

from __future__ import annotations

import os

import lazy_loader

# The batch kernels run over the cores on OpenMP threads (Numba). libgomp's default lets a
# worker spin for milliseconds before it sleeps, and on a machine whose cores are shared that
# spinning takes the core from the thread the batch waits for (twice the wall time, measured on
# 2 cores); the workers sleep instead, unless the user chose otherwise.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
# Numba checks a kernel's cache directory (a directory creation and a temporary file) for every
# cached kernel it sets up; kinestat's locators check each directory once per process (the
# value is kinestat.serial._numba_cache.LOCATORS; Numba reads it on its first import)
os.environ.setdefault(
    "NUMBA_CACHE_LOCATOR_CLASSES",
    "kinestat.serial._numba_cache.UserProvidedCacheLocator,"
    "kinestat.serial._numba_cache.InTreeCacheLocator,"
    "UserWideCacheLocator,IPythonCacheLocator,ZipCacheLocator")

__version__ = "0.2.0"  # the one place the version is written (pyproject reads it)

# the public names load with their module on first use (PEP 562, lazy_loader), and are then
# kept as the module's attributes: later uses do not go through __getattr__ (a twentieth of a
# one-configuration fk call)
_lazy_getattr, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'errors': ['KinestatError'],
        'io.library': ['list_models', 'load'],
        'mechanism.chain': ['ChainModel'],
        'serial.fk': ['fk'],
        'serial.ik': ['ik'],
        'serial.analytic': ['ik_all'],
        'serial.jacobian': ['jacobian'],
    },
)


def __getattr__(name: str):
    value = _lazy_getattr(name)
    globals()[name] = value
    return value


def _run_spec(spec, **kw):
    """The composition root's runner of a ``RunSpec``: the application layer builds the cell.
    Named, as the table above names its modules: the root wires the layers, and a module that
    imports the root for its version or ``load`` does not thereby depend on the application."""
    import importlib  # lazy: on the first run only

    return importlib.import_module("kinestat.app.control_api").run(spec, **kw)


def _wire() -> None:
    from kinestat.control.entry import use_spec_runner  # lazy: light, imports nothing

    use_spec_runner(_run_spec)


_wire()
