"""Single-call ``ik_all`` time across separate processes, beside a machine probe.

Run ``.venv/bin/python benchmarks/ik_all_processes.py [--processes 20] [--single 200]
[--arms jaco6,random1] [--taskset CPU] [--roots DIR,DIR] [--json]``.

Each of ``--processes`` fresh Python processes (run one after another) times ``ik_all(model,
T)`` on one pose per call (median over ``--single`` poses, after the batched warm-up call the
benchmark :mod:`benchmarks.ik_all` makes first) and, interleaved call by call, two probes that
do not touch kinestat: LAPACK ``dgeev`` on a fixed 24x24 matrix (the general 6R's dominant
step, throughput-bound) and a latency-bound scalar loop (one dependent multiply-add chain).
Per arm it prints the distribution of the process medians (min / quartiles / max, and how many
exceed 100 µs) and the same for the ratio ``ik_all / dgeev probe``: when the slow processes are
slow in the probe too (ratio unchanged) the machine, not kinestat, made them slow.
``--roots``: checkouts of kinestat to compare (e.g. ``/work/main,.``); their processes
alternate (root 1, root 2, root 1, ...), so both see the same machine.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

_ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def _probes():
    """Compiled probes (``geev(reps)`` µs per call, ``chain(n)``); Numba, not cached to disk."""
    import numba as nb  # lazy: only in the child processes
    from numba import types
    from numba.np.linalg import _LAPACK

    rgeev = _LAPACK().numba_ez_rgeev(types.float64)
    rng = np.random.default_rng(1)
    X = rng.standard_normal((12, 24))
    M0 = np.zeros((24, 24))
    M0[np.arange(12) + 12, np.arange(12)] = 1.0
    M0[:, 12:] = -X.T
    Mc, wr, wi, d = np.zeros((24, 24)), np.zeros(24), np.zeros(24), np.zeros(1)

    @nb.njit
    def geev(M0, Mc, wr, wi, d):
        Mc[:, :] = M0
        return rgeev(ord("d"), ord("N"), ord("N"), 24, Mc.ctypes, 24, wr.ctypes, wi.ctypes,
                     d.ctypes, 1, d.ctypes, 1)

    @nb.njit
    def chain(n):
        x = 1.0
        for _ in range(n):
            x = x * 1.0000001 + 1e-9
        return x

    geev(M0, Mc, wr, wi, d)
    chain(10)
    return (lambda: geev(M0, Mc, wr, wi, d)), (lambda: chain(10_000))


def child(arms: list[str], n_single: int, root: str = _ROOT) -> dict:
    """One process: per arm the median single-call µs of ik_all and of the two probes, with
    the kinestat of checkout ``root``."""
    sys.path.insert(0, os.path.join(root, "tests", "serial", "analytic"))
    sys.path.insert(0, root)
    from arms import arm  # lazy: test arms, only in the child processes

    import kinestat  # lazy: only in the child processes
    from kinestat.serial.analytic import ik_all  # lazy: only in the child processes

    geev, chain = _probes()
    rng = np.random.default_rng(20261201)
    out = {}
    for name in arms:
        model = arm(name)
        T = kinestat.fk(model, rng.uniform(-math.pi, math.pi, (max(n_single, 512), 6)))
        ik_all(model, T[:512])  # the batched call first, as in benchmarks/ik_all.py
        ik_all(model, T[0])
        t_ik, t_geev, t_chain = [], [], []
        for Ti in T[:n_single]:
            t = time.perf_counter()
            geev()
            t_geev.append(time.perf_counter() - t)
            t = time.perf_counter()
            chain()
            t_chain.append(time.perf_counter() - t)
            t = time.perf_counter()
            ik_all(model, Ti)
            t_ik.append(time.perf_counter() - t)
        out[name] = {k: float(np.median(v)) * 1e6 for k, v in
                     (("ik_all", t_ik), ("geev", t_geev), ("chain", t_chain))}
    return out


def _quart(v, spec: str = ".1f") -> str:
    q = np.percentile(v, [0, 25, 50, 75, 100])
    return " / ".join(format(x, spec) for x in q)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--processes", type=int, default=20)
    ap.add_argument("--single", type=int, default=200, help="poses timed per process and arm")
    ap.add_argument("--arms", default="jaco6,random1")
    ap.add_argument("--taskset", default=None, help="pin the processes to this CPU list")
    ap.add_argument("--roots", default=_ROOT, help="comma-separated kinestat checkouts")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    arms = a.arms.split(",")
    roots = [os.path.abspath(r) for r in a.roots.split(",")]
    if a.child:
        print(json.dumps(child(arms, a.single, roots[0])))
        return 0
    by_root: dict[str, list] = {r: [] for r in roots}
    for _ in range(a.processes):
        for r in roots:
            cmd = [sys.executable, os.path.abspath(__file__), "--child", "--arms", a.arms,
                   "--single", str(a.single), "--roots", r]
            if a.taskset:
                cmd = ["taskset", "-c", a.taskset] + cmd
            p = subprocess.run(cmd, capture_output=True, text=True, check=True)
            by_root[r].append(json.loads(p.stdout.strip().splitlines()[-1]))
    if a.json:
        print(json.dumps({"load_avg": os.getloadavg(), "runs": by_root}, indent=1))
        return 0
    for r, runs in by_root.items():
        _report(r, runs, arms, a)
    return 0


def _report(root, runs, arms, a) -> None:
    print(f"# {root}: ik_all single call over {a.processes} processes, {a.single} poses each, "
          f"load {os.getloadavg()}; min / 25% / median / 75% / max of the process medians")
    for name in arms:
        ik = np.array([r[name]["ik_all"] for r in runs])
        ge = np.array([r[name]["geev"] for r in runs])
        ch = np.array([r[name]["chain"] for r in runs])
        print(f"{name:8} ik_all µs      {_quart(ik)}   > 100 µs: {int(np.sum(ik > 100))}"
              f"/{ik.size}")
        print(f"{'':8} dgeev probe µs {_quart(ge)}")
        print(f"{'':8} chain probe µs {_quart(ch)}")
        print(f"{'':8} ik_all / dgeev {_quart(ik / ge, '.3f')}")
        print(f"{'':8} per process    " + " ".join(f"{x:.0f}" for x in ik))


if __name__ == "__main__":
    sys.exit(main())
