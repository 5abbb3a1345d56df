"""``kinestat.control.run``: one call for a task on a cell the caller holds, or for a whole
``kinestat control`` run described by a :class:`~kinestat.control.runspec.RunSpec`.

* ``run(task, io, log)`` — the loop (:func:`kinestat.control.loop.run`) on a cell the caller
  opened (any :class:`~kinestat.control.loop.CellIO`);
* ``run(RunSpec(...), log=path)`` — the command as a Python call: the cell is built from the
  spec (built-in simulator, MuJoCo or the devices) and the run's JSON report is returned.

Building a cell needs the simulators and drivers, which sit above this layer; the package's
root (:mod:`kinestat`, the composition root) hands the runner that does it to
:func:`use_spec_runner` when kinestat is imported, so this module imports none of them.

>>> from kinestat.control import RunSpec, run
>>> report = run(RunSpec(), log=tmp / "log.jsonl")   # doctest: +SKIP
>>> report["converged"], report["states"]            # doctest: +SKIP
(True, 'aaabe')
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["run", "use_spec_runner"]

_spec_runner: list[Callable] = []


def use_spec_runner(runner: Callable) -> None:
    """Make ``runner(spec, **kw)`` the one that runs a RunSpec (the composition root's call)."""
    _spec_runner[:] = [runner]


def run(what, io=None, log=None, **kw):
    """Run a task on ``io`` (returns the loop's
    :class:`~kinestat.control.loop.RunReport`) or a :class:`~kinestat.control.runspec.RunSpec`
    on the cell it describes (returns the JSON report as a dict; ``log``: the log's path,
    ``plot_dir``, ``progress`` as :func:`kinestat.app.control_api.run`)."""
    from kinestat.control.runspec import RunSpec  # lazy: the root imports this module

    if isinstance(what, RunSpec):
        if io is not None:
            from kinestat.errors import InputError  # lazy: as above

            raise InputError("kinestat.control.run(RunSpec(...)) builds its own cell: pass "
                             "log=PATH, plot_dir=, progress=, not a cell")
        return _spec_runner[0](what, log=log, **kw)
    from kinestat.control.loop import run as loop_run  # lazy: as above

    return loop_run(what, io, log, **kw)
