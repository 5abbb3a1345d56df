"""Fuzz campaign over every kinestat reader: N mutated inputs per reader within a time budget.

Usage::

    .venv/bin/python benchmarks/fuzz_campaign.py --inputs 20000 --budget 600 [--seed 1]
        [--readers model_toml,urdf] [--timeout 5] [--save-dir fuzz-failures] [--json]

For each reader of :data:`tests.fuzz.corpus.READERS` a worker process (memory capped with
``RLIMIT_AS``) feeds it mutated seed inputs (:func:`tests.fuzz.corpus.mutate`) until ``--inputs``
inputs or ``--budget`` seconds. Each input runs under ``signal.alarm``: one that has not finished
after ``--timeout`` seconds counts as a hang and is abandoned. Printed per reader: inputs tried,
accepted (parsed without error), rejected with a KinestatError, non-Kinestat exceptions (by type
and place), hangs, and the maximum and mean time per input. The exit status is 1 if any reader
let a non-Kinestat exception escape or hung. ``--save-dir`` keeps each distinct failing input.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import random
import resource
import signal
import sys
import tempfile
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(ROOT))
# KINESTAT_FUZZ_CODE=<dir holding a kinestat/ package>: fuzz that code (e.g. an older checkout,
# to measure a before/after) with this corpus.
if os.environ.get("KINESTAT_FUZZ_CODE"):
    sys.path.insert(0, os.environ["KINESTAT_FUZZ_CODE"])


class _Hang(Exception):
    """Raised by the alarm in a worker when one input takes longer than the timeout."""


def _on_alarm(signum, frame):
    raise _Hang


def _place(exc: BaseException) -> str:
    """``Type at file:line`` of the innermost frame of ``exc`` (groups repeats of one bug)."""
    tb = traceback.extract_tb(exc.__traceback__)
    frame = tb[-1] if tb else None
    where = f"{Path(frame.filename).name}:{frame.lineno}" if frame else "?"
    return f"{type(exc).__name__} at {where}"


def run_reader(name: str, n_inputs: int, budget_s: float, seed: int, timeout_s: float,
               save_dir: str | None, mem_bytes: int) -> dict:
    """Fuzz one reader (in a worker process); returns its figures."""
    import warnings

    from kinestat.errors import KinestatError
    from tests.fuzz.corpus import CLI_READER, READERS, mutate, seeds

    if mem_bytes:
        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))
    warnings.simplefilter("ignore")  # numeric warnings are not failures here
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 1000))
    signal.signal(signal.SIGALRM, _on_alarm)
    reader = CLI_READER if name == "cli" else READERS[name]
    rng = random.Random(f"{seed}:{name}")
    work = Path(tempfile.mkdtemp(prefix=f"kinestat-fuzz-{name}-"))
    pool = seeds(name)
    out = {"reader": name, "inputs": 0, "accepted": 0, "rejected": 0, "escaped": 0, "hangs": 0,
           "max_s": 0.0, "total_s": 0.0, "escapes": {}, "examples": {}}
    start = time.perf_counter()
    while out["inputs"] < n_inputs and time.perf_counter() - start < budget_s:
        text = mutate(rng, rng.choice(pool))
        t0 = time.perf_counter()
        signal.setitimer(signal.ITIMER_REAL, timeout_s)
        try:
            try:
                reader.call(text, work)
                out["accepted"] += 1
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
        except _Hang:
            out["hangs"] += 1
            key = "hang"
        except KinestatError:
            out["rejected"] += 1
            key = None
        except Exception as exc:  # noqa: BLE001 - what this campaign counts
            out["escaped"] += 1
            key = _place(exc)
            out["escapes"][key] = out["escapes"].get(key, 0) + 1
            out["examples"].setdefault(key, str(exc)[:200])
        else:
            key = None
        dt = time.perf_counter() - t0
        out["inputs"] += 1
        out["total_s"] += dt
        out["max_s"] = max(out["max_s"], dt)
        if key is not None and save_dir:
            d = Path(save_dir) / name
            d.mkdir(parents=True, exist_ok=True)
            safe = "".join(c if c.isalnum() else "_" for c in key)[:80]
            target = d / f"{safe}.in"
            if not target.exists():
                from tests.fuzz.corpus import to_bytes

                target.write_bytes(to_bytes(text))
    out["elapsed_s"] = time.perf_counter() - start
    return out


def _row(r: dict) -> str:
    mean_ms = 1e3 * r["total_s"] / max(r["inputs"], 1)
    return (f"{r['reader']:<14} {r['inputs']:>8} {r['accepted']:>8} {r['rejected']:>8} "
            f"{r['escaped']:>8} {r['hangs']:>6} {r['max_s']:>9.3f} {mean_ms:>8.2f}")


def main(argv: list[str] | None = None) -> int:
    from tests.fuzz.corpus import READERS

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--inputs", type=int, default=20_000, help="inputs per reader")
    ap.add_argument("--budget", type=float, default=600.0, help="seconds per reader")
    ap.add_argument("--timeout", type=float, default=5.0, help="seconds per input (a hang)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--readers", default=",".join(READERS),
                    help="comma-separated; 'cli' fuzzes command lines (in-process)")
    ap.add_argument("--save-dir", default=None, help="keep one input per distinct failure")
    ap.add_argument("--memory-mb", type=int, default=2048, help="address-space cap per worker")
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = ap.parse_args(argv)
    names = [n for n in args.readers.split(",") if n]
    unknown = set(names) - set(READERS) - {"cli"}
    if unknown:
        ap.error(f"unknown readers {sorted(unknown)}; known: {', '.join(READERS)}")
    results = []
    ctx = mp.get_context("spawn")
    header = (f"{'reader':<14} {'inputs':>8} {'accepted':>8} {'rejected':>8} {'escaped':>8} "
              f"{'hangs':>6} {'max s':>9} {'mean ms':>8}")
    if not args.json:
        print(f"kinestat fuzz campaign: seed {args.seed}, up to {args.inputs} inputs or "
              f"{args.budget:g} s per reader, {args.timeout:g} s per input (pid {os.getpid()})")
        print(header)
    for name in names:
        with ctx.Pool(1) as pool:
            job = pool.apply_async(run_reader, (name, args.inputs, args.budget, args.seed,
                                                args.timeout, args.save_dir,
                                                args.memory_mb * 2**20))
            try:
                r = job.get(timeout=args.budget + 10 * args.timeout + 60)
            except mp.TimeoutError:
                r = {"reader": name, "inputs": 0, "accepted": 0, "rejected": 0, "escaped": 0,
                     "hangs": 1, "max_s": float("inf"), "total_s": 0.0,
                     "escapes": {"worker stuck (an input ignored the alarm)": 1},
                     "examples": {}}
        results.append(r)
        if not args.json:
            print(_row(r), flush=True)
            for key, count in sorted(r["escapes"].items(), key=lambda kv: -kv[1]):
                print(f"    {count:>6} x {key}: {r['examples'].get(key, '')}")
    total = {k: sum(r[k] for r in results) for k in ("inputs", "escaped", "hangs")}
    if args.json:
        print(json.dumps({"seed": args.seed, "results": results, "total": total}, indent=1))
    else:
        print(f"total: {total['inputs']} inputs, {total['escaped']} non-Kinestat exceptions, "
              f"{total['hangs']} hangs")
    return 1 if total["escaped"] or total["hangs"] else 0


if __name__ == "__main__":
    sys.exit(main())
