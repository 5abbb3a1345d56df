"""Plots of a follow run (``kinestat control --task follow``): the normal force against the
distance travelled along the surface, and the tool's path on the surface.

Both read the cycle log (:mod:`kinestat.control.log`): each cycle's ``task`` record holds the
measured tip, the normal estimate, the measured normal force and the travel; ``true`` holds the
simulator's tip, force and normal when simulated (drawn dashed).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kinestat.errors import InputError
from kinestat.viz._files import save_figures

__all__ = ["follow_series", "force_travel_figure", "path_figure", "write_follow_plots"]


def _nan3(v) -> np.ndarray:
    return np.full(3, np.nan) if v is None else np.asarray(v, dtype=float)


def follow_series(records: list[dict]) -> dict:
    """Arrays of a follow run's log: travel (mm), measured and true normal force (N, NaN where
    unknown), measured and true tip (n, 3), phase per cycle, the target force."""
    cyc = [r for r in records if r.get("type") == "cycle" and r.get("task")]
    if not cyc:
        raise InputError("the log has no follow-task cycles to plot")
    head = next((r for r in records if r.get("type") == "start"), {})
    true_fn = []
    for r in cyc:
        t = r.get("true") or {}
        f, n = t.get("tool_force"), t.get("normal")
        true_fn.append(np.nan if f is None or n is None
                       else -float(np.asarray(f, dtype=float) @ np.asarray(n, dtype=float)))
    return {
        "travel": np.array([r["task"]["travel"] for r in cyc], dtype=float),
        "normal_force": np.array([r["task"]["normal_force"] for r in cyc], dtype=float),
        "true_normal_force": np.array(true_fn, dtype=float),
        "tip": np.array([_nan3(r["task"]["tip"]) for r in cyc]),
        "true_tip": np.array([_nan3((r.get("true") or {}).get("tip")) for r in cyc]),
        "phase": [r["task"]["phase"] for r in cyc],
        "in_contact": np.array([bool(r["task"]["in_contact"]) for r in cyc]),
        "target": head.get("config", {}).get("force_target"),
    }


def _mpl():
    import matplotlib  # lazy: matplotlib costs start-up time and is needed only to plot

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure  # lazy: as above

    return Figure


def force_travel_figure(records: list[dict]):
    """Normal force (measured, and true when simulated) against travel, travel cycles only."""
    s = follow_series(records)
    keep = np.array([p == "travel" for p in s["phase"]]) & s["in_contact"]
    fig = _mpl()(figsize=(8, 4.5), constrained_layout=True)
    ax = fig.subplots()
    if s["target"] is not None:
        ax.axhspan(s["target"] - 0.5, s["target"] + 0.5, color="#2ca02c", alpha=0.12, lw=0,
                   label="target ± 0.5 N")
        ax.axhline(s["target"], color="#2ca02c", lw=0.8, ls=":")
    ax.plot(s["travel"][keep], s["normal_force"][keep], "o-", ms=3, lw=0.8, label="measured")
    if np.any(np.isfinite(s["true_normal_force"][keep])):
        ax.plot(s["travel"][keep], s["true_normal_force"][keep], ls="--", color="black", lw=0.8,
                label="true (simulator)")
    ax.set_xlabel("travel along the surface (mm)")
    ax.set_ylabel("normal force (N)")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Normal force against travel")
    return fig


def path_figure(records: list[dict]):
    """The tool tip's path in contact, drawn in the plane of its two main directions (the
    surface's tangent plane for a plane; the path's own plane on a curved surface), and its
    height along the third direction (mm)."""
    s = follow_series(records)
    tips = s["tip"][s["in_contact"]]
    if tips.shape[0] < 2:
        raise InputError("the log has fewer than two contact cycles: no path to plot")
    c = tips.mean(axis=0)
    _, _, vt = np.linalg.svd(tips - c)
    fig = _mpl()(figsize=(9, 4.5), constrained_layout=True)
    ax1, ax2 = fig.subplots(1, 2)
    for key, style, label in (("tip", "o-", "measured tip"), ("true_tip", "--", "true tip")):
        p = s[key][s["in_contact"]]
        if not np.all(np.isfinite(p)):
            continue
        uvw = (p - c) @ vt.T
        ax1.plot(uvw[:, 0], uvw[:, 1], style, ms=3, lw=0.8, label=label)
        ax2.plot(uvw[:, 0], uvw[:, 2], style, ms=3, lw=0.8, label=label)
    ax1.set_xlabel("along the path (mm)")
    ax1.set_ylabel("across the path (mm)")
    ax1.set_title("Tool path on the surface")
    ax2.set_xlabel("along the path (mm)")
    ax2.set_ylabel("out of the path's plane (mm)")
    ax2.set_title("Path height (curvature of the surface)")
    for ax in (ax1, ax2):
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=8)
    return fig


def write_follow_plots(records: list[dict], directory: str | os.PathLike) -> list[Path]:
    """Write ``normal-force-vs-travel.png`` and ``tool-path.png`` into ``directory``."""
    return save_figures(directory, [("normal-force-vs-travel.png", force_travel_figure(records)),
                                    ("tool-path.png", path_figure(records))])
