"""Inputs of a study by index arithmetic: tensor grids, chunk ranges and per-chunk random streams.

Nothing here materialises a whole grid: chunk ``i`` of a grid of ``N^n`` points is rebuilt from
its flat indices ``[i*C, min((i+1)*C, N^n))`` (C the chunk size), so a 10^8-point study holds
one chunk at a time. Random inputs come from ``SeedSequence(seed, spawn_key=(stream, i))``:
chunk ``i`` draws the same numbers on any worker, in any order, after any restart.
"""

from __future__ import annotations

import os

import numpy as np

from kinestat.errors import InputError

__all__ = ["MAX_POINTS", "MAX_CHUNKS", "check_chunking", "memory_budget",
           "check_grid", "check_grid_count", "check_samples", "check_seed",
           "sampling", "chunk_count", "chunk_range", "grid_points", "chunk_rng",
           "parse_values"]

#: the largest grid or sample count accepted (indices stay exact in int64)
MAX_POINTS = 1 << 62

#: the most chunks a study may have: each is a JSON and a Parquet file in its directory, and
#: the reduction holds every chunk's partial summary at once
MAX_CHUNKS = 1_000_000

#: the share of this machine's memory one chunk may take (a worker holds up to two chunks per
#: thread in flight, one worker per core; the client receives their rows)
CHUNK_MEMORY_SHARE = 1 / 8


def memory_budget() -> int:
    """Bytes one chunk may take here: :data:`CHUNK_MEMORY_SHARE` of the physical memory."""
    try:
        phys = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # no sysconf: assume a small machine, 4 GiB
        phys = 4 << 30
    return int(phys * CHUNK_MEMORY_SHARE)


def check_chunking(total: int, chunk_size: int, row_bytes: int, what: str) -> int:
    """The chunk count of ``total`` items in chunks of ``chunk_size``, refused BEFORE anything
    is allocated when one chunk (``row_bytes`` per item) would not fit :func:`memory_budget`
    or the chunks would be more than :data:`MAX_CHUNKS`.

    >>> check_chunking(10, 4, 100, "samples")
    3
    """
    n = chunk_count(total, chunk_size)
    budget = memory_budget()
    largest = max(1, budget // row_bytes)
    if min(chunk_size, total) > largest:
        raise InputError(f"--chunk-size {chunk_size}: one chunk would take about "
                         f"{min(chunk_size, total) * row_bytes / 2**30:.3g} GiB ({row_bytes} bytes "
                         f"per evaluation), more than the {budget / 2**30:.3g} GiB a chunk may "
                         f"use on this machine; give --chunk-size {largest} or less")
    if n > MAX_CHUNKS:
        raise InputError(f"{total:.4g} {what} in chunks of {chunk_size} make {n:.4g} chunks, "
                         f"more than the {MAX_CHUNKS:.0e} a study holds; give a larger "
                         f"--chunk-size (at most {largest} here) or fewer {what}")
    return n


#: independent random streams of a study (the stream is the first spawn key)
STREAM_INPUTS = 0
STREAM_POSES = 1


def _whole(v) -> bool:
    return isinstance(v, (int, np.integer)) and not isinstance(v, bool)


def check_grid_count(n_per_axis: int, what: str = "--grid") -> int:
    """A grid's values per axis: a whole number ≥ 2 (both ends of each range are included)."""
    if not _whole(n_per_axis) or n_per_axis < 2:
        raise InputError(f"{what} {n_per_axis}: a grid needs at least 2 values per axis (both "
                         "ends of each range are included)")
    return int(n_per_axis)


def check_samples(samples: int, what: str = "--samples") -> int:
    """A sample count: a whole number from 1 to :data:`MAX_POINTS`."""
    if not _whole(samples) or not 1 <= samples <= MAX_POINTS:
        raise InputError(f"{what} must be at least 1 (and at most {MAX_POINTS:.3e}), "
                         f"got {samples}")
    return int(samples)


def check_seed(seed: int) -> int:
    """A seed of the random inputs: a whole number ≥ 0 (NumPy's ``SeedSequence`` entropy).

    >>> check_seed(7)
    7
    """
    if not _whole(seed) or seed < 0:
        raise InputError(f"--seed must be a whole number ≥ 0, got {seed}")
    return int(seed)


def sampling(grid: int | None, samples: int | None, seed: int, n_axes: int) -> dict:
    """The spec entries of a study over a box: ``{"mode": "grid", "grid": N}`` (a full tensor
    grid, N values per axis) or ``{"mode": "samples", "samples": N}``, with ``"seed"``.

    >>> sampling(None, 10, 3, 2)
    {'seed': 3, 'mode': 'samples', 'samples': 10}
    """
    if (grid is None) == (samples is None):
        raise InputError("give exactly one of --grid N and --samples N")
    out: dict = {"seed": check_seed(seed)}
    if grid is not None:
        check_grid(grid, n_axes)
        out.update(mode="grid", grid=int(grid))
    else:
        out.update(mode="samples", samples=check_samples(samples))
    return out


def check_grid(n_per_axis: int, n_axes: int, what: str = "--grid") -> int:
    """Total points ``n_per_axis ** n_axes`` of a full tensor grid (both ends included)."""
    check_grid_count(n_per_axis, what)
    total = int(n_per_axis) ** int(n_axes)
    if total > MAX_POINTS:
        raise InputError(f"{what} {n_per_axis} over {n_axes} axes makes {total:.3e} points, "
                         f"more than {MAX_POINTS:.3e}")
    return total


def chunk_count(total: int, chunk_size: int) -> int:
    """Number of chunks of at most ``chunk_size`` covering ``total`` items."""
    if chunk_size < 1:
        raise InputError(f"--chunk-size must be positive, got {chunk_size}")
    return (int(total) + chunk_size - 1) // chunk_size


def chunk_range(i: int, total: int, chunk_size: int) -> tuple[int, int]:
    """Flat index range ``[start, stop)`` of chunk ``i``."""
    start = i * chunk_size
    return start, min(start + chunk_size, total)


def grid_points(start: int, stop: int, lower, upper, n_per_axis: int) -> np.ndarray:
    """Points ``(stop-start, n_axes)`` of the tensor grid, flat C order (last axis fastest).

    Axis ``j`` takes ``n_per_axis`` evenly spaced values from ``lower[j]`` to ``upper[j]``, both
    ends exact: value ``lower (1 - t) + upper t`` with ``t = k / (n_per_axis - 1)``.

    >>> grid_points(0, 4, [0.0, 0.0], [1.0, 2.0], 2).tolist()
    [[0.0, 0.0], [0.0, 2.0], [1.0, 0.0], [1.0, 2.0]]
    """
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    idx = np.arange(start, stop, dtype=np.int64)
    out = np.empty((idx.size, lo.size))
    for j in range(lo.size - 1, -1, -1):
        k = idx % n_per_axis
        idx = idx // n_per_axis
        t = k / (n_per_axis - 1)
        out[:, j] = lo[j] * (1.0 - t) + hi[j] * t
    return out


def chunk_rng(seed: int, chunk: int, stream: int = STREAM_INPUTS) -> np.random.Generator:
    """The random generator of chunk ``chunk`` (stream ``stream``) of a study seeded ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(stream, chunk)))


def parse_values(text: str, name: str, grid: int | None = None) -> list[float]:
    """A parameter's values: ``v``, ``v1,v2,...``, ``lo:hi`` (``grid`` values) or ``lo:hi:n``.

    >>> parse_values("100:140:3", "base-side")
    [100.0, 120.0, 140.0]
    """
    s = text.strip()
    try:
        if ":" in s:
            parts = s.split(":")
            if len(parts) not in (2, 3):
                raise ValueError
            lo, hi = float(parts[0]), float(parts[1])
            n = int(parts[2]) if len(parts) == 3 else grid
            if n is None:
                raise InputError(f"--{name} {text!r}: a range lo:hi needs a count (lo:hi:n) "
                                 "or --grid N")
            if n < 1 or (n == 1 and lo != hi):
                raise InputError(f"--{name} {text!r}: a range needs at least 2 values")
            vals = [lo] if n == 1 else [lo * (1 - k / (n - 1)) + hi * (k / (n - 1))
                                        for k in range(n)]
        else:
            vals = [float(v) for v in s.split(",")]
    except InputError:
        raise
    except ValueError:
        raise InputError(f"--{name}: cannot read {text!r}; give a number, numbers separated by "
                         "commas, lo:hi or lo:hi:n") from None
    if not vals or not np.all(np.isfinite(vals)):
        raise InputError(f"--{name}: values must be finite numbers, got {text!r}")
    return vals
