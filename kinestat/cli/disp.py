"""``kinestat disp``: run a DISP card deck (Nadkarni 1977, App. I) for any MS = 0..6."""

from __future__ import annotations

import contextlib
import math
from pathlib import Path

import numpy as np
import typer

from kinestat.cli._output import console, err_console, literal, print_json, table, to_jsonable
from kinestat.errors import InputError

__all__ = ["register", "print_result", "guidance_options", "progress_reporter", "load_deck"]


def load_deck(spec: str):
    """A deck from a file path, or an embedded deck by name (``illustration5``, ...)."""
    from kinestat.io.disp_deck import embedded_deck, list_embedded_decks, read_deck

    p = Path(spec)
    if p.exists():
        return read_deck(p)
    names = list_embedded_decks()
    key = spec.strip().lower().removesuffix(".dat")
    if key in names:
        return embedded_deck(key)
    raise InputError(
        f"DECK {spec!r} is neither a file nor an embedded deck; embedded decks: "
        f"{', '.join(names)}")


def guidance_options(*, closed_loop: bool, second_order: bool, damped: bool, settle: bool,
                     cond_limit: float, disp_1977: bool = False):
    from kinestat.serial.guidance.run import GuidanceOptions

    kw = dict(closed_loop=closed_loop, second_order=second_order,
              singular="damped" if damped else "perturb", settle=settle, cond_limit=cond_limit)
    return GuidanceOptions.disp_1977(**kw) if disp_1977 else GuidanceOptions(**kw)


@contextlib.contextmanager
def progress_reporter(enabled: bool = True):
    """A ``progress(done, total)`` callback drawing a rich progress bar on stderr when stderr
    is a terminal (None otherwise)."""
    if not (enabled and err_console.is_terminal):
        yield None
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    with Progress(TextColumn("guidance"), BarColumn(), MofNCompleteColumn(),
                  console=err_console, transient=True) as prog:
        task = prog.add_task("steps", total=None)

        def update(done: int, total: int) -> None:
            prog.update(task, completed=done, total=max(total, done))

        yield update


def _fmt_event(ev: dict) -> str:
    skip = {"step", "kind", "stage"}
    parts = []
    for k, v in ev.items():
        if k in skip:
            continue
        if isinstance(v, np.ndarray):
            v = "[" + ", ".join(f"{x:.4g}" for x in v) + "]"
        elif isinstance(v, float):
            v = f"{v:.4g}"
        parts.append(f"{k}={v}")
    return ", ".join(parts)


def print_result(result, notes=(), title: str = "Joint variables") -> None:
    """Human-readable tables of a guidance run (rich)."""
    from kinestat.mechanism.nadkarni import hand_points
    from kinestat.serial.guidance.run import joint_display

    m = result.model
    vals = np.round(joint_display(m, result.q), 3) + 0.0  # no "-0.000"
    cols = ["step"] + [
        (f"r{i + 1} {m.length_unit}" if m.prismatic[i] else f"θ{i + 1} deg") for i in range(m.n)]
    settle = {e["step"] for e in result.events if e["kind"] == "settle"}
    rows = []
    for r in range(vals.shape[0]):
        label = "initial" if r == 0 else (f"{r}*" if r in settle else str(r))
        if r == vals.shape[0] - 1 and r > 0:
            label = "final" + ("*" if r in settle else "")
        rows.append([label, *[float(v) for v in vals[r]]])
    console.print(table(title, cols, rows, fmt="{:.3f}"))
    if result.events:
        ev_rows = [[str(e["step"]), e["kind"], _fmt_event(e)] for e in result.events]
        console.print(table("Events", ["step", "kind", "details"], ev_rows))
    hp = hand_points(result.final_pose)
    dp, da = result.final_pose_error()
    mp, ma = result.max_path_deviation()
    summary = [
        ["steps per stage", ", ".join(str(k) for k in result.steps) +
         (f" (+{result.substeps} sub-steps)" if result.substeps else "")],
        ["final hand origin", ", ".join(f"{v:.4f}" for v in hp[0])],
        ["final hand +z point", ", ".join(f"{v:.4f}" for v in hp[1])],
        ["final hand +x point", ", ".join(f"{v:.4f}" for v in hp[2])],
        ["final pose error", f"{dp:.3g} {m.length_unit}, {math.degrees(da):.3g} deg"],
        ["max deviation from the ideal path", f"{mp:.3g} {m.length_unit}, "
                                               f"{math.degrees(ma):.3g} deg"],
    ]
    if settle:
        summary.append(["rows marked *", "correction steps straight at the stage target"])
    if result.stopped:
        summary.append(["STOPPED", result.stop_message or result.stop_kind or ""])
    for n in notes:
        summary.append(["note", n])
    console.print(table("Summary", ["", ""], summary))


def _print_screws(screws: list[dict]) -> None:
    rows = []
    for s in screws:
        pitch = "inf" if s["pure_translation"] else f"{s['pitch']:.4f}"
        rows.append([f"{s['from_position']}→{s['to_position']}",
                     ", ".join(f"{v:.4f}" for v in s["axis"]),
                     ", ".join(f"{v:.4f}" for v in s["point"]),
                     f"{s['angle_deg']:.3f}", f"{s['translation']:.4f}", pitch])
    console.print(table("Screw axes (SCREWM)", ["positions", "axis U", "point ρn",
                                                 "angle (deg)", "translation d", "pitch"], rows))


def _print_joints(joints: list[dict]) -> None:
    rows = [[str(j["joint"]), *(", ".join(f"{v:.4f}" for v in j[k]) for k in
                                ("origin_star", "origin", "axis", "normal"))] for j in joints]
    console.print(table("Mechanism in the global frame (TRANSM)",
                        ["i", "X*(i)", "X(i)", "U(i)", "ρn(i)"], rows))


def disp(
    deck: str = typer.Argument(..., help="A DISP deck file, or an embedded deck name "
                               "(illustration1 … illustration7, illustration5-corrected, …)."),
    as_json: bool = typer.Option(False, "--json", help="Machine-readable JSON output."),
    steps: str = typer.Option(None, "--steps", help="Step count N for every stage, or "
                              "N1,N2,… one per stage (command or target); overrides the deck's "
                              "IT. 0 = automatic."),
    closed_loop: bool = typer.Option(False, "--closed-loop", help="Correct every step onto "
                                     "the ideal path by Newton iterations (error ≤ 1e-12)."),
    second_order: bool = typer.Option(False, "--second-order", help="Include the second-order "
                                      "terms of Nadkarni eq. 5-5 in every step."),
    damped: bool = typer.Option(False, "--damped", help="At singular configurations use "
                                "damped least squares instead of the thesis's perturbation."),
    plot: Path = typer.Option(None, "--plot", help="Write joints.png and hand-path.png into "
                              "this directory."),
    no_settle: bool = typer.Option(False, "--no-settle", help="Do not add correction steps "
                                   "at the end of a stage to reach its target exactly."),
    cond_limit: float = typer.Option(1e3, "--cond-limit", help="Dimensionless condition "
                                     "number above which a configuration counts as singular."),
    disp_1977: bool = typer.Option(False, "--disp-1977", help="The 1977 program's step rule "
                                   "(B from the hand origin's second-order displacement, "
                                   "ceil(dθ°²/40) sub-steps), which reproduces Table A2-9 with "
                                   "the illustration5-published deck."),
) -> None:
    """Run a DISP deck (Nadkarni 1977): MS 1 screw axes, 2 mechanism data, 3 both, 0/4/5/6
    guidance of types II/III/IV/I.

    Exit status 2 when the run stops early (joint limit, singularity, unreachable target); the
    table up to that point is printed first.
    """
    from kinestat.serial.guidance.disp import deck_json, parse_steps, run_deck

    d = load_deck(deck)
    opts = guidance_options(closed_loop=closed_loop, second_order=second_order, damped=damped,
                            settle=not no_settle, cond_limit=cond_limit, disp_1977=disp_1977)
    with progress_reporter(not as_json) as prog:
        run = run_deck(d, steps=parse_steps(steps), options=opts, progress=prog)
    written = []
    if plot is not None and run.result is not None:
        from kinestat.viz.guidance_plots import write_guidance_plots

        written = write_guidance_plots(run.result, plot, title=f"DISP MS = {d.ms}: {d.source}")
    if as_json:
        rec = deck_json(run)
        if written:
            rec["plots"] = [str(p) for p in written]
        print_json(to_jsonable(rec))
    else:
        console.print(f"[bold]DISP MS = {d.ms}[/bold]: {d.analysis} ({literal(d.source)})")
        if run.screws is not None:
            _print_screws(run.screws)
        if run.joints is not None:
            _print_joints(run.joints)
        if run.result is not None:
            print_result(run.result, run.notes)
        else:
            for n in run.notes:
                console.print(f"note: {literal(n)}")
        for p in written:
            console.print(f"wrote {literal(p)}")
    if run.result is not None:
        run.result.raise_if_stopped()


def register(app: typer.Typer) -> None:
    """Add the ``disp`` command to the ``kinestat`` app."""
    app.command("disp")(disp)
