"""Compute time of one control cycle: the pure decision plus the PUMA's IK, press vs follow.

Records every (state, measurement) pair of a run on the in-process simulated cell (the
default thesis cell: 5° tilted plane, thesis calibration and sensor), then times the decision
function on each recorded pair (``decide`` for the press task, ``decide_follow`` for a 50 mm
follow run; both include the closed-form reverse analysis, the vernier's rounding to counts and
the envelope's prediction). Also times the parts: the reverse analysis + vernier alone
(``_solve_counts``), the measurement chain (``measure``, not part of the decision), and the
decisions without the vernier. Figures are medians over cycles of the median of repeats.

    .venv/bin/python benchmarks/control_cycle.py [--json]
"""

from __future__ import annotations

import argparse
import copy
import functools
import json
import statistics
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control  # noqa: E402
from kinestat.app.sim_cell import InProcessIO, start_counts  # noqa: E402
from kinestat.control.controller import THESIS_FORCE_DIRECTION, _solve_counts, decide  # noqa: E402
from kinestat.control.follow import decide_follow  # noqa: E402
from kinestat.control.log import CycleLog  # noqa: E402
from kinestat.control.loop import run  # noqa: E402
from kinestat.control.wrench import Measurement, measure  # noqa: E402

START = np.array([-400.0, 800.0, -100.0])


def _record(task: str) -> tuple:
    req = ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                         cell=SimulatedCell(), task=task, travel_dir=np.array([0.0, 1.0, 0.0]))
    prep = prepare_control(req)
    pairs: list = []
    if task == "follow":
        base_fn = functools.partial(decide_follow, prep.follow)
    else:
        base_fn = functools.partial(decide, prep.config)

    def recording(state, meas):
        pairs.append((state, meas))
        return base_fn(state, meas)

    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with tempfile.TemporaryDirectory() as tmp, CycleLog(Path(tmp) / "log.jsonl") as log:
        rep = run(prep.config, io, log, decide_fn=recording)
    return prep, pairs, rep


def _fresh(args: tuple) -> tuple:
    """The call's arguments with a new Measurement object (same values), so that no per-cycle
    data cached for the measurement (:func:`kinestat.control.cycle.cycle_data`) is reused."""
    return tuple(copy.copy(a) if isinstance(a, Measurement) else a for a in args)


def _median_per_call(fn, pairs, repeat: int = 5) -> float:
    per = []
    for p in pairs:
        fn(*_fresh(p))  # warm-up (compiles on the very first call)
        ts = []
        for _ in range(repeat):
            args = _fresh(p)
            t0 = time.perf_counter()
            fn(*args)
            ts.append(time.perf_counter() - t0)
        per.append(statistics.median(ts))
    return statistics.median(per)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    rows = []
    for task in ("press", "follow"):
        prep, pairs, rep = _record(task)
        model = prep.config.model
        if task == "follow":
            fc = prep.follow
            nov = replace(fc, base=replace(fc.base, vernier=False))
            full = functools.partial(decide_follow, fc)
            plain = functools.partial(decide_follow, nov)
        else:
            full = functools.partial(decide, prep.config)
            plain = functools.partial(decide, replace(prep.config, vernier=False))
        moving = [(s, m) for s, m in pairs if full(s, m)[0].kind == "move"]
        targets = [(full(s, m)[0].target, m.q, s.axis_counts) for s, m in moving]
        t_full = _median_per_call(full, moving)
        t_plain = _median_per_call(plain, moving)
        t_ik = _median_per_call(
            lambda t, q, c, model=model: _solve_counts(model, t, q, c, True), targets)
        t_meas = _median_per_call(
            lambda s, m, model=model: measure(model, m.q, m.counts, s.top_pose), moving)
        rows.append({"task": task, "cycles": len(pairs), "moves_timed": len(moving),
                     "decide_us": 1e6 * t_full, "decide_no_vernier_us": 1e6 * t_plain,
                     "ik_vernier_us": 1e6 * t_ik, "measure_us": 1e6 * t_meas,
                     "converged": rep.converged})
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    print(f"{'task':8s} {'cycles':>6s} {'decide+IK':>11s} {'no vernier':>11s} "
          f"{'IK+vernier':>11s} {'measure':>9s}   (µs per cycle, median)")
    for r in rows:
        print(f"{r['task']:8s} {r['cycles']:6d} {r['decide_us']:11.0f} "
              f"{r['decide_no_vernier_us']:11.0f} {r['ik_vernier_us']:11.0f} "
              f"{r['measure_us']:9.0f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
