"""``kinestat demo``: a tour of the thesis illustrations on the embedded data.

Each section computes one published illustration from its inputs and prints the result; see the
docs for how each compares with the publication.
"""

from __future__ import annotations

import numpy as np
import typer

from kinestat.cli._compile import (
    KERNELS,
    RUN_GROUPS,
    compile_groups,
    compiling_notice,
    is_cold,
)
from kinestat.cli._options import command_help, flag, json_option
from kinestat.cli._output import console, print_json, table
from kinestat.io.disp_deck import embedded_deck
from kinestat.mechanism.nadkarni import mechanism_frames
from kinestat.spatial.displacement import frame_from_triple, screws_between


def register(app: typer.Typer) -> None:
    app.command("demo", help=command_help(demo_command))(demo_command)
    app.command("warmup", hidden=True, help=command_help(warmup_command))(warmup_command)


def warmup_command(
    every: bool = flag(False, "--all", help="Every kernel group, not only those "
                       "`kinestat control` runs."),
    jobs: int = typer.Option(0, "--jobs", min=0, help="Processes compiling at once "
                             "(0: one an idle core)."),
    as_json: bool = json_option(),
) -> None:
    """Compile the kernels `kinestat control` runs now (first run only; later runs load them
    from the cache); `--all` every group.

    `make run` calls this, so that its control run does not spend its first cycles compiling;
    any other command compiles what it uses on first use and says so on stderr when that takes
    over a second. Cold groups compile in parallel processes, one an idle core. JSON:
    {"seconds": {group: s}, "compiled": [groups that were cold]}.
    """
    groups = tuple(KERNELS) if every else RUN_GROUPS
    cold = [g for g in groups if is_cold(g)]
    took = compile_groups(groups, jobs or None)
    if as_json:
        print_json({"seconds": took, "compiled": cold})
        return
    console.print(table("Kernels", ["group", "module", "state", "time (s)"],
                        [[g, KERNELS[g], "compiled now" if g in cold else "cached", took[g]]
                         for g in groups], fmt="{:.2f}"))


def _screws() -> dict:
    """Nadkarni Illustration 1 (MS = 1): the screw between consecutive body positions."""

    deck = embedded_deck("illustration1")
    s = screws_between(frame_from_triple(deck.positions))
    rows = [{"axis": s.axis[i], "point": s.point[i], "translation": s.d[i],
             "angle_deg": s.angle_deg[i], "pitch": s.pitch[i]} for i in range(len(s.theta))]
    console.print(table("Nadkarni Illustration 1: screw axes between positions",
                        ["pair", "u1", "u2", "u3", "ρn x", "ρn y", "ρn z", "θ (deg)", "d"],
                        [[f"{i + 1}→{i + 2}", *r["axis"], *r["point"], r["angle_deg"],
                          r["translation"]] for i, r in enumerate(rows)]))
    return {"screws": rows}


def _transm() -> dict:
    """Nadkarni Illustration 2 (MS = 2): the mechanism in the global frame."""

    deck = embedded_deck("illustration2")
    f = mechanism_frames(deck.joint_table, deck.frame_points)
    console.print(table("Nadkarni Illustration 2: joint origins X*(i), X(i) and axes U(i)",
                        ["i", "X* x", "X* y", "X* z", "X x", "X y", "X z", "U x", "U y", "U z"],
                        [[i + 1, *f.origin_star[i], *f.origin[i], *f.axis[i]]
                         for i in range(len(f.axis))], fmt="{:.3f}"))
    return {"joints": [{"origin_star": f.origin_star[i], "origin": f.origin[i],
                        "axis": f.axis[i], "normal": f.normal[i]} for i in range(len(f.axis))]}


def _puma() -> dict:
    """Vibhute Appendix C: reverse analysis of the PUMA 762 example pose."""
    from kinestat.robots.puma762 import (
        closed_form as puma762,  # lazy: PUMA closed-form kernels, ~13 ms at start-up
    )

    res = puma762.reverse([725.0, 190.0, 650.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    sols = np.rad2deg(res.solutions)
    console.print(table("PUMA 762, Vibhute App. C example: P_tool_F (725, 190, 650), "
                        "S6 = x, a67 = z", ["branch", "φ1", "θ2", "θ3", "θ4", "θ5", "θ6"],
                        [[int(b), *q] for b, q in zip(res.branches, sols, strict=True)],
                        fmt="{:.3f}"))
    for fam in res.families:
        # WristFamily: "sum" fixes θ4 + θ6 (θ5 = 180°), "difference" fixes θ6 − θ4 (θ5 = 0)
        rel = "θ4 + θ6" if fam.kind == "sum" else "θ6 − θ4"
        console.print(f"  wrist-singular family: {rel} = {np.rad2deg(fam.value):.3f}° "
                      f"(θ5 = {np.rad2deg(fam.theta5):.1f}°)")
    return {"solutions_deg": sols, "singular_families": len(res.families)}


def _platform() -> dict:
    """Vibhute Appendix B: every assembly mode of the prototype for main.cpp's leg lengths."""

    from kinestat.io.library import prototype  # lazy: start-up
    from kinestat.parallel.fk import fk_list  # lazy: start-up (numba)
    from kinestat.parallel.legs import leg_lengths  # lazy: start-up

    p = prototype()
    legs = np.array([79.6804, 81.8285, 81.2669, 68.6500, 67.2037, 68.2854])
    modes = fk_list(p, legs)
    rows = []
    for k, T in enumerate(modes):
        err = np.abs(leg_lengths(p, T) - legs).max()
        yaw = np.rad2deg(np.arctan2(T[1, 0], T[0, 0]))
        rows.append([k + 1, *T[:3, 3], yaw, err])
    console.print(table("Special 6-6 platform: assembly modes for Appendix B's legs",
                        ["mode", "x", "y", "z", "yaw (deg)", "leg error"], rows, fmt="{:.4g}"))
    return {"modes": len(modes), "poses": modes}


def demo_command(
    as_json: bool = json_option(),
) -> None:
    """Run the thesis illustrations on the embedded data and print their results."""
    out = {}
    with compiling_notice("puma762", "platform"):
        _demo(out, as_json)
    if as_json:
        print_json(out)


def _demo(out: dict, as_json: bool) -> None:
    for name, fn in (("illustration1", _screws), ("illustration2", _transm),
                     ("puma762_appendix_c", _puma), ("platform_appendix_b", _platform)):
        if as_json:
            with console.capture():
                out[name] = fn()
        else:
            console.rule(f"[bold]{name}")
            out[name] = fn()
