"""PNG plots of a guidance run: the joint variables per step and the hand path in 3-D.

matplotlib with the Agg backend (no display needed); figures are built with
``matplotlib.figure.Figure`` so nothing touches pyplot's global state.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kinestat.serial.guidance.events import JointLimitStop, NotConverged, Singularity
from kinestat.serial.guidance.run import GuidanceResult, joint_display
from kinestat.viz._files import save_figures

__all__ = ["joints_figure", "hand_path_figure", "write_guidance_plots"]


def _figure(**kw):
    import matplotlib  # lazy: matplotlib takes ~0.5 s to import, only plots need it

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure  # lazy: as above

    return Figure(**kw)


def joints_figure(result: GuidanceResult, title: str | None = None):
    """Joint values per step (one panel per joint; degrees or length units)."""
    m = result.model
    vals = joint_display(m, result.q)
    steps = np.arange(vals.shape[0])
    n = m.n
    cols = 2 if n > 3 else 1
    rows = int(np.ceil(n / cols))
    fig = _figure(figsize=(10, 2.2 * rows + 0.8), constrained_layout=True)
    axes = np.atleast_1d(fig.subplots(rows, cols, sharex=True)).ravel()
    ends = result.stage_end_rows()
    for i in range(n):
        ax = axes[i]
        y = vals[:, i]
        if np.ptp(y) < 1e-9 * max(1.0, float(np.max(np.abs(y)))):  # constant: no noise plot
            y = np.full_like(y, np.round(float(np.mean(y)), 9))
            ax.set_ylim(y[0] - 1.0, y[0] + 1.0)
        ax.plot(steps, y, lw=1.2, marker="." if len(steps) <= 60 else None)
        for e in ends[:-1]:
            ax.axvline(e, color="grey", lw=0.6, ls=":")
        for ev in result.events:
            if isinstance(ev, (Singularity, JointLimitStop, NotConverged)):
                ax.axvline(ev.step, color="red", lw=0.8, ls="--")
        unit = m.length_unit if m.prismatic[i] else "deg"
        name = f"r{i + 1}" if m.prismatic[i] else f"θ{i + 1}"
        ax.set_ylabel(f"{name} ({unit})")
        ax.grid(True, lw=0.3)
    for ax in axes[n:]:
        ax.axis("off")
    for ax in axes[max(0, n - cols):n]:
        ax.set_xlabel("step")
    fig.suptitle(title or f"Joint variables, {m.name}")
    return fig


def hand_path_figure(result: GuidanceResult, title: str | None = None):
    """3-D path of the hand origin (actual and ideal) with the start and the targets."""
    fig = _figure(figsize=(7.5, 6.5), constrained_layout=True)
    ax = fig.add_subplot(projection="3d")
    o = result.poses[:, :3, 3]
    ideal = result.ideal[:, :3, 3]
    ax.plot(*ideal.T, color="#2ca02c", lw=1.0, ls="--", label="ideal path")
    ax.plot(*o.T, color="#1f77b4", lw=1.5, label="hand origin")
    ax.scatter(*o[0], color="black", s=30, label="start")
    if result.stage_targets:
        t = np.array([T[:3, 3] for T in result.stage_targets])
        ax.scatter(*t.T, color="red", marker="x", s=50, label="target(s)")
    # hand z axes at a few rows
    k = max(1, len(o) // 12)
    z = result.poses[::k, :3, 2]
    scale = 0.15 * max(float(np.ptp(o, axis=0).max()), 1e-9)
    ax.quiver(*o[::k].T, *(scale * z).T, color="#ff7f0e", lw=0.8, label="hand z")
    # equal scales on the three axes, so a straight path looks straight and deviations are
    # seen at their true size
    pts = np.vstack([o, ideal])
    centre = (pts.max(axis=0) + pts.min(axis=0)) / 2
    half = max(float(np.ptp(pts, axis=0).max()) / 2 * 1.1, 1e-9)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    u = result.model.length_unit
    ax.set_xlabel(f"x ({u})")
    ax.set_ylabel(f"y ({u})")
    ax.set_zlabel(f"z ({u})")
    ax.legend(loc="upper left", fontsize=8)
    fig.suptitle(title or f"Hand path, {result.model.name}")
    return fig


def write_guidance_plots(result: GuidanceResult, directory: str | os.PathLike,
                         title: str | None = None) -> list[Path]:
    """Write ``joints.png`` and ``hand-path.png`` into ``directory`` (created)."""
    return save_figures(directory, [("joints.png", joints_figure(result, title)),
                                    ("hand-path.png", hand_path_figure(result, title))])
