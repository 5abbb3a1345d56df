"""Helpers shared by ``kinestat disp`` and ``kinestat guide``: ``--steps`` parsing, the progress
bar, the human-readable tables of a guidance run."""

from __future__ import annotations

import contextlib
import math
from typing import TYPE_CHECKING

import numpy as np
import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

from kinestat.cli._output import console, err_console, print_pairs, table
from kinestat.errors import InputError

if TYPE_CHECKING:
    from kinestat.serial.guidance.run import GuidanceResult

__all__ = ["check_cond_limit", "parse_steps", "progress_reporter", "print_result",
           "singular_mode", "SINGULAR_HELP"]

SINGULAR_HELP = ("At a singular configuration: perturb (small increments, one joint at a time, "
                 "greedy), perturb-all (DISP's way: small increments on all joints at once), "
                 "damped (damped least squares) or stop.")


def parse_steps(text: str | None) -> list[int] | int | None:
    """``--steps`` text: ``"40"`` (every stage) or ``"30,12"`` (one per stage); 0 = automatic.

    >>> parse_steps("30, 12")
    [30, 12]
    """
    if text is None or text.strip() == "":
        return None
    try:
        vals = [int(v) for v in text.replace(" ", "").split(",")]
    except ValueError:
        raise InputError(
            f"--steps: expected an integer or comma-separated integers (one per stage), "
            f"got {text!r}") from None
    if any(v < 0 for v in vals):
        raise InputError("--steps: step counts must be ≥ 0 (0 = automatic)")
    return vals[0] if len(vals) == 1 else vals


def check_cond_limit(value: float | None) -> None:
    """``--cond-limit``: a finite condition number > 0 (None: the default), refused before
    the run with the option's name."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise InputError(f"--cond-limit must be a finite number > 0, got {value}")


def singular_mode(text: str, damped: bool, default: str | None = None) -> str:
    """``--singular`` value (``perturb-all`` → ``perturb_all``); ``--damped`` is short for
    ``--singular damped`` and is refused beside another ``--singular`` than the command's
    ``default`` (``--damped --singular stop`` used to run damped without a word).

    >>> singular_mode("perturb", True, "perturb")
    'damped'
    """
    mode = text.strip().lower().replace("-", "_")
    if mode not in ("perturb", "perturb_all", "damped", "stop"):
        raise InputError(f"--singular must be perturb, perturb-all, damped or stop, got {text!r}")
    if damped and mode != "damped" and (default is None or text != default):
        raise InputError(f"--damped is --singular damped: it does not go with --singular {text}")
    return "damped" if damped else mode


@contextlib.contextmanager
def progress_reporter(enabled: bool = True, console_err: Console | None = None):
    """A ``progress(done, total)`` callback drawing a rich progress bar on stderr when stderr
    is a terminal (None otherwise). Ctrl-C inside ends the command with one line saying where
    the run was (``kinestat: interrupted: …``) and status 130, no traceback."""
    con = err_console if console_err is None else console_err
    try:
        with _bar(enabled and con.is_terminal, con) as update:
            yield update
    except KeyboardInterrupt as exc:  # Typer would turn it into a silent exit 130
        where = " ".join(str(exc).split())
        typer.echo(f"kinestat: interrupted{': ' + where if where else ''}", err=True)
        raise typer.Exit(130) from None


@contextlib.contextmanager
def _bar(enabled: bool, con: Console):
    if not enabled:
        yield None
        return
    with Progress(TextColumn("guidance"), BarColumn(), MofNCompleteColumn(),
                  console=con, transient=True) as prog:
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


def print_result(result: GuidanceResult, notes=(), title: str = "Joint variables") -> None:
    """Human-readable tables of a guidance run (rich)."""
    m = result.model
    from kinestat.disp.steps import total_steps  # lazy: start-up (numba)
    from kinestat.mechanism.nadkarni import hand_points  # lazy: start-up (`kinestat --help`)
    from kinestat.serial.guidance.run import joint_display  # lazy: start-up (numba)

    vals = np.round(joint_display(m, result.q), 3) + 0.0  # no "-0.000"
    cols = ["step"] + [
        (f"r{i + 1} {m.length_unit}" if m.prismatic[i] else f"θ{i + 1} deg") for i in range(m.n)]
    settle = result.settle_rows()
    rows = []
    for r in range(vals.shape[0]):
        label = "initial" if r == 0 else (f"{r}*" if r in settle else str(r))
        if r == vals.shape[0] - 1 and r > 0:
            label = "final" + ("*" if r in settle else "")
        rows.append([label, *[float(v) for v in vals[r]]])
    console.print(table(title, cols, rows, fmt="{:.3f}"))
    if result.events:
        ev_rows = [[str(e.step), e.kind, _fmt_event(e.as_dict())] for e in result.events]
        console.print(table("Events", ["step", "kind", "details"], ev_rows))
    hp = hand_points(result.final_pose)
    dp, da = result.final_pose_error()
    mp, ma = result.max_path_deviation()
    summary = [
        ["steps per stage", ", ".join(str(k) for k in result.steps) +
         (f" (+{result.substeps} sub-steps)" if result.substeps else "")],
        ["total steps", f"{total_steps(result)} (path steps, sub-steps and correction rows, "
                        "as Nadkarni's captions count)"],
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
    print_pairs("Summary", summary)
