"""Compute time of one control cycle: the pure decision plus the PUMA's IK, press vs follow.

Records every (state, measurement) pair of a run on the in-process simulated cell (the default
thesis cell: 5° tilted plane, thesis calibration and sensor), then times the decision function
on each recorded pair (``decide`` for the press task, ``decide_follow`` for a 50 mm follow run,
and for one with friction 0.3 on an R = 200 mm cylinder with the automatic tilt;
both include the closed-form reverse analysis, the vernier's rounding to counts and the
prediction). Also times the parts: the move onto the target (reverse analysis, selection and
vernier), the prediction (``predict``), the decision without the vernier, the measurement
chain (``measure``, not part of the decision) and the decision as the control loop makes it
("in loop": each call right after the ``measure`` that makes its Measurement, which leaves the
caches cold: the closest figure to a real cycle). The cycle waits hundreds of milliseconds on
the arm's motion and settling; these figures say how small the decision's share is, they are
not a goal.
Figures are medians over the moving cycles (the follow task's settle and follow cycles: not
its approach or surface-probe moves) of the median of repeats; every call gets a fresh copy
of its Measurement (no per-cycle data is reused between calls). The kernels are compiled (or
loaded from the cache) before anything is timed; that first load is reported on its own.

    .venv/bin/python benchmarks/control_cycle.py [--json] [--repeat N] [--clock wall|cpu]
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from kinestat.app.control_run import (  # noqa: E402
    ControlRequest,
    CylinderSpec,
    SimulatedCell,
    prepare_control,
)
from kinestat.app.sim_cell import InProcessIO, start_counts  # noqa: E402
from kinestat.cli._compile import warm_kernels  # noqa: E402
from kinestat.control.controller import (  # noqa: E402
    THESIS_FORCE_DIRECTION,
    _solve_counts,
    decide,
)
from kinestat.control.follow import decide_follow  # noqa: E402
from kinestat.control.log import CycleLog  # noqa: E402
from kinestat.control.loop import run  # noqa: E402
from kinestat.control.predict import predict  # noqa: E402
from kinestat.control.wrench import Measurement, measure  # noqa: E402

START = np.array([-400.0, 800.0, -100.0])


TASKS = ("press", "press-cylinder", "follow", "follow-friction")
"""The recorded runs: the press task and a 50 mm follow run on the default 5° plane, the press
on an R = 200 mm cylinder with Coulomb friction 0.3 (its stuck tip is shed across S6), and a
follow run with Coulomb friction 0.3 on an R = 200 mm cylinder with the automatic tilt (the
friction estimator, cone normal and curvature fit in every sliding cycle)."""


def _request(task: str) -> ControlRequest:
    if task == "press-cylinder":
        cell = SimulatedCell(friction=0.3, cylinder=CylinderSpec(
            radius=200.0, axis=np.array([0.0, 0.0, 1.0])))
        return ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                              cell=cell, task="press")
    if task == "follow-friction":
        cell = SimulatedCell(friction=0.3, cylinder=CylinderSpec(
            radius=200.0, axis=np.array([0.0, 0.0, 1.0])))
        return ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                              cell=cell, task="follow", travel_dir=np.array([0.0, 1.0, 0.0]),
                              auto_tilt=True)
    return ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                          cell=SimulatedCell(), task=task, travel_dir=np.array([0.0, 1.0, 0.0]))


def _record(task: str) -> tuple:
    prep = prepare_control(_request(task))
    pairs: list = []
    if prep.follow is not None:
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
    """The call's arguments with a new Measurement object (same values, made anew: no cache
    of :meth:`Measurement.tip`), so that no per-cycle data cached for the measurement
    (:func:`kinestat.control.cycle.cycle_data`) is reused."""
    return tuple(replace(a) if isinstance(a, Measurement) else a for a in args)


CLOCKS = {"wall": time.perf_counter, "cpu": time.thread_time}
_clock = CLOCKS["wall"]


def _once(fn, args) -> float:
    args = _fresh(args)
    t0 = _clock()
    fn(*args)
    return _clock() - t0


def _timed(fn, pairs, repeat: int) -> tuple[float, float]:
    """Median over ``pairs`` of the median of ``repeat`` calls, and the same with the best
    (least) of the repeats (less sensitive to other processes on a shared machine); seconds."""
    med, best = [], []
    for p in pairs:
        _once(fn, p)
        ts = [_once(fn, p) for _ in range(repeat)]
        med.append(statistics.median(ts))
        best.append(min(ts))
    return statistics.median(med), statistics.median(best)


def _per_cycle(fn, pairs, repeat: int) -> list[float]:
    """The median of ``repeat`` back-to-back calls, per pair (seconds)."""
    per = []
    for p in pairs:
        _once(fn, p)
        per.append(statistics.median(_once(fn, p) for _ in range(repeat)))
    return per


def _in_loop(fn, model, pairs, repeat: int) -> list[float]:
    """Per pair, the median of ``repeat`` calls each made right after the measurement chain
    that makes its Measurement (``measure`` on the recorded counts, as the control loop
    calls it before every decision: ~0.25 ms, mostly NumPy, that leaves the caches cold),
    seconds.
    The closest of these figures to a cycle of the real loop (which also reads the devices
    and writes the log between decisions)."""
    per = []
    for s, m in pairs:
        ts = []
        for _ in range(repeat):
            fresh = measure(model, m.q, m.counts, s.top_pose)
            t0 = _clock()
            fn(s, fresh)
            ts.append(_clock() - t0)
        per.append(statistics.median(ts))
    return per


def _single(fn, pairs, repeat: int) -> float:
    return statistics.median(_per_cycle(fn, pairs, repeat))


def _task_row(task: str, repeat: int) -> dict:
    prep, pairs, rep = _record(task)
    model = prep.config.model
    if prep.follow is not None:
        fc = prep.follow
        full = functools.partial(decide_follow, fc)
        plain = functools.partial(decide_follow, replace(fc, base=replace(fc.base, vernier=False)))
    else:
        full = functools.partial(decide, prep.config)
        plain = functools.partial(decide, replace(prep.config, vernier=False))
    moving = []
    for s, m in pairs:
        cmd = full(s, m)[0]
        # the follow task's timed cycles are its force + motion ones (settle, follow): its
        # approach and probe moves (a step along S6 or across, no decomposition) are cheaper
        # and would pull the median down
        if cmd.kind == "move" and (prep.follow is None
                                   or cmd.action not in ("approach", "probe")):
            moving.append((s, m, cmd))
    decisions = [(s, m) for s, m, _ in moving]
    targets = [(c.target, m.q, s.axis_counts) for s, m, c in moving]
    poses = [(m, model.arm.flange_pose(c.q)) for s, m, c in moving]
    t_full, b_full = _timed(full, decisions, repeat)
    t_ik, _ = _timed(lambda t, q, c: _solve_counts(model, t, q, c, True), targets, repeat)
    t_pred, _ = _timed(lambda m, T: predict(model, m, T), poses, repeat)
    t_plain = _single(plain, decisions, repeat)
    alone = _per_cycle(full, decisions, repeat)
    t_alone = statistics.median(alone)
    # the cycles in contact (the press's align, force and shed moves; for the follow task the
    # timed cycles are already its settle and follow ones): the press's approach steps are
    # cheaper and make most of its moving cycles
    contact = [t for t, (_, _, c) in zip(alone, moving, strict=True)
               if c.action not in ("approach", "probe")]
    t_meas = _single(lambda s, m: measure(model, m.q, m.counts, s.top_pose), decisions, repeat)
    loop = _in_loop(full, model, decisions, repeat)
    loop_contact = [t for t, (_, _, c) in zip(loop, moving, strict=True)
                    if c.action not in ("approach", "probe")]
    return {"task": task, "cycles": len(pairs), "moves_timed": len(moving),
            "decide_us": 1e6 * t_full, "decide_best_us": 1e6 * b_full,
            "ik_vernier_us": 1e6 * t_ik, "predict_us": 1e6 * t_pred,
            "rest_us": 1e6 * max(t_full - t_ik - t_pred, 0.0),
            "decide_no_vernier_us": 1e6 * t_plain, "decide_alone_us": 1e6 * t_alone,
            "contact_alone_us": 1e6 * statistics.median(contact) if contact else None,
            "contact_cycles": len(contact), "slowest_alone_us": 1e6 * max(alone),
            "measure_us": 1e6 * t_meas,
            "in_loop_us": 1e6 * statistics.median(loop),
            "in_loop_contact_us": (1e6 * statistics.median(loop_contact) if loop_contact
                                   else None),
            "converged": rep.converged}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--repeat", type=int, default=5, help="calls per cycle (median)")
    ap.add_argument("--clock", choices=tuple(CLOCKS), default="wall",
                    help="wall time (default) or this thread's CPU time (leaves out the time "
                         "other processes hold the CPU on a shared machine)")
    args = ap.parse_args(argv)
    global _clock
    _clock = CLOCKS[args.clock]
    t0 = time.perf_counter()
    warm_kernels()  # compile (first run) or load from the cache: never part of a cycle's time
    first_load_s = time.perf_counter() - t0
    rows = [_task_row(task, args.repeat) for task in TASKS]
    meta = {"date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
            "machine": f"{platform.machine()}, {os.cpu_count()} cores",
            "python": platform.python_version(), "kernel_load_s": first_load_s,
            "clock": args.clock, "load_average": os.getloadavg()[0]}
    if args.json:
        print(json.dumps({"meta": meta, "tasks": rows}, indent=2))
        return 0
    print(f"{meta['date']}, {meta['machine']}, load average {meta['load_average']:.1f}, "
          f"{args.clock} clock; kernels compiled/loaded first in {first_load_s:.1f} s (not timed)")
    print("µs per cycle (median over the moving cycles)")
    print(f"{'task':15s} {'cycles':>6s} {'decide+IK':>10s} {'best-of':>8s} {'IK+vernier':>11s} "
          f"{'prediction':>11s} {'rest':>6s} {'no vernier':>11s} {'measure':>8s} {'alone':>6s} "
          f"{'contact':>8s} {'slowest':>8s} {'in loop':>8s} {'(contact)':>9s}")
    for r in rows:
        print(f"{r['task']:15s} {r['cycles']:6d} {r['decide_us']:10.0f} "
              f"{r['decide_best_us']:8.0f} {r['ik_vernier_us']:11.0f} {r['predict_us']:11.0f} "
              f"{r['rest_us']:6.0f} {r['decide_no_vernier_us']:11.0f} {r['measure_us']:8.0f} "
              f"{r['decide_alone_us']:6.0f} "
              + (f"{r['contact_alone_us']:8.0f}" if r["contact_cycles"] else f"{'-':>8s}")
              + f" {r['slowest_alone_us']:8.0f} {r['in_loop_us']:8.0f} "
              + (f"{r['in_loop_contact_us']:9.0f}" if r["contact_cycles"] else f"{'-':>9s}"))
    print("best-of: the least of the repeats per cycle (median over cycles); alone: the calls "
          "back to back on the same inputs (the caches warm, a lower bound); contact: the same "
          "over the cycles in contact only; slowest: the slowest timed cycle, alone; in loop: "
          "each call right after the measurement chain that makes its measurement (the caches "
          "cold), the closest to a real cycle")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
