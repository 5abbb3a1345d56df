"""The follow task over 20 random workpieces (issue 13 item 5): figures for docs/control.md.

Runs ``kinestat control --task follow`` (50 mm, |F_req| = 4 N, thesis calibration, legs and
sensor resolution) on the in-process simulated cell for 10 random planes (1.5-4 mm ahead of
the start tool point, normal tilted 0-8° from −F_req in a random azimuth) and 10 random
cylinders (radius 150-400 mm, axis within ~20° of the fixed z axis), the initial travel
direction within ~11° of +y; then the acceptance runs (the default plane and the R = 200 mm
cylinder, thesis and ideal sensor). Prints one row per run (true figures from the simulator)
and a summary. Options: ``--devices`` (through the simulated Galil and encoder stream, as
``kinestat control`` without device options, instead of the in-process cell; about a minute
of one core per run), ``--jobs N`` (runs in parallel processes), ``--friction MU`` (Coulomb
friction of every workpiece), ``--ideal`` (1 nm leg encoders instead of the thesis's
resolution), ``--auto-tilt auto|on|off`` (the follow task's automatic tilt; default auto, as
the CLI: it switches itself on when the tip sticks; the friction studies before 2026-12-02
ran with it on from the start), ``--sim kinestat|mujoco`` (the plant: the built-in simulator,
or MuJoCo in process as ``kinestat control --sim mujoco``; true figures from MuJoCo's contact
force).

    .venv/bin/python scripts/follow_study.py [N] [--acceptance] [--friction MU] [--ideal]
        [--auto-tilt auto|on|off] [--seed N] [--budget] [--devices] [--jobs N]
        [--sim kinestat|mujoco]
"""

from __future__ import annotations

import argparse
import concurrent.futures
import dataclasses
import functools
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from kinestat.app.control_run import (  # noqa: E402
    ControlRequest,
    CylinderSpec,
    SimulatedCell,
    prepare_control,
    report_dict,
    run_control,
)
from kinestat.app.sim_cell import InProcessIO, start_counts  # noqa: E402
from kinestat.control.controller import THESIS_FORCE_DIRECTION  # noqa: E402
from kinestat.control.follow import decide_follow  # noqa: E402
from kinestat.control.log import CycleLog  # noqa: E402
from kinestat.control.loop import run  # noqa: E402

START = np.array([-400.0, 800.0, -100.0])
F_HAT = np.asarray(THESIS_FORCE_DIRECTION)
Y = np.array([0.0, 1.0, 0.0])


def random_cell(rng: np.random.Generator, k: int) -> tuple[str, SimulatedCell]:
    if k % 2 == 0:
        tilt, az = math.radians(rng.uniform(0, 8)), rng.uniform(0, 2 * math.pi)
        u = np.cross(F_HAT, Y)
        u /= np.linalg.norm(u)
        v = np.cross(F_HAT, u)
        n = -(math.cos(tilt) * F_HAT + math.sin(tilt) * (math.cos(az) * u + math.sin(az) * v))
        d = rng.uniform(1.5, 4.0)
        return (f"plane {math.degrees(tilt):.1f}°",
                SimulatedCell(plane_point=START + d * F_HAT, plane_normal=n))
    r = rng.uniform(150, 400)
    axis = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.2, 0.2), 1.0])
    return f"cylinder R {r:.0f}", SimulatedCell(cylinder=CylinderSpec(radius=r, axis=axis))


AUTO_TILT = {"auto": None, "on": True, "off": False}


def wood_stiffnesses(seed: int, n: int, wood: tuple[float, float] | None) -> list[float | None]:
    """Per run, None (rigid) or, with even odds when ``wood = (LO, HI)`` is given, a workpiece
    stiffness log-uniform in LO-HI N/mm; drawn from a stream of its own (``[seed, 1]``), so
    that the campaigns' workpieces stay those of the seed."""
    rng = np.random.default_rng([seed, 1])
    out: list[float | None] = []
    for _ in range(n):
        k = None
        if wood and rng.random() < 0.5:
            k = float(np.exp(rng.uniform(*np.log(wood))))
        out.append(k)
    return out


def follow(cell: SimulatedCell, travel_dir, travel: float = 50.0,
           auto_tilt: bool | None = None, devices: bool = False, force: float = 4.0) -> dict:
    """One follow run on ``cell`` (|F_req| = ``force`` N along the thesis's direction): in
    process, or (``devices``) through the simulated Galil and encoder stream as
    ``kinestat control`` runs it."""
    req = ControlRequest(force=force * F_HAT, start_tool_point=START, cell=cell, task="follow",
                         travel=travel, travel_dir=np.asarray(travel_dir, dtype=float),
                         auto_tilt=auto_tilt)
    prep = prepare_control(req)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        if devices or prep.plant is not None:  # the MuJoCo plant runs as the CLI runs it
            rep = run_control(prep, Path(tmp) / "log.jsonl")
        else:
            io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
            with CycleLog(Path(tmp) / "log.jsonl") as log:
                rep = run(prep.config, io, log,
                          decide_fn=functools.partial(decide_follow, prep.follow))
    out = report_dict(prep, rep)
    out["wall_s"] = time.perf_counter() - t0
    return out


def error_budget(out: dict, target: float = 4.0) -> tuple[float, int, float, int]:
    """The true normal-force error's squares summed over the travel cycles before the first
    friction sample (the tip stuck, the normal still the first contact's force) and from it
    on: ``(N² before, cycles before, N² after, cycles after)``. A frictionless run, whose μ̂
    stays 0, counts as all "before"."""
    sums = [0.0, 0, 0.0, 0]
    slid = False
    for c in out["cycles"]:
        if c.get("phase") != "travel" or c.get("true_force") is None:
            continue
        slid = slid or bool(c.get("friction_ratio"))
        fn = -float(np.asarray(c["true_force"]) @ np.asarray(c["true_normal"]))
        k = 2 if slid else 0
        sums[k] += (fn - target) ** 2
        sums[k + 1] += 1
    return sums[0], sums[1], sums[2], sums[3]


def _row(name: str, out: dict, budget: bool = False) -> str:
    def f(key, fmt):
        v = out.get(key)
        return "-" if v is None else format(v, fmt)
    extra = ""
    if budget:
        b, nb, a, na = error_budget(out)
        extra = f" {b:.3f} N² / {nb} | {a:.3f} N² / {na} |"
    return (f"| {name:18s} | {'yes' if out['completed'] else 'NO':3s} | {out['travel']:6.2f} | "
            f"{f('true_normal_force_rms_error', '.3f'):>6s} | "
            f"{f('true_normal_force_max_error', '.3f'):>6s} | {out['contact_lost']} | "
            f"{out['iterations']:3d} | {f('friction_estimate', '.3f'):>5s} | "
            f"{out['stop_reason'][:60]} |" + extra)


HEAD = "| workpiece          | ok  | travel | RMS N  | max N  | lost | cycles | mu^ | stop |"


def main(n: int = 20, friction: float = 0.0, ideal: bool = False,
         auto_tilt: str = "auto", seed: int = 13, budget: bool = False,
         devices: bool = False, jobs: int = 1, sim: str = "kinestat") -> None:
    rng = np.random.default_rng(seed)
    print(f"friction {friction:g}, {'ideal' if ideal else 'thesis'} sensor, automatic tilt "
          f"{auto_tilt}, seed {seed}, "
          + ("through the simulated devices" if devices else "in-process cell")
          + f", plant {sim}")
    print(HEAD + (" error² before the first slip / cycles | after |" if budget else ""))
    draws = []  # drawn up front, in order: the same workpieces whatever --jobs
    for k in range(n):
        name, cell = random_cell(rng, k)
        cell = dataclasses.replace(cell, friction=friction, ideal_sensor=ideal, plant=sim)
        draws.append((name, cell, Y + rng.uniform(-0.2, 0.2, 3)))
    run_one = functools.partial(_follow_drawn, auto_tilt=AUTO_TILT[auto_tilt], devices=devices)
    with concurrent.futures.ProcessPoolExecutor(jobs) if jobs > 1 else _Serial() as pool:
        rows = []
        for (name, _, _), out in zip(draws, pool.map(run_one, draws), strict=True):
            rows.append(out)
            print(_row(name, out, budget), flush=True)
    done = [r for r in rows if r["completed"]]
    print(f"\ncompleted {len(done)}/{n}; "
          + (f"true normal-force RMS error median {np.median([r['true_normal_force_rms_error'] for r in done]):.3f} N, "  # noqa: E501
             f"worst {max(r['true_normal_force_rms_error'] for r in done):.3f} N; max error "
             f"worst {max(r['true_normal_force_max_error'] for r in done):.3f} N; travel "
             f"{min(r['travel'] for r in done):.2f}-{max(r['travel'] for r in done):.2f} mm"
             if done else ""))
    n_on = sum(bool(r.get("auto_tilt")) for r in rows)
    print(f"automatic tilt on in {n_on}/{n} runs")
    print(f"passed (completed, RMS <= {0.05 if ideal else 0.2} N, max <= 0.5 N, no contact "
          f"lost, travel within 1 mm): {sum(_passes(r, ideal) for r in rows)}/{n}")
    if budget:
        tot = np.sum([error_budget(r) for r in rows], axis=0)
        print(f"squared error over all runs: {tot[0]:.2f} N² in {int(tot[1])} cycles before "
              f"the first slip, {tot[2]:.2f} N² in {int(tot[3])} cycles after")


def _follow_drawn(draw, auto_tilt, devices) -> dict:
    _, cell, travel_dir = draw
    return follow(cell, travel_dir, auto_tilt=auto_tilt, devices=devices)


class _Serial:
    """``map`` in this process (``--jobs 1``), as a context manager like the process pool."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    @staticmethod
    def map(fn, items):
        return map(fn, items)


def _passes(out: dict, ideal: bool) -> bool:
    """Issue 13's acceptance for one run (true figures)."""
    return bool(out["completed"] and out["contact_lost"] == 0
                and abs(out["travel"] - 50.0) <= 1.0
                and out["true_normal_force_rms_error"] <= (0.05 if ideal else 0.2)
                and out["true_normal_force_max_error"] <= 0.5)


def acceptance(friction: float = 0.0, auto_tilt: str = "auto", devices: bool = False,
               sim: str = "kinestat") -> None:
    print(f"acceptance runs (default plane and R = 200 mm cylinder), friction {friction:g}, "
          f"automatic tilt {auto_tilt}, plant {sim}:")
    print(HEAD)
    cyl = CylinderSpec(radius=200.0, axis=np.array([0.0, 0.0, 1.0]))
    for name, cell in (("plane 5°, thesis", SimulatedCell()),
                       ("plane 5°, ideal", SimulatedCell(ideal_sensor=True)),
                       ("cyl R 200, thesis", SimulatedCell(cylinder=cyl)),
                       ("cyl R 200, ideal", SimulatedCell(ideal_sensor=True, cylinder=cyl))):
        cell = dataclasses.replace(cell, friction=friction, plant=sim)
        print(_row(name, follow(cell, Y, auto_tilt=AUTO_TILT[auto_tilt], devices=devices)),
              flush=True)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("n", nargs="?", type=int, default=20)
    ap.add_argument("--acceptance", action="store_true", help="only the acceptance runs")
    ap.add_argument("--friction", type=float, default=0.0)
    ap.add_argument("--ideal", action="store_true")
    ap.add_argument("--auto-tilt", choices=sorted(AUTO_TILT), default="auto",
                    help="the follow task's automatic tilt: auto (default: it switches itself "
                    "on when the tip sticks), on (from the start), off")
    ap.add_argument("--budget", action="store_true",
                    help="also the squared error before the first slip and after, per run")
    ap.add_argument("--seed", type=int, default=13,
                    help="the random workpieces' draw (docs/control.md quotes 13, 29 and 57)")
    ap.add_argument("--devices", action="store_true",
                    help="through the simulated Galil and encoder stream (as the CLI runs it)")
    ap.add_argument("--jobs", type=int, default=1, help="runs in parallel processes")
    ap.add_argument("--sim", choices=("kinestat", "mujoco"), default="kinestat",
                    help="the plant: the built-in simulator or MuJoCo (in process)")
    a = ap.parse_args()
    if a.acceptance:
        acceptance(a.friction, a.auto_tilt, a.devices, a.sim)
    else:
        main(a.n, a.friction, a.ideal, a.auto_tilt, a.seed, a.budget, a.devices, a.jobs, a.sim)
