"""Throughput and memory of ``kinestat sweep`` studies on Dask (docs/sweeps.md).

Measures the PUMA 762 workspace study (reach, Yoshikawa manipulability, condition number;
summaries only, ``--no-arrays``) on

* one process with no Dask (the kernels alone, the per-core baseline),
* a local cluster with 1 and with 2 worker processes,
* an external ``dask scheduler`` + ``dask worker --nworkers 2`` started here on loopback,

and reports evaluations per second, the peak resident memory of every worker and of the client,
then the cost of one platform design (256 poses) for the scaling estimate, and the Parquet
output rate with rows written.

Run: ``.venv/bin/python benchmarks/sweeps.py [N]`` (default N = 10^7 configurations), or
``benchmarks/sweeps.py --huge 1e8`` for a 10^8-configuration planar workspace study (memory
bounded: the same worker RSS as a small study).
"""

from __future__ import annotations

import logging
import os
import resource
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from kinestat.studies.base import build_study  # noqa: E402
from kinestat.studies.engine import run_study  # noqa: E402
from kinestat.studies.platform_design import platform_design_spec  # noqa: E402
from kinestat.studies.workspace import workspace_spec  # noqa: E402


def _peak_rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _worker_rss(address: str) -> list[float]:
    import distributed

    with distributed.Client(address, set_as_default=False) as c:
        return sorted(c.run(_peak_rss_mib).values())


def _timed(study, out: Path, **kw) -> float:
    t0 = time.perf_counter()
    res = run_study(study, out, progress=False, plots=False, **kw)
    assert res.complete
    return time.perf_counter() - t0


def _local(study, out: Path, workers: int) -> tuple[float, list[float]]:
    import distributed

    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  dashboard_address="127.0.0.1:0", host="127.0.0.1",
                                  silence_logs=logging.ERROR) as cluster:
        # warm the workers (imports, compiled kernels) outside the timing
        warm = build_study("workspace", workspace_spec("puma762", samples=2000, chunk_size=1000))
        _timed(warm, out.with_name(out.name + "-warm"), scheduler=cluster.scheduler_address)
        dt = _timed(study, out, scheduler=cluster.scheduler_address)
        return dt, _worker_rss(cluster.scheduler_address)


def _external(study, out: Path) -> tuple[float, list[float]]:
    dask = str(Path(sys.executable).parent / "dask")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    addr = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], **quiet)]
    try:
        time.sleep(3)
        procs.append(subprocess.Popen([dask, "worker", addr, "--nworkers", "2", "--nthreads",
                                       "1", "--no-dashboard", "--host", "127.0.0.1"], **quiet))
        warm = build_study("workspace", workspace_spec("puma762", samples=2000, chunk_size=1000))
        _timed(warm, out.with_name(out.name + "-warm"), scheduler=addr, timeout_s=60)
        dt = _timed(study, out, scheduler=addr)
        return dt, _worker_rss(addr)
    finally:
        for p in reversed(procs):
            p.terminate()
            p.wait(timeout=30)


PLANAR = """name = "planar2"
notation = "standard_dh"
length_unit = "m"
angle_unit = "deg"
[[joints]]
name = "1"
type = "revolute"
theta = 0.0
d = 0.0
a = 1.0
alpha = 0.0
limits = [-180.0, 180.0]
[[joints]]
name = "2"
type = "revolute"
theta = 0.0
d = 0.0
a = 0.5
alpha = 0.0
limits = [-180.0, 180.0]
"""


def huge(n: int) -> int:
    """Bounded memory at scale: n planar 2-link configurations (2 worker processes)."""
    tmp = Path(tempfile.mkdtemp(prefix="kinestat-bench-"))
    model = tmp / "planar2.toml"
    model.write_text(PLANAR)
    spec = workspace_spec(str(model), samples=n, seed=1, chunk_size=1 << 20, arrays=False)
    study = build_study("workspace", spec)
    dt, rss = _local(study, tmp / "huge", 2)
    res = run_study(study, tmp / "huge", progress=False, plots=False)  # complete: reduce only
    print(f"planar 2-link workspace, {n:,} configurations, {study.n_chunks} chunks of 2^20, "
          f"2 local worker processes: {dt:.0f} s ({n / dt / 1e6:.2f} M/s); points "
          f"{res.summary['points']:,}, reach {res.summary['reach_min']:.6f} .. "
          f"{res.summary['reach_max']:.6f}; workers peak RSS "
          f"{', '.join(f'{x:.0f}' for x in rss)} MiB; client peak RSS {_peak_rss_mib():.0f} MiB; "
          f"load average {os.getloadavg()[0]:.1f}")
    return 0


def main(argv: list[str]) -> int:
    if len(argv) > 2 and argv[1] == "--huge":
        return huge(int(float(argv[2])))
    n = int(float(argv[1])) if len(argv) > 1 else 10**7
    tmp = Path(tempfile.mkdtemp(prefix="kinestat-bench-"))
    spec = workspace_spec("puma762", samples=n, seed=1, arrays=False)
    study = build_study("workspace", spec)
    print(f"workspace study, PUMA 762, {n:,} random configurations, {study.n_chunks} chunks of "
          f"{spec['chunk_size']:,}; {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.1f} at the start")
    # the kernels alone, one process, a tenth of the chunks
    k = max(1, study.n_chunks // 10)
    study.compute_chunk(0)
    t0 = time.perf_counter()
    for i in range(k):
        study.compute_chunk(i)
    dt = time.perf_counter() - t0
    base = min(n, k * spec["chunk_size"]) / dt
    print(f"| no Dask, 1 process ({k} chunks) | {base / 1e3:,.0f} k/s | — |")
    for workers in (1, 2):
        dt, rss = _local(study, tmp / f"local{workers}", workers)
        print(f"| local cluster, {workers} worker process(es) | {n / dt / 1e3:,.0f} k/s "
              f"({dt:.1f} s) | workers peak RSS {', '.join(f'{x:.0f}' for x in rss)} MiB |")
    dt, rss = _external(study, tmp / "external")
    print(f"| external scheduler + 2 workers (loopback) | {n / dt / 1e3:,.0f} k/s ({dt:.1f} s) | "
          f"workers peak RSS {', '.join(f'{x:.0f}' for x in rss)} MiB |")
    print(f"client peak RSS {_peak_rss_mib():.0f} MiB; load average {os.getloadavg()[0]:.1f}")
    # one design: 256 random poses + 48 axis poses + build and checks
    dspec = platform_design_spec(values={"height": "40:80:40", "top_offset": "8:20:5"},
                                 poses=256, chunk_size=50)
    dstudy = build_study("platform-design", dspec)
    dstudy.compute_chunk(0)
    t0 = time.perf_counter()
    for i in range(dstudy.n_chunks):
        dstudy.compute_chunk(i)
    dt = time.perf_counter() - t0
    per = dt / dstudy.n_items
    print(f"platform design: {dstudy.n_items} designs in {dt:.2f} s = {per * 1e3:.2f} ms per "
          f"design of 256 + 48 poses = {304 / per / 1e3:.0f} k pose evaluations/s per core")
    # rows written as Parquet
    m = min(n, 10**6)
    aspec = workspace_spec("puma762", samples=m, seed=2, arrays=True)
    astudy = build_study("workspace", aspec)
    t0 = time.perf_counter()
    run_study(astudy, tmp / "arrays", workers=2, progress=False, plots=False)
    dt = time.perf_counter() - t0
    size = sum(f.stat().st_size for f in (tmp / "arrays" / "rows").iterdir())
    print(f"with rows: {m:,} configurations in {dt:.1f} s ({m / dt / 1e3:,.0f} k/s incl. "
          f"cluster start), Parquet {size / 2**20:.0f} MiB ({size / m:.0f} B/row)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
