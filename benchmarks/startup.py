"""Start-up time of kinestat, side by side (issue 16): what a user waits for before any work.

`kinestat --help` and `--version` import no command module (kinestat/cli/_lazy.py); a
command's own help imports that command's module, and with it NumPy. `kinestat fk` runs NumPy
only (no compiled kernel), so its cold row differs from the warm one only by noise;
`kinestat ik` with --tool-point runs the PUMA 762's compiled closed form. Each row is a fresh
Python process (median of ``--repeat`` runs, the rows taking turns; a cold-cache row runs half
as often, each time with an empty ``NUMBA_CACHE_DIR``, so every kernel it uses compiles):

    python benchmarks/startup.py            # a table
    python benchmarks/startup.py --json     # the same as JSON

Goal (issue 16): ``import kinestat`` and ``kinestat --help`` at most ~2x ``import numpy``.
Goal (issue 44): one FK from the CLI on a URDF (``kinestat fk ur5_robot.urdf ... --json``) at
most 2x a Pinocchio script that loads the same URDF and prints the same pose (both rows in the
same run, the ``x pinocchio`` column); the first ``ik_all`` call of a fresh process (after
``import kinestat``, loading the model and one ``fk``) at most 20 ms: measured inside fresh
processes (the ``first call`` rows, median of ``--repeat``), beside the first call of EAIK's
``IK`` and ik-geo's ``get_ik`` on the URDF arms (after importing them and building the robot),
the processes taking turns; ``--first-only`` runs just these rows.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CLI = "import sys; from kinestat.cli.main import main; sys.exit(main(sys.argv[1:]))"
FK = ["fk", "puma762", "--q-deg", "0,0,0,0,0,0"]
IK = ["ik", "puma762", "--tool-point", "725,190,650", "--s6", "1,0,0", "--a67", "0,0,1"]



def _robots() -> Path | None:
    from importlib.metadata import PackageNotFoundError, distribution

    try:
        return Path(str(distribution("example-robot-data").locate_file(
            "cmeel.prefix/share/example-robot-data/robots")))
    except PackageNotFoundError:
        return None


_ERD = _robots()
UR5 = str(_ERD / "ur_description/urdf/ur5_robot.urdf") if _ERD else ""
Q_UR5 = "0.1,0.2,0.3,0.4,0.5,0.6"
FK_URDF = ["fk", UR5, "--tip", "tool0", "--q", Q_UR5, "--json"]
PINOCCHIO = (f"import sys, numpy as np, pinocchio as pin; m = pin.buildModelFromUrdf({UR5!r}); "
             f"d = m.createData(); pin.framesForwardKinematics(m, d, np.array([{Q_UR5}])); "
             "print(d.oMf[m.getFrameId('tool0')].homogeneous.tolist())")
#: the first ik_all call of a fresh process, timed inside it: wall and CPU ms on stdout (the
#: process's CPU time is the figure a loaded machine leaves meaningful)
FIRST_CALL = ("import time, numpy as np, kinestat; m = kinestat.load({model!r}{tip}); "
              "T = kinestat.fk(m, np.full(m.n, 0.3)); t = time.perf_counter(); "
              "c = time.process_time(); kinestat.ik_all(m, T); "
              "print(1e3 * (time.perf_counter() - t), 1e3 * (time.process_time() - c))")
KR16 = "kuka_description/kuka_kr16/urdf/kr16_2.urdf"
FIRST_MODELS = {"puma560 (pieper)": ("puma560", None), "UR5 URDF (three-parallel)": (UR5, "tool0"),
                "KR16 URDF (pieper, offset shoulder)": (KR16, None)}

#: (label, python arguments, cold kernel cache?)
ROWS: list[tuple[str, list[str], bool]] = [
    ('python -c "import numpy"', ["-c", "import numpy"], False),
    ('python -c "import kinestat"', ["-c", "import kinestat"], False),
    ("kinestat --help", ["-c", CLI, "--help"], False),
    ("kinestat --version", ["-c", CLI, "--version"], False),
    ("kinestat fk --help (a command's help)", ["-c", CLI, "fk", "--help"], False),
    ("kinestat fk puma762 --q-deg 0,0,0,0,0,0 (warm kernel cache)", ["-c", CLI, *FK], False),
    ("kinestat fk puma762 --q-deg 0,0,0,0,0,0 (cold kernel cache)", ["-c", CLI, *FK], True),
    ("kinestat ik puma762 --tool-point ... (closed form; warm)", ["-c", CLI, *IK], False),
    ("kinestat ik puma762 --tool-point ... (closed form; cold)", ["-c", CLI, *IK], True),
]
if UR5:
    ROWS += [("pinocchio script: ur5_robot.urdf, FK at q, print the pose", ["-c", PINOCCHIO],
              False),
             ("kinestat fk ur5_robot.urdf --tip tool0 --q ... --json", ["-c", CLI, *FK_URDF],
              False)]


def _once(args: list[str], cold: bool, output: bool = False):
    env = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="100")
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # as a user's shell: bytecode cached
    with tempfile.TemporaryDirectory(prefix="kinestat-numba-") as cache:
        if cold:
            env["NUMBA_CACHE_DIR"] = cache
        t0 = time.perf_counter()
        run = subprocess.run([sys.executable, *args], env=env, capture_output=True, text=True,
                             timeout=600)
        took = time.perf_counter() - t0
    if run.returncode != 0:
        raise SystemExit(f"{args} failed ({run.returncode}): {run.stderr[-500:]}")
    return [float(v) for v in run.stdout.split()[-2:]] if output else took


#: a peer's first IK call of a fresh process, after importing it and building the robot from
#: the model's home axes (as benchmarks/ik_all.py calls it); wall and CPU ms on stdout
PEER_FIRST = {
    "EAIK IK": ("import time, numpy as np; from eaik.IK_HP import HPRobot; "
                "bot = HPRobot(np.array({H}), np.array({P})); T = np.array({T}); "
                "t = time.perf_counter(); c = time.process_time(); bot.IK(T); "
                "print(1e3 * (time.perf_counter() - t), 1e3 * (time.process_time() - c))"),
    "ik-geo get_ik": ("import time; from ik_geo import Robot; bot = Robot.{ctor}({H}, {P}); "
                      "R, p = {R}, {p}; t = time.perf_counter(); c = time.process_time(); "
                      "bot.get_ik(R, p); print(1e3 * (time.perf_counter() - t), "
                      "1e3 * (time.process_time() - c))"),
}


def _peer_codes(model: str, tip: str | None) -> dict[str, str]:
    """The peers' first-call scripts for the model at the pose FIRST_CALL solves (ik-geo's
    constructor for the model's class, as benchmarks/ik_all.py picks it)."""
    import numpy as np

    import kinestat
    from kinestat.serial.analytic import method_for
    from kinestat.serial.analytic.geometry import home_axes, meet, parallel

    m = kinestat.load(model, tip=tip) if tip else kinestat.load(model)
    T = kinestat.fk(m, np.full(m.n, 0.3))
    ax = home_axes(m)
    pts = np.vstack([ax.r, ax.T0[:3, 3]])
    H, P = ax.w.tolist(), np.vstack([pts[0], np.diff(pts, axis=0)]).tolist()
    Rr = T[:3, :3] @ ax.T0[:3, :3].T
    Tp = T.copy()
    Tp[:3, :3] = Rr
    kind = method_for(m)
    if kind == "pieper" and meet(ax, 0, 1) is None:
        kind = "pieper-parallel" if parallel(ax, 1, 2) else "pieper-offset"
    ctor = {"three-parallel": "three_parallel_two_intersecting",
            "pieper": "spherical_two_intersecting", "pieper-parallel": "spherical_two_parallel",
            "pieper-offset": "spherical"}.get(kind, "gen_six_dof")
    fill = {"H": H, "P": P, "T": Tp.tolist(), "ctor": ctor, "R": Rr.T.tolist(),
            "p": T[:3, 3].tolist()}
    return {k: v.format(**fill) for k, v in PEER_FIRST.items()}


def _model_path(model: str) -> str | None:
    if model == KR16:
        try:
            import rtbdata
        except ImportError:
            return None
        return str(Path(rtbdata.__file__).parent / "xacro" / KR16)
    return model or None


def first_calls(repeat: int) -> list[dict]:
    """The first IK call's time (ms) inside fresh processes, per model, kinestat's ``ik_all``
    and each peer's, the processes taking turns: median and range."""
    out = []
    for label, (model, tip) in FIRST_MODELS.items():
        model = _model_path(model)
        if model is None:
            continue
        codes = {"kinestat ik_all": FIRST_CALL.format(
            model=model, tip="" if tip is None else f", tip={tip!r}")}
        if model.endswith(".urdf"):  # peers from the URDF's home axes
            codes |= _peer_codes(model, tip)
        for code in codes.values():
            _once(["-c", code], False, True)  # compile once, untimed
        runs: dict[str, list] = {k: [] for k in codes}
        for _ in range(repeat):
            for k, code in codes.items():
                try:
                    runs[k].append(_once(["-c", code], False, True))
                except SystemExit:  # a peer not installed
                    pass
        for k, rr in runs.items():
            if not rr:
                continue
            wall, cpu = [r[0] for r in rr], [r[1] for r in rr]
            out.append({"model": label, "solver": k, "median_ms": statistics.median(wall),
                        "min_ms": min(wall), "max_ms": max(wall),
                        "cpu_median_ms": statistics.median(cpu), "cpu_min_ms": min(cpu),
                        "cpu_max_ms": max(cpu), "runs": len(rr)})
    return out


def measure(repeat: int = 5) -> list[dict]:
    """Median wall time (s) of each row over ``repeat`` fresh processes, and its ratio to
    ``import numpy``. The rows take turns (round ``k`` runs every row once), so a change in the
    machine's load during the run reaches every row alike and the ratios stay fair."""
    for _, args, _cold in ROWS:  # the warm rows need a warm cache: compile once, untimed
        _once(args, False)
    times: list[list[float]] = [[] for _ in ROWS]
    for k in range(repeat):
        for i, (_, args, cold) in enumerate(ROWS):
            if not cold or k < max(1, repeat // 2):
                times[i].append(_once(args, cold))
    rows = [{"command": label, "median_s": statistics.median(t), "min_s": min(t), "runs": len(t)}
            for (label, _, _), t in zip(ROWS, times, strict=True)]
    base = rows[0]["median_s"]
    pin = next((r["median_s"] for r in rows if r["command"].startswith("pinocchio")), None)
    for r in rows:
        r["ratio_to_numpy"] = r["median_s"] / base
        r["ratio_to_pinocchio"] = None if pin is None else r["median_s"] / pin
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="processes per row (default 5)")
    ap.add_argument("--json", action="store_true", help="print JSON")
    ap.add_argument("--first-only", action="store_true",
                    help="only the first-IK-call rows (kinestat and peers)")
    a = ap.parse_args(argv)
    rows = [] if a.first_only else measure(a.repeat)
    first = first_calls(a.repeat)
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    load = os.getloadavg()
    if a.json:
        print(json.dumps({"date": stamp, "python": sys.version.split()[0], "load_avg": load,
                          "rows": rows, "first_ik_all": first}, indent=2))
        return 0
    width = max([len(r["command"]) for r in rows] + [7])
    print(f"start-up, {stamp}, Python {sys.version.split()[0]}, median of fresh processes, "
          f"load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")
    print(f"{'command':<{width}}  {'median s':>9}  {'min s':>7}  {'x numpy':>8}  "
          f"{'x pinocchio':>11}")
    for r in rows:
        xp = "" if r["ratio_to_pinocchio"] is None else f"{r['ratio_to_pinocchio']:.2f}"
        print(f"{r['command']:<{width}}  {r['median_s']:>9.3f}  {r['min_s']:>7.3f}  "
              f"{r['ratio_to_numpy']:>8.2f}  {xp:>11}")
    for f in first:
        print(f"first call, {f['solver']}, {f['model']}: median {f['median_ms']:.1f} ms "
              f"(range {f['min_ms']:.1f}-{f['max_ms']:.1f}), CPU {f['cpu_median_ms']:.1f} ms "
              f"({f['cpu_min_ms']:.1f}-{f['cpu_max_ms']:.1f}), {f['runs']} processes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
