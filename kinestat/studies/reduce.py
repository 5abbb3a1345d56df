"""Partial summaries of one chunk and their exact, order-fixed reduction.

A chunk's partial summary is plain JSON: counts (ints), float sums/extremes (Python floats, which
JSON round-trips exactly) and histogram counts on bin edges fixed before the run. The reduction
visits the partials in chunk order 0, 1, 2, ... and adds with Python floats, so the reduced
summary is bitwise the same whichever cluster, worker or resume produced the partials.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["stats", "merge_stats", "finish_stats", "histogram", "merge_histograms",
           "log_edges", "histogram2d", "merge_counts"]


def stats(values) -> dict:
    """Count, sum, sum of squares, min and max of the finite entries of ``values``."""
    x = np.asarray(values, dtype=float).ravel()
    x = x[np.isfinite(x)]
    if x.size == 0:
        return {"count": 0, "sum": 0.0, "sumsq": 0.0, "min": None, "max": None}
    return {"count": int(x.size), "sum": float(np.sum(x)), "sumsq": float(np.sum(x * x)),
            "min": float(np.min(x)), "max": float(np.max(x))}


def merge_stats(parts: Sequence[dict]) -> dict:
    """Combine partial :func:`stats` in the given (fixed) order."""
    count, s, s2, lo, hi = 0, 0.0, 0.0, math.inf, -math.inf
    for p in parts:
        if p["count"] == 0:
            continue
        count += p["count"]
        s += p["sum"]
        s2 += p["sumsq"]
        lo = min(lo, p["min"])
        hi = max(hi, p["max"])
    if count == 0:
        return {"count": 0, "sum": 0.0, "sumsq": 0.0, "min": None, "max": None}
    return {"count": count, "sum": s, "sumsq": s2, "min": lo, "max": hi}


def finish_stats(s: dict) -> dict:
    """``{count, min, mean, max, rms}`` of merged stats (None where there is no value)."""
    n = s["count"]
    return {"count": n, "min": s["min"], "mean": s["sum"] / n if n else None,
            "max": s["max"], "rms": math.sqrt(s["sumsq"] / n) if n else None}


def log_edges(lo_decade: int, hi_decade: int, per_decade: int = 5) -> np.ndarray:
    """Logarithmic bin edges 10^lo … 10^hi, ``per_decade`` bins a decade."""
    return np.logspace(lo_decade, hi_decade, (hi_decade - lo_decade) * per_decade + 1)


def histogram(values, edges) -> dict:
    """Counts of finite ``values`` in bins ``edges`` plus ``below``/``above`` the range."""
    x = np.asarray(values, dtype=float).ravel()
    x = x[np.isfinite(x)]
    e = np.asarray(edges, dtype=float)
    counts, _ = np.histogram(x, bins=e)
    return {"edges": e.tolist(), "counts": counts.astype(np.int64).tolist(),
            "below": int(np.sum(x < e[0])), "above": int(np.sum(x > e[-1]))}


def merge_histograms(parts: Sequence[dict]) -> dict:
    """Sum histograms with identical edges (exact integer counts)."""
    first = parts[0]
    counts = np.zeros(len(first["counts"]), dtype=np.int64)
    below = above = 0
    for p in parts:
        counts += np.asarray(p["counts"], dtype=np.int64)
        below += p["below"]
        above += p["above"]
    return {"edges": first["edges"], "counts": counts.tolist(), "below": below, "above": above}


def histogram2d(x, y, edges_x, edges_y) -> list[list[int]]:
    """Counts (len(edges_x)-1, len(edges_y)-1) of the points (x, y) inside the edges."""
    h, _, _ = np.histogram2d(np.asarray(x, float), np.asarray(y, float),
                             bins=[np.asarray(edges_x, float), np.asarray(edges_y, float)])
    return h.astype(np.int64).tolist()


def merge_counts(parts: Sequence) -> list:
    """Elementwise integer sum of nested count lists of one shape."""
    total = np.zeros(np.shape(parts[0]), dtype=np.int64)
    for p in parts:
        total += np.asarray(p, dtype=np.int64)
    return total.tolist()
