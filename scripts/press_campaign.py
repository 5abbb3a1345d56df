"""The press task (the default `kinestat control`) over random steep and curved workpieces.

Per run: |F_req| uniform in 2-6 N along the thesis's direction, friction 0 or 0.3 (``--friction``),
even runs a plane 1.5-4 mm ahead whose normal is tilted 0-45° from F_req in any azimuth, odd
runs a cylinder of radius uniform in 150-500 mm whose axis makes 45-90° with F_req (so the
surface is met up to 45° off the tool axis), placed as ``--workpiece cylinder`` places it (the
surface 2.5 mm ahead). Through the simulated Galil and encoder stream (as the CLI runs it), or in
process with ``--in-process``; ``--sim mujoco`` runs each on the MuJoCo cell (in process, as
``kinestat control --sim mujoco``: true figures from MuJoCo's contact force). Printed per run:
whether the goal was attained (|F| within ``force_tol`` of the request and the tool axis within
``align_tol_deg`` of the measured force), the cycles, the true force's error and the true
force's angle to the tool axis, the stop reason; then the counts by workpiece kind.
docs/control.md ("The press on curved and steep workpieces") quotes its draws. With
``--wood LO HI`` each run is, with even odds, rigid or compliant with a workpiece stiffness
log-uniform in LO-HI N/mm (drawn from a second stream, so the workpieces stay those of the seed).

    .venv/bin/python scripts/press_campaign.py [N] [--seed S] [--friction MU ...] [--in-process]
        [--jobs J] [--sim kinestat|mujoco] [--wood LO HI]
"""

from __future__ import annotations

import argparse
import concurrent.futures
import dataclasses
import functools
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from follow_study import F_HAT, START, wood_stiffnesses  # noqa: E402

from kinestat.app.control_run import (  # noqa: E402
    ControlRequest,
    CylinderSpec,
    SimulatedCell,
    prepare_control,
    report_dict,
    run_control,
)
from kinestat.app.sim_cell import InProcessIO, start_counts  # noqa: E402
from kinestat.control.log import CycleLog  # noqa: E402
from kinestat.control.loop import run  # noqa: E402

_U = np.cross(F_HAT, [0.0, 1.0, 0.0])
_U /= np.linalg.norm(_U)
_V = np.cross(F_HAT, _U)


def draw(rng: np.random.Generator, k: int, frictions: tuple[float, ...]) -> dict:
    """Run ``k``'s request (module docstring)."""
    force = float(rng.uniform(2.0, 6.0))
    mu = float(rng.choice(frictions))
    az = rng.uniform(0.0, 2.0 * math.pi)
    side = math.cos(az) * _U + math.sin(az) * _V  # a unit vector across F_req
    if k % 2 == 0:
        tilt = math.radians(rng.uniform(0.0, 45.0))
        n = -(math.cos(tilt) * F_HAT + math.sin(tilt) * side)
        name = f"plane {math.degrees(tilt):.1f}°"
        cell = SimulatedCell(plane_point=START + rng.uniform(1.5, 4.0) * F_HAT, plane_normal=n,
                             friction=mu)
    else:
        r = float(rng.uniform(150.0, 500.0))
        angle = math.radians(rng.uniform(45.0, 90.0))  # between the axis and F_req
        axis = math.cos(angle) * F_HAT + math.sin(angle) * side
        name = f"cyl R {r:.0f}, {90.0 - math.degrees(angle):.0f}° off"
        cell = SimulatedCell(cylinder=CylinderSpec(radius=r, axis=axis), friction=mu)
    return {"name": name, "cell": cell, "force": force, "mu": mu,
            "kind": "plane" if k % 2 == 0 else ("cylinder, μ = 0" if mu == 0.0
                                                else f"cylinder, μ = {mu:g}")}


def press(req: dict, devices: bool = True) -> dict:
    """One press run of ``req`` (:func:`draw`): its report (:func:`report_dict`)."""
    prep = prepare_control(ControlRequest(force=req["force"] * F_HAT, start_tool_point=START,
                                          cell=req["cell"], task="press"))
    with tempfile.TemporaryDirectory() as tmp:
        if devices or prep.plant is not None:  # the MuJoCo cell runs as the CLI runs it
            rep = run_control(prep, Path(tmp) / "log.jsonl")
        else:
            io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
            with CycleLog(Path(tmp) / "log.jsonl") as log:
                rep = run(prep.config, io, log)
    return report_dict(prep, rep)


def _row(k: int, req: dict, out: dict) -> str:
    ok = "goal" if out["converged"] else "STOP"
    tf = out.get("true_force_magnitude")
    err = "-" if tf is None else f"{abs(tf - req['force']):.3f}"
    ax = out.get("axis_error_deg")
    ax = "-" if ax is None else f"{ax:.2f}"
    return (f"| {k:3d} | {req['name']:22s} | {req['force']:4.2f} | {req['mu']:3.1f} | {ok} | "
            f"{out['iterations']:3d} | {err:>6s} | {ax:>5s} | {out['stop_reason'][:70]} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", nargs="?", type=int, default=30)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--friction", type=float, nargs="+", default=[0.0, 0.3])
    ap.add_argument("--in-process", action="store_true")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--sim", choices=("kinestat", "mujoco"), default="kinestat")
    ap.add_argument("--wood", type=float, nargs=2, metavar=("LO", "HI"),
                    help="half the runs on a compliant workpiece, stiffness N/mm log-uniform")
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    reqs = [draw(rng, k, tuple(a.friction)) for k in range(a.n)]
    for r, k_wood in zip(reqs, wood_stiffnesses(a.seed, a.n, a.wood), strict=True):
        if k_wood is not None:
            r["name"] = f"{r['name'][:14]} k{k_wood:.0f}"
        r["cell"] = dataclasses.replace(r["cell"], plant=a.sim, workpiece_stiffness=k_wood)
    print(f"seed {a.seed}, {a.n} runs, |F_req| 2-6 N, friction {a.friction}, plant {a.sim}, "
          + ("in process" if a.in_process or a.sim == "mujoco"
             else "through the simulated devices"))
    print("| run | workpiece | F N | μ | verdict | cycles | true |F| error N | axis error ° "
          "| stop |")
    fn = functools.partial(press, devices=not a.in_process)
    with concurrent.futures.ProcessPoolExecutor(max_workers=a.jobs) as ex:
        outs = list(ex.map(fn, reqs))
    tally: dict[str, list[int]] = {}
    for k, (req, out) in enumerate(zip(reqs, outs, strict=True)):
        print(_row(k, req, out), flush=True)
        t = tally.setdefault(req["kind"], [0, 0])
        t[0] += bool(out["converged"])
        t[1] += 1
    print("attain the goal: " + ", ".join(f"{kind} {g}/{n}" for kind, (g, n) in tally.items())
          + f"; all {sum(g for g, _ in tally.values())}/{a.n}")


if __name__ == "__main__":
    main()
