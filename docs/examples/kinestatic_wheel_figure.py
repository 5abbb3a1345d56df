"""Draw docs/images/kinestatic-wheel.png: Vibhute Fig. 2-10's wheel on a wall, two targets.

Run from the repository root: ``python docs/examples/kinestatic_wheel_figure.py [OUT.png]``.
Left: the mechanism (body, springs, wheel, contact force) for two wanted (s, N). Right: the
actuator coordinates d1, d2 against the contact force N (s fixed), exact (spring balance) and
the kinestatic step's tangent at N = 10 N.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from kinestat.parallel.planar_wheel import (  # noqa: E402
    actuator_displacements,
    actuator_step,
    figure_2_10_example,
    wheel_center,
)


def zigzag(a, b, turns=8, width=4.0):
    """Points of a spring drawn as a zigzag from a to b."""
    a, b = np.asarray(a), np.asarray(b)
    v = b - a
    u = v / np.linalg.norm(v)
    p = np.array([-u[1], u[0]])
    t = np.linspace(0.15, 0.85, 2 * turns + 1)
    side = np.r_[0, np.tile([1, -1], turns)[: 2 * turns - 1], 0]
    pts = a + np.outer(t, v) + np.outer(side * width, p)
    return np.vstack([a, pts, b])


def draw_state(ax, model, s, N, color, label, names=False):
    d = actuator_displacements(model, s, N)
    C = wheel_center(model, s)
    B = d + model.body_points
    ax.plot(*B.T, color=color, lw=6, solid_capstyle="round")
    for b in B:
        ax.plot(*zigzag(b, C).T, color=color, lw=1.2)
        ax.plot(*b, "o", color="k", ms=4)
    ax.add_patch(matplotlib.patches.Circle(C, model.wheel_radius, fill=False, ec=color, lw=2))
    ax.plot(*C, "o", color=color, ms=4)
    contact = C - model.wheel_radius * model.wall_normal
    ax.annotate("", xy=contact + 1.2 * N * model.wall_normal, xytext=contact,
                arrowprops={"arrowstyle": "-|>", "color": "crimson", "lw": 2})
    ax.text(*(contact + np.array([model.wheel_radius + 2, 3])), f"N = {N:g} N", color="crimson",
            fontsize=8)
    ax.plot(*d, "s", color="k", ms=5)
    text = f"{label}: s = {s:g} mm, d = ({d[0]:.1f}, {d[1]:.1f}) mm"
    if names:
        ax.text(*(B[0] + [-2, 5]), text, color=color, fontsize=8)
    else:
        ax.text(B[1][0] + 28, B[1][1] + 5, text, color=color, fontsize=8, ha="right")
    if names:
        ax.text(*(B[0] + [-10, -8]), "B1", fontsize=8)
        ax.text(*(B[1] + [-4, 6]), "B2", fontsize=8)
        ax.text(*(C + [-12, 4]), "C", fontsize=8)


def main(out: str = "docs/images/kinestatic-wheel.png") -> None:
    model = figure_2_10_example()
    fig = Figure(figsize=(11, 4.6), layout="constrained")
    ax, bx = fig.subplots(1, 2, width_ratios=[1.25, 1])
    ax.axhspan(-12, 0, color="0.85")
    ax.axhline(0, color="k", lw=1.5)
    ax.text(-95, -8, "rigid wall (floor): n = (0, 1), s along t = (1, 0)", fontsize=8)
    draw_state(ax, model, -35.0, 5.0, "tab:blue", "A", names=True)
    draw_state(ax, model, 40.0, 25.0, "tab:green", "B")
    ax.annotate("", xy=(-85, 110), xytext=(-100, 110), arrowprops={"arrowstyle": "->"})
    ax.annotate("", xy=(-100, 125), xytext=(-100, 110), arrowprops={"arrowstyle": "->"})
    ax.text(-84, 107, "d1 (i)", fontsize=8)
    ax.text(-98, 126, "d2 (j)", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlim(-105, 115)
    ax.set_ylim(-12, 135)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title("Fig. 2-10: body on two actuators, springs B1C, B2C, wheel on the wall",
                 fontsize=9)

    N = np.linspace(0.0, 40.0, 81)
    d = actuator_displacements(model, 0.0, N)
    N0 = 10.0
    d0 = actuator_displacements(model, 0.0, N0)
    tangent = d0 + actuator_step(model, N0, 0.0, N - N0)
    for i, c in enumerate(("tab:blue", "tab:orange")):
        bx.plot(N, d[:, i] - d[0, i], color=c, lw=2, label=f"d{i + 1} exact (balance)")
        bx.plot(N, tangent[:, i] - d[0, i], "--", color=c, lw=1,
                label=f"d{i + 1} kinestatic step from N = {N0:g} N")
    bx.plot([N0, N0], [d0[0] - d[0, 0], d0[1] - d[0, 1]], "ko", ms=4)
    bx.set_xlabel("contact force N (N), wheel at s = 0")
    bx.set_ylabel("actuator displacement from N = 0 (mm)")
    bx.set_title("Actuator moves for a wanted contact force", fontsize=9)
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main(*sys.argv[1:])
