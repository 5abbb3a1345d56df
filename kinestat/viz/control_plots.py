"""Plots of a kinestatic control run: the contact wrench versus the state of the platform.

Vibhute 2011 Figure 5-2 (A–G): the force magnitude, the force components fx, fy, fz and the
torque components mx, my, mz of the effective wrench in the fixed frame, against the states
a–e of the run (:data:`kinestat.control.controller.STATES`). Here each measurement cycle is a
point, coloured by its state; the torque (E–G) is the moment about the robot's base, the fixed
frame's origin, as the thesis's panels take it (the log's ``torque_about_base``). When
the log holds the simulator's true force (``true``), panel A also shows it (dashed), and the
target band ``|F_req| ± force_tol`` is shaded.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kinestat.control.controller import STATES
from kinestat.errors import InputError
from kinestat.viz._files import save_figures

__all__ = ["STATE_COLOURS", "cycle_series", "wrench_figure", "write_plots"]

STATE_COLOURS = {"a": "#7f7f7f", "b": "#d62728", "c": "#ff7f0e", "d": "#1f77b4", "e": "#2ca02c"}
"""Colour of each state a–e."""

_PANELS = [
    ("A", "force magnitude |F| (N)", "fmag"),
    ("B", "fx (N)", 0),
    ("C", "fy (N)", 1),
    ("D", "fz (N)", 2),
    ("E", "mx about the robot base (N·mm)", 3),
    ("F", "my about the robot base (N·mm)", 4),
    ("G", "mz about the robot base (N·mm)", 5),
]


def cycle_series(records: list[dict]) -> dict:
    """Arrays from a run's log records: cycle, state, force (n, 3), torque about the robot base
    (n, 3), |F|, true |F| (NaN where unknown), and the target and tolerance from the start
    record."""
    cyc = [r for r in records if r.get("type") == "cycle"]
    if not cyc:
        raise InputError("the log has no measurement cycles to plot")
    head = next((r for r in records if r.get("type") == "start"), {})
    cfg = head.get("config", {})
    force = np.array([r["measured"]["force"] for r in cyc], dtype=float)
    torque = np.array([r["measured"].get("torque_about_base", r["measured"].get("moment_origin"))
                       for r in cyc], dtype=float)
    true = np.array([
        (r.get("true") or {}).get("tool_force_magnitude", np.nan) for r in cyc], dtype=float)
    return {
        "cycle": np.array([r["cycle"] for r in cyc], dtype=int),
        "state": [r["state"] for r in cyc],
        "force": force,
        "torque": torque,
        "fmag": np.linalg.norm(force, axis=1),
        "true_fmag": true,
        "target": cfg.get("force_target"),
        "tol": cfg.get("force_tol"),
    }


def wrench_figure(records: list[dict], title: str | None = None):
    """The seven-panel figure (matplotlib ``Figure``) of Vibhute's Figure 5-2 for a run."""
    import matplotlib  # lazy: matplotlib costs start-up time and is needed only to plot

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure  # lazy: as above
    from matplotlib.lines import Line2D  # lazy: as above

    s = cycle_series(records)
    x = s["cycle"]
    states = s["state"]
    cols = [STATE_COLOURS.get(st, "black") for st in states]
    fig = Figure(figsize=(11, 12), constrained_layout=True)
    axes = fig.subplots(4, 2).ravel()
    for ax, (letter, label, key) in zip(axes, _PANELS, strict=False):
        if key == "fmag":
            y = s["fmag"]
            if s["target"] is not None and s["tol"] is not None:
                ax.axhspan(s["target"] - s["tol"], s["target"] + s["tol"], color="#2ca02c",
                           alpha=0.12, lw=0)
                ax.axhline(s["target"], color="#2ca02c", lw=0.8, ls=":")
            if np.any(np.isfinite(s["true_fmag"])):
                ax.plot(x, s["true_fmag"], ls="--", color="black", lw=0.8, label="true")
        elif key < 3:
            y = s["force"][:, key]
        else:
            y = s["torque"][:, key - 3]
        ax.plot(x, y, color="#bbbbbb", lw=0.8, zorder=1)
        ax.scatter(x, y, c=cols, s=28, zorder=2)
        ax.set_title(f"{letter}) {label}", fontsize=10, loc="left")
        ax.set_xticks(x)
        ax.set_xticklabels(states if len(x) <= 40 else [""] * len(x), fontsize=8)
        ax.grid(True, lw=0.3)
    ax = axes[-1]
    ax.axis("off")
    handles = [Line2D([], [], marker="o", ls="", color=c, label=f"{k}") for k, c in
               STATE_COLOURS.items()]
    labels = [f"{k}: {STATES[k]}" for k in STATE_COLOURS]
    if np.any(np.isfinite(s["true_fmag"])):
        handles.append(Line2D([], [], ls="--", color="black"))
        labels.append("true force (simulator)")
    ax.legend(handles, labels, loc="center", fontsize=9, frameon=False,
              title="state of the platform (x axis: one point per cycle)")
    fig.suptitle(title or "Contact wrench vs state of the platform (cf. Vibhute Fig. 5-2)")
    return fig


def write_plots(records: list[dict], directory: str | os.PathLike,
                title: str | None = None) -> list[Path]:
    """Write ``wrench-vs-state.png`` into ``directory`` (created); return the paths written."""
    return save_figures(directory, [("wrench-vs-state.png", wrench_figure(records, title))])
