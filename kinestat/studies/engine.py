"""Run a study's chunks on Dask (dask.distributed) and reduce them; resume from partial output.

The only module of :mod:`kinestat.studies` that knows about Dask. By default it starts an
embedded :class:`distributed.LocalCluster` sized to the machine (one single-threaded worker
process per core: the kernels hold the GIL part of the time, and processes keep a crashing
chunk from taking the client down); ``scheduler="tcp://HOST:PORT"`` runs the same tasks on an
existing cluster. Workers only compute: each task rebuilds the study from its spec (model and
platform files travel as text) and returns the chunk's rows and partial summary; the client
writes them (:mod:`kinestat.studies.store`), so workers need no shared file system. At most
two tasks per worker thread are in flight, which bounds the client's memory.
"""

from __future__ import annotations

import logging
import math
import os
import socket
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from kinestat.errors import ClusterError, InputError, KinestatError
from kinestat.studies.base import Study, build_study, spec_hash, spec_json
from kinestat.studies.store import StudyStore

__all__ = ["ClusterError", "RunResult", "StudyInterrupted", "run_study", "default_output",
           "compute_chunk_task"]


class StudyInterrupted(KeyboardInterrupt):
    """Ctrl-C (or a signal raising KeyboardInterrupt) during a study: ``message`` says how far
    it got and how to resume (the chunks written so far are kept)."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message

#: where studies go when no --output is given
RUNS_DIR = "kinestat-runs"


@dataclass
class RunResult:
    """What a run did: the summary (None unless complete) and the chunk bookkeeping."""

    study: str
    output: Path
    complete: bool
    summary: dict | None
    chunks_total: int
    chunks_computed: int
    chunks_reused: int
    elapsed_s: float
    plots: list[str]
    chunks_damaged: int = 0

    def to_json(self) -> dict:
        return {"study": self.study, "complete": self.complete, "summary": self.summary,
                "output": str(self.output),
                "chunks": {"total": self.chunks_total, "computed": self.chunks_computed,
                           "reused": self.chunks_reused, "damaged": self.chunks_damaged},
                "elapsed_s": self.elapsed_s, "plots": self.plots}


def default_output(study: Study) -> Path:
    """``./kinestat-runs/<study>-<first 12 hex of the spec hash>``: the same inputs land in the
    same directory, so rerunning an interrupted command resumes it."""
    return Path(RUNS_DIR) / f"{study.name}-{spec_hash(study.spec)[:12]}"


def compute_chunk_task(name: str, text: str, i: int):
    """The Dask task: chunk ``i`` of study ``name`` with spec ``text`` -> (i, rows, partial)."""
    study = build_study(name, text)
    rows, partial = study.compute_chunk(i)
    return i, rows, partial


def check_address(address: str) -> None:
    """Refuse a scheduler address that is not ``[PROTOCOL://]HOST:PORT``."""
    rest = address.split("://", 1)[-1]
    host, _, port = rest.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError(f"--scheduler {address!r}: expected an address tcp://HOST:PORT")


def probe_scheduler(address: str, timeout_s: float) -> None:
    """Refuse, within ``timeout_s``, a ``tcp://`` address where no Dask scheduler listens.

    A Dask scheduler speaks first: on a new TCP connection it sends its handshake (an 8-byte
    little-endian length, then msgpack frames naming ``compression``, ``python`` and
    ``pickle-protocol``). Nothing within the timeout (an HTTP server, a silent listener) or
    other bytes (a service answering garbage) is a :class:`ClusterError` naming the address;
    ``distributed.Client`` would otherwise wait or fail with a traceback. Other protocols
    (``tls://``...) are left to the client's own timeout.
    """
    proto, _, rest = address.rpartition("://")
    if proto not in ("", "tcp"):
        return
    host, _, port = rest.rpartition(":")
    host = host.strip("[]")
    where = f"--scheduler {address}"
    deadline = time.monotonic() + timeout_s
    try:
        sock = socket.create_connection((host, int(port)), timeout=timeout_s)
    except OSError as exc:
        raise ClusterError(f"{where}: cannot connect within {timeout_s:g} s ({exc}); check the "
                           "address and that the scheduler runs") from None
    data = b""
    with sock:
        while len(data) < 8 or len(data) < 8 + _frame_length(data) <= 8 + 4096:
            left = deadline - time.monotonic()
            if left <= 0:
                break
            sock.settimeout(left)
            try:
                chunk = sock.recv(4096)
            except OSError:  # the timeout included
                break
            if not chunk:
                break
            data += chunk
    if not data:
        raise ClusterError(f"{where}: no Dask handshake within {timeout_s:g} s — not a Dask "
                           "scheduler (an HTTP server or another service?); check the address "
                           "and port (the scheduler's, usually 8786)")
    if b"pickle-protocol" not in data[:4096] or _frame_length(data) > 4096:
        raise ClusterError(f"{where}: answered {data[:24]!r}..., not a Dask scheduler's "
                           "handshake; check the address and port (the scheduler's, usually "
                           "8786)")


def _frame_length(data: bytes) -> int:
    return int.from_bytes(data[:8], "little") if len(data) >= 8 else 0


@contextmanager
def open_client(scheduler: str | None, workers: int | None, processes: bool,
                timeout_s: float) -> Iterator:
    """A connected ``distributed.Client``: to ``scheduler`` or to a fresh local cluster."""
    try:
        import distributed  # lazy: Dask costs ~1 s to import and only studies need it
    except ImportError as exc:
        raise ClusterError(f"kinestat sweep needs dask.distributed ({exc}); install the "
                           "pinned requirements (requirements/run.txt)") from None

    if scheduler:
        check_address(scheduler)
        probe_scheduler(scheduler, timeout_s)
        try:
            client = distributed.Client(scheduler, timeout=f"{timeout_s}s",
                                        set_as_default=False)
        except Exception as exc:  # noqa: BLE001 - whatever the peer did: one clear error
            raise ClusterError(
                f"--scheduler {scheduler}: cannot connect to a Dask scheduler within "
                f"{timeout_s:g} s ({type(exc).__name__}: {str(exc).splitlines()[0][:160]}); "
                "check the address (tcp://HOST:PORT) and that the scheduler runs") from None
        try:
            if not client.scheduler_info().get("workers"):
                client.wait_for_workers(1, timeout=timeout_s)
        except (OSError, TimeoutError) as exc:
            client.close()
            raise ClusterError(f"--scheduler {scheduler}: no worker joined within "
                               f"{timeout_s:g} s ({type(exc).__name__})") from None
        try:
            yield client
        finally:
            client.close()
        return
    n = (os.cpu_count() or 1) if workers is None else workers
    if n < 1:
        raise InputError(f"--workers must be at least 1, got {n}")
    extra = {"host": "127.0.0.1"} if processes else {}  # threads talk in-process
    try:
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1,
                                           processes=processes,
                                           dashboard_address="127.0.0.1:0",  # any free port
                                           silence_logs=logging.ERROR, **extra)
    except (OSError, RuntimeError, TimeoutError) as exc:
        raise ClusterError(f"the local Dask cluster did not start ({exc})") from None
    with cluster, distributed.Client(cluster, set_as_default=False) as client:
        yield client


def _progress(enabled: bool, total: int, done: int, label: str):
    from rich.console import Console  # lazy: the progress bar only when a study runs
    from rich.progress import (  # lazy: the progress bar only when a study runs
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    prog = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                    TimeElapsedColumn(), TimeRemainingColumn(),
                    console=Console(stderr=True), disable=not enabled, transient=False)
    task = prog.add_task(label, total=total, completed=done)
    return prog, task


def _compute(client, study: Study, store: StudyStore, todo: list[int], progress: bool,
             done: int) -> int:
    from distributed import as_completed  # lazy: Dask only when a study runs

    text = spec_json(study.spec)
    key = f"{study.name}-{spec_hash(study.spec)[:12]}"
    in_flight = max(2, 2 * sum(client.nthreads().values()))
    pending = iter(todo)
    prog, task = _progress(progress, study.n_chunks, done, f"{study.name}")

    def submit(i: int):
        return client.submit(compute_chunk_task, study.name, text, i, key=f"{key}-{i}",
                             pure=False, retries=1)

    computed = 0
    futures = [submit(i) for _, i in zip(range(in_flight), pending, strict=False)]
    queue = as_completed(futures, loop=client.loop)
    with prog:
        for fut in queue:
            try:
                i, rows, partial = fut.result()
            except KinestatError:
                client.cancel(list(queue.futures))
                raise
            store.write_chunk(i, rows, partial)
            fut.release()
            computed += 1
            prog.advance(task)
            nxt = next(pending, None)
            if nxt is not None:
                queue.add(submit(nxt))
    return computed


def run_study(study: Study, output: str | os.PathLike | None = None, *,
              scheduler: str | None = None, workers: int | None = None,
              processes: bool = True, max_chunks: int | None = None, progress: bool = True,
              timeout_s: float = 10.0, plots: bool = True) -> RunResult:
    """Run (or resume) ``study`` into ``output``; reduce and write the summary when complete.

    ``max_chunks`` stops after computing that many new chunks (a staged run: rerun to go on).
    """
    t0 = time.perf_counter()
    if max_chunks is not None and max_chunks < 0:
        raise InputError(f"--max-chunks must be >= 0, got {max_chunks}")
    if not (math.isfinite(timeout_s) and timeout_s > 0):
        raise InputError(f"--timeout must be a finite number of seconds > 0, got {timeout_s}")
    root = Path(output) if output is not None else default_output(study)
    store = StudyStore(root, study.name, study.spec, spec_hash(study.spec), study.n_chunks)
    if scheduler is not None and not scheduler.strip():
        raise InputError("--scheduler: empty address; give tcp://HOST:PORT")
    done = store.check()
    damaged = list(store.damaged)  # recomputed below like any chunk not done
    todo = [i for i in range(study.n_chunks) if i not in done]
    if max_chunks is not None:
        todo = todo[:max_chunks]
    computed = 0
    try:
        if todo:
            # connect first: a bad scheduler leaves no output directory behind
            with open_client(scheduler, workers, processes, timeout_s) as client:
                store.open()
                computed = _compute(client, study, store, todo, progress, len(done))
        else:
            store.open()
    except KeyboardInterrupt:
        n = len(store.done_chunks())
        raise StudyInterrupted(f"{study.name}: {n} of {study.n_chunks} chunks done in {root}; "
                               "run the same command again to resume") from None
    complete = len(done) + computed == study.n_chunks
    summary, plot_files = None, []
    if complete:
        summary = study.reduce(store.read_partials())
        if plots:
            plot_files = study.plot(summary, root / "plots")
        store.write_summary({"study": study.name, "complete": True,
                             "spec_hash": spec_hash(study.spec), "inputs": study.describe(),
                             "summary": summary, "chunks": study.n_chunks, "plots": plot_files})
    return RunResult(study=study.name, output=root, complete=complete, summary=summary,
                     chunks_total=study.n_chunks, chunks_computed=computed,
                     chunks_reused=len(done), elapsed_s=time.perf_counter() - t0,
                     plots=plot_files, chunks_damaged=len(damaged))


def run_reference(study: Study) -> dict:
    """The summary computed in this process, chunk by chunk in order (no Dask, no files)."""
    return study.reduce([study.compute_chunk(i)[1] for i in range(study.n_chunks)])
