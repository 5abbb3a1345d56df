"""``kinestat control`` as a Python call: one :class:`~kinestat.control.runspec.RunSpec` in,
the run's JSON report out.

>>> from kinestat.app import run
>>> from kinestat.control import RunSpec
>>> report = run(RunSpec(), log=tmp / "log.jsonl")   # doctest: +SKIP
>>> report["converged"], report["states"]            # doctest: +SKIP
(True, 'abcde')

docs/control.md runs this example (tests/test_docs_site.py).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from kinestat.app.control_run import (
    PreparedRun,
    plot_run,
    prepare_control,
    report_dict,
    run_control,
)
from kinestat.control.loop import RunReport
from kinestat.control.runspec import RunSpec
from kinestat.errors import InputError

__all__ = ["run", "execute", "run_dir", "RUNS_DIR"]

RUNS_DIR = Path("kinestat-runs")
"""Where a run without ``log`` writes its log and plots: ``RUNS_DIR/<timestamp>/``."""


def run(spec: RunSpec, *, log: Path | None = None, plot_dir: Path | None = None,
        progress: Callable[[dict], None] | None = None) -> dict:
    """Run ``spec`` on its cell and return the JSON report (the keys of ``kinestat control
    --json``; ``plots`` lists the plots written to ``plot_dir``, none without it).

    ``log``: the cycle log (JSON lines; default ``kinestat-runs/<timestamp>/log.jsonl``).
    Bad settings raise one :class:`~kinestat.errors.InputError` before anything moves; a
    fault of the cell ends the run with a safe stop, and the report says why
    (``converged`` False, ``stop_reason``)."""
    prepared = prepare_control(spec)
    log_path = log if log is not None else run_dir(RUNS_DIR) / "log.jsonl"
    return execute(prepared, Path(log_path), plot_dir, progress)[0]


def execute(prepared: PreparedRun, log_path: Path, plot_dir: Path | None,
            progress: Callable[[dict], None] | None = None,
            on_plot_error: Callable[[InputError], None] | None = None
            ) -> tuple[dict, RunReport]:
    """Run a prepared run, write its plots to ``plot_dir`` (None: none) and return its JSON
    report (with ``plots``) and the loop's :class:`~kinestat.control.loop.RunReport`. A plot
    the log cannot give (an :class:`InputError`) goes to ``on_plot_error`` (default: none)."""
    report = run_control(prepared, log_path, progress=progress)
    out = report_dict(prepared, report)
    plots: list[str] = []
    if plot_dir is not None:
        try:
            plots = plot_run(log_path, plot_dir)
        except InputError as exc:
            if on_plot_error is not None:
                on_plot_error(exc)
    out["plots"] = plots
    return out, report


def run_dir(base: Path) -> Path:
    """A new run directory ``base/<timestamp>[-k]``, created here: two runs started in the
    same second each get their own (mkdir is atomic; checking for it first was not, and two
    runs wrote one interleaved log)."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    base.mkdir(parents=True, exist_ok=True)
    k = 1
    while True:
        d = base / (stamp if k == 1 else f"{stamp}-{k}")
        try:
            d.mkdir()
            return d
        except FileExistsError:
            k += 1
