"""Bounded memory for 10^7 configurations: stream FK, PUMA closed-form IK and numerical IK in
chunks and report the peak resident memory above the input array.

Run: ``.venv/bin/python benchmarks/memory.py [N]`` (default N = 10^7 for FK, N/100 for IK).
"""

from __future__ import annotations

import resource
import sys
import time

import numpy as np

import kinestat
from kinestat.robots.puma762 import closed_form as puma762
from kinestat.serial.fk import iter_fk


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main(argv: list[str]) -> int:
    N = int(float(argv[1])) if len(argv) > 1 else 10**7
    m = kinestat.load("puma560")
    rng = np.random.default_rng(1)
    kinestat.fk(m, np.zeros((2, 6)))  # compile / load the kernels first
    base = peak_mb()
    q = rng.uniform(-np.pi, np.pi, (N, 6))
    with_input = peak_mb()
    t0 = time.perf_counter()
    zmax = -np.inf
    for _, T in iter_fk(m, q):
        zmax = max(zmax, float(T[:, 2, 3].max()))
    dt = time.perf_counter() - t0
    after = peak_mb()
    print(f"FK over {N:,} configurations in chunks: {dt:.2f} s ({N / dt / 1e6:.2f} M/s); "
          f"input {q.nbytes / 2**20:.0f} MiB; peak RSS {base:.0f} -> {with_input:.0f} (input) "
          f"-> {after:.0f} MiB (+{after - with_input:.0f} MiB for the run; the full (N, 4, 4) "
          f"output would be {N * 128 / 2**20:.0f} MiB); highest z {zmax:.3f} m")
    del q
    n_ik = max(N // 100, 1000)
    m762 = kinestat.load("puma762")
    lim = np.radians(puma762.AXIS_LIMITS_DEG)
    qa = puma762.from_axis_angles(lim[:, 0] + rng.random((n_ik, 6)) * (lim[:, 1] - lim[:, 0]))
    poses = kinestat.fk(m762, qa)
    before = peak_mb()
    t0 = time.perf_counter()
    ok = 0
    for _, b in puma762.iter_reverse_batch_pose(poses):
        ok += int(b.valid.any(axis=-1).sum())
    dt = time.perf_counter() - t0
    print(f"PUMA 762 closed form over {n_ik:,} poses in chunks: {dt:.2f} s; {ok:,} solved; "
          f"peak RSS +{peak_mb() - before:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
