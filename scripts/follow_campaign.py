"""The follow task beyond the study's range: random force, travel, directions and friction.

``scripts/follow_study.py`` varies the workpiece only (4 N, 50 mm, travel near +y, cylinder
axes near z). This campaign also draws, per run: |F_req| uniform in [2, ``--max-force``] N,
the travel uniform in 20-80 mm, the initial travel direction in any azimuth about F_req (up
to ±0.3 of it along F_req), friction from ``--friction`` (default 0, 0.3 and 0.5), the ideal
sensor in 30 % of the runs; even runs a plane (1.5-4 mm ahead, tilted 0-``--max-tilt`` degrees
(default 10) in any azimuth),
odd runs a cylinder of radius uniform in [``--min-radius``, 500] mm whose axis lies in any
azimuth across F_req (up to ±0.2 of it along F_req). Each run is judged by the
acceptance (completed, no contact lost, travel within 1 mm of the request, measured and true
(:func:`true_travel`), true normal-force RMS ≤ 0.2 N and max ≤ 0.5 N, issue 40's bounds; the
campaign also counts the ideal sensor's runs against 0.05 N RMS); requests the controller
refuses before any motion (a force the platform cannot carry) are counted apart. In process;
``--devices`` runs through the simulated Galil and encoder stream as the CLI does;
``--sim mujoco`` on the MuJoCo cell (in process; true figures from MuJoCo's contact force).
With ``--wood LO HI`` each run is, with even odds, rigid or compliant with a workpiece stiffness
log-uniform in LO-HI N/mm (a second stream, so the workpieces stay those of the seed).

    .venv/bin/python scripts/follow_campaign.py [N] [--seed S] [--max-force F]
        [--min-radius R] [--friction MU ...] [--devices] [--jobs J] [--sim kinestat|mujoco]
        [--max-tilt DEG] [--wood LO HI]
"""

from __future__ import annotations

import argparse
import concurrent.futures
import dataclasses
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from follow_study import START, follow, wood_stiffnesses  # noqa: E402

from kinestat.app.control_run import (  # noqa: E402
    DEFAULT_PLANE_DISTANCE,
    CylinderSpec,
    SimulatedCell,
)
from kinestat.control.controller import THESIS_FORCE_DIRECTION  # noqa: E402
from kinestat.errors import InputError  # noqa: E402
from kinestat.sim.surface import cylinder_ahead  # noqa: E402

F_HAT = np.asarray(THESIS_FORCE_DIRECTION, dtype=float)
_U = np.cross(F_HAT, [0.0, 1.0, 0.0])
_U /= np.linalg.norm(_U)
_V = np.cross(F_HAT, _U)


def draw(rng: np.random.Generator, k: int, max_force: float, min_radius: float,
         frictions: tuple[float, ...], max_tilt: float = 10.0) -> dict:
    """Run ``k``'s request (module docstring)."""
    force = float(rng.uniform(2.0, max_force))
    travel = float(rng.uniform(20.0, 80.0))
    mu = float(rng.choice(frictions))
    az = rng.uniform(0.0, 2.0 * math.pi)
    travel_dir = math.cos(az) * _U + math.sin(az) * _V + rng.uniform(-0.3, 0.3) * F_HAT
    ideal = bool(rng.random() < 0.3)
    if k % 2 == 0:
        tilt, paz = math.radians(rng.uniform(0.0, max_tilt)), rng.uniform(0.0, 2.0 * math.pi)
        n = -(math.cos(tilt) * F_HAT + math.sin(tilt) * (math.cos(paz) * _U + math.sin(paz) * _V))
        name = f"plane {math.degrees(tilt):.1f}°"
        cell = SimulatedCell(plane_point=START + rng.uniform(1.5, 4.0) * F_HAT, plane_normal=n)
    else:
        r = rng.uniform(min_radius, 500.0)
        aaz = rng.uniform(0.0, math.pi)
        axis = math.cos(aaz) * _U + math.sin(aaz) * _V + rng.uniform(-0.2, 0.2) * F_HAT
        across = [_unit(v - (v @ F_HAT) * F_HAT) for v in (travel_dir, axis)]
        off_axis = math.degrees(math.acos(min(1.0, abs(float(across[0] @ across[1])))))
        name = f"cyl R {r:.0f}, {off_axis:.0f}° off axis"
        cell = SimulatedCell(cylinder=CylinderSpec(radius=r, axis=axis))
    cell = dataclasses.replace(cell, friction=mu, ideal_sensor=ideal)
    return {"name": name, "cell": cell, "force": force, "travel": travel,
            "travel_dir": travel_dir, "mu": mu, "ideal": ideal}


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def run_one(args: tuple[dict, bool]) -> dict:
    d, devices = args
    try:
        return follow(d["cell"], d["travel_dir"], travel=d["travel"], devices=devices,
                      force=d["force"])
    except InputError as exc:  # refused before any motion
        return {"refused": str(exc)}


def true_travel(d: dict, out: dict) -> float:
    """The true tip's distance on the surface from the first travel cycle to the last (the
    simulator's tips): a straight line on a plane; on a cylinder, the unrolled arc about the
    axis and the axial part (the geodesic's length: a path that bends on the surface went
    further, so this is a lower bound of its length)."""
    tips = [np.asarray(c["true_tip"]) for c in out["cycles"]
            if c.get("phase") == "travel" and c.get("true_tip") is not None]
    a, b = tips[0], tips[-1]
    cyl = d["cell"].cylinder
    if cyl is None:
        return float(np.linalg.norm(b - a))
    wp = cylinder_ahead(START, F_HAT, DEFAULT_PLANE_DISTANCE, cyl.radius, cyl.axis)
    ra, rb = wp._radial(a), wp._radial(b)
    ang = math.atan2(float(np.linalg.norm(np.cross(ra, rb))), float(ra @ rb))
    return math.hypot(wp.radius * ang, float((b - a) @ wp.axis))


def verdict(d: dict, out: dict) -> str:
    """Issue 40's bounds (completed, contact kept, travel within 1 mm measured and true, true
    normal-force RMS ≤ 0.2 N and max ≤ 0.5 N): "pass" or "FAIL"; "pass*" marks a pass above
    the campaign's own, stricter RMS bound for the ideal sensor (0.05 N)."""
    if "refused" in out:
        return "refused"
    out["true_travel"] = true_travel(d, out) if out["completed"] else float("nan")
    ok = (out["completed"] and out["contact_lost"] == 0
          and abs(out["travel"] - d["travel"]) <= 1.0
          and abs(out["true_travel"] - d["travel"]) <= 1.0
          and out["true_normal_force_rms_error"] <= 0.2
          and out["true_normal_force_max_error"] <= 0.5)
    if not ok:
        return "FAIL"
    return "pass*" if d["ideal"] and out["true_normal_force_rms_error"] > 0.05 else "pass"


def _row(k: int, d: dict, out: dict, v: str) -> str:
    head = (f"| {k:3d} | {d['name']:26s} | {d['force']:4.1f} | {d['travel']:4.0f} | "
            f"{d['mu']:.1f} | {'ideal' if d['ideal'] else 'thesis':6s} | {v:7s} |")
    if "refused" in out:
        return head + f" | | | {out['refused'][:90]} |"

    def f(key):
        x = out.get(key)
        return "-" if x is None else f"{x:.3f}"
    return head + (f" {out['travel']:6.2f} ({out['true_travel']:6.2f}) | "
                   f"{f('true_normal_force_rms_error')} | "
                   f"{f('true_normal_force_max_error')} | {out['stop_reason'][:90]} |")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", nargs="?", type=int, default=30)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-force", type=float, default=6.0)
    ap.add_argument("--min-radius", type=float, default=150.0)
    ap.add_argument("--friction", type=float, nargs="+", default=[0.0, 0.3, 0.5])
    ap.add_argument("--devices", action="store_true")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--sim", choices=("kinestat", "mujoco"), default="kinestat")
    ap.add_argument("--max-tilt", type=float, default=10.0, help="planes' largest tilt, degrees")
    ap.add_argument("--wood", type=float, nargs=2, metavar=("LO", "HI"),
                    help="half the runs on a compliant workpiece, stiffness N/mm log-uniform")
    a = ap.parse_args(argv)
    rng = np.random.default_rng(a.seed)
    draws = [draw(rng, k, a.max_force, a.min_radius, tuple(a.friction), a.max_tilt)
             for k in range(a.n)]
    for d, k_wood in zip(draws, wood_stiffnesses(a.seed, a.n, a.wood), strict=True):
        if k_wood is not None:
            d["name"] = f"{d['name'][:18]} k{k_wood:.0f}"
        d["cell"] = dataclasses.replace(d["cell"], plant=a.sim, workpiece_stiffness=k_wood)
    print(f"seed {a.seed}, |F_req| 2-{a.max_force:g} N, planes <= {a.max_tilt:g}°, "
          f"cylinders R >= {a.min_radius:g} mm, wood {a.wood or 'no'}, "
          f"friction {a.friction}, plant {a.sim}, "
          + ("through the devices" if a.devices else "in process"))
    print("| run | workpiece | F N | travel mm | μ | sensor | verdict | travelled (true) | "
          "RMS N | max N | stop |")
    counts: dict[str, int] = {}
    with concurrent.futures.ProcessPoolExecutor(a.jobs) as pool:
        for k, (d, out) in enumerate(zip(draws, pool.map(run_one, [(d, a.devices) for d in draws]),
                                         strict=True)):
            v = verdict(d, out)
            counts[v] = counts.get(v, 0) + 1
            print(_row(k, d, out, v), flush=True)
    print(", ".join(f"{v} {c}" for v, c in sorted(counts.items())) + f" of {a.n}")
    print(f"issue 40's bounds: {counts.get('pass', 0) + counts.get('pass*', 0)}/{a.n}; "
          f"with the ideal sensor's 0.05 N RMS bound too: {counts.get('pass', 0)}/{a.n}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
