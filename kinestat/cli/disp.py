"""``kinestat disp``: run a DISP card deck (Nadkarni 1977, App. I) for any MS = 0..6.

By default it behaves as DISP did: first-order steps (eq. 4-11), the deck's own step counts
(IT), every joint nudged at a singular start, a final correction onto the target to the
printed precision for MS 0 and MS 4. kinestat's refinements (settling, closed loop, damping,
second order) are options. ``kinestat guide`` is not an emulator and keeps them on.
"""

from __future__ import annotations

import contextlib
from pathlib import Path

import typer

from kinestat.cli import _guidance
from kinestat.cli._compile import compiling_notice
from kinestat.cli._guidance import (
    SINGULAR_HELP,
    check_cond_limit,
    parse_steps,
    print_result,
    singular_mode,
)
from kinestat.cli._options import (
    STEPS_METAVAR,
    check_output_dir,
    check_output_file,
    command_help,
    flag,
    json_option,
    name_value,
    path_value,
    units,
)
from kinestat.cli._output import console, err_console, literal, print_json, table, to_jsonable
from kinestat.errors import InputError
from kinestat.io.disp_deck import DispDeck, embedded_deck, list_embedded_decks, read_deck

__all__ = ["register", "print_result", "progress_reporter", "load_deck"]


def load_deck(spec: str) -> DispDeck:
    """A deck from a file path, or an embedded deck by name (``illustration5``, ...)."""
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


@contextlib.contextmanager
def progress_reporter(enabled: bool = True):
    """The progress bar of :func:`kinestat.cli._guidance.progress_reporter` on this module's
    ``err_console``."""
    with _guidance.progress_reporter(enabled, err_console) as prog:
        yield prog


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
    deck: str = typer.Argument(..., parser=name_value,
                               help="A DISP deck file, or an embedded deck name "
                               "(illustration1 … illustration7, illustration5-corrected, …)."),
    as_json: bool = json_option(),
    steps: str = typer.Option(None, "--steps", help="Step count N for every stage, or "
                              "N1,N2,… one per stage (command or target); overrides the deck's "
                              "IT. 0 = automatic.", metavar=STEPS_METAVAR),
    settle: bool = flag(False, "--settle", help="Not DISP: after each stage add "
                                "correction steps straight at its target until it is reached "
                                "to 1e-9 (rows marked *)."),
    no_settle: bool = flag(False, "--no-settle", help="No correction steps at all (DISP "
                                   "ended MS 0 and MS 4 runs with correction rows to its "
                                   "printed precision, 0.0005; that is the default there)."),
    closed_loop: bool = flag(False, "--closed-loop", help="Not DISP: correct every "
                                     "step onto the ideal path by Newton iterations "
                                     "(to 1e-9 × the mechanism's size L)."),
    second_order: bool = flag(False, "--second-order", help="Not DISP: include the "
                                      "second-order terms of Nadkarni eq. 5-5 in every step."),
    singular: str = typer.Option("perturb-all", "--singular", help=SINGULAR_HELP),
    damped: bool = flag(False, "--damped", help="Short for --singular damped (not "
                                "DISP)."),
    plot: Path = typer.Option(None, "--plot", parser=path_value,
                              help="Write joints.png and hand-path.png into "
                              "this directory.", metavar="DIR"),
    cond_limit: float = typer.Option(None, "--cond-limit", help="Dimensionless condition "
                                     "number above which a configuration counts as singular "
                                     "(default: DISP's, L / 0.005 for a deck whose hand is "
                                     "given on F10.2 cards: the cards no longer fix the "
                                     "joint increments).", show_default=False),
    disp_1977: bool = flag(False, "--disp-1977", help="MS = 4 only: an inferred step "
                                   "rule for the type III analysis, fitted to Table A2-9 "
                                   "(B from the hand origin's second-order displacement, "
                                   "ceil(dθ°²/40) sub-steps, a final correction step); it "
                                   "reproduces that table with the illustration5-published "
                                   "deck. Not stated in the thesis."),
    view: bool = flag(False, "--view", help="Also open a 3D view in the browser."),
    html: Path = typer.Option(None, "--html", parser=path_value,
                              metavar="FILE", help="With --view: write the "
                              "3D page to FILE (self-contained) instead of opening a browser."),
) -> None:
    """Run a DISP deck (Nadkarni 1977): MS 1 screw axes, 2 mechanism data, 3 both, 0/4/5/6
    guidance of types II/III/IV/I.

    By default this is DISP: first-order steps, the deck's step counts, every joint nudged
    at a singular configuration, and for MS 0 and MS 4 a final correction row (marked *) onto
    each target to the printed precision. Use `kinestat guide` for kinestat's defaults
    (correction steps to 1e-9 at each target).

    Exit status 2 when the run stops early (joint limit, singularity, unreachable target); the
    table up to that point is printed first.
    """
    check_output_file(html, "--html")
    check_output_dir(plot, "--plot")
    check_cond_limit(cond_limit)
    from kinestat.disp import deck_json, disp_options, run_deck  # lazy: start-up (numba)

    d = load_deck(deck)
    if settle and no_settle:
        raise InputError("give --settle or --no-settle, not both")
    correction = "settle" if settle else ("none" if no_settle else None)
    mode = singular_mode(singular, damped, "perturb-all")
    opts = disp_options(closed_loop=closed_loop, second_order=second_order,
                        singular=mode, cond_limit=cond_limit,
                        disp_1977=disp_1977, correction=correction, deck=d)
    with compiling_notice("serial"), progress_reporter(not as_json) as prog:
        run = run_deck(d, steps=parse_steps(steps), options=opts, progress=prog)
    written = []
    if plot is not None and run.result is not None:
        from kinestat.viz.guidance_plots import write_guidance_plots  # lazy: matplotlib

        written = write_guidance_plots(run.result, plot, title=f"DISP MS = {d.ms}: {d.source}")
    if as_json:
        rec = deck_json(run)
        if run.result is not None:
            rec["units"] = units(run.result.model.length_unit)
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
    if (view or html is not None) and run.result is not None:
        from kinestat.viz.show import show_guidance  # lazy: viewer only with --view

        show_guidance(run.result, f"DISP MS = {d.ms}: {d.source}", html=html)
    if run.result is not None:
        run.result.raise_if_stopped()


def register(app: typer.Typer) -> None:
    """Add the ``disp`` command to the ``kinestat`` app."""
    app.command("disp", help=command_help(disp))(disp)
