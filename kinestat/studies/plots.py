"""PNG plots of complete studies (matplotlib, imported lazily with the Agg backend)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["histogram_png", "slice_png", "scatter_png"]


def _plt():
    import matplotlib  # lazy: plotting is optional and slow to import

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # lazy: matplotlib only when plotting

    return plt


def _save(plt, fig, ax, path: Path, xlabel: str, ylabel: str, title: str) -> str:
    """Label the axes, title the plot, write ``path`` (its folder created) and close the
    figure; returns the file name."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path.name


def histogram_png(hist: dict, path: Path, xlabel: str, title: str, log_x: bool = False) -> str:
    """A bar histogram of reduced counts (:func:`kinestat.studies.reduce.histogram`)."""
    plt = _plt()
    e = np.asarray(hist["edges"])
    c = np.asarray(hist["counts"])
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.stairs(c, e, fill=True, alpha=0.7)
    if log_x:
        ax.set_xscale("log")
    extra = f" (below {hist['below']}, above {hist['above']})" if hist["below"] or \
        hist["above"] else ""
    return _save(plt, fig, ax, path, xlabel, "count", title + extra)


def slice_png(counts, edges_x, edges_y, path: Path, xlabel: str, ylabel: str,
              title: str) -> str:
    """A 2-D occupancy image (counts per cell, log colour scale)."""
    plt = _plt()
    from matplotlib.colors import LogNorm  # lazy: matplotlib only when plotting

    c = np.asarray(counts, dtype=float)
    fig, ax = plt.subplots(figsize=(5.5, 5))
    masked = np.ma.masked_where(c <= 0, c)
    vmax = max(float(c.max()), 1.0)
    m = ax.pcolormesh(edges_x, edges_y, masked.T, norm=LogNorm(vmin=1, vmax=vmax))
    fig.colorbar(m, ax=ax, label="points")
    ax.set_aspect("equal")
    return _save(plt, fig, ax, path, xlabel, ylabel, title)


def scatter_png(x, y, path: Path, xlabel: str, ylabel: str, title: str, mark=None) -> str:
    """A scatter plot; ``mark`` (bool array) highlights some points."""
    plt = _plt()
    x, y = np.asarray(x, float), np.asarray(y, float)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.scatter(x, y, s=8, alpha=0.6)
    if mark is not None and np.any(mark):
        ax.scatter(x[mark], y[mark], s=40, facecolors="none", edgecolors="red")
    return _save(plt, fig, ax, path, xlabel, ylabel, title)
