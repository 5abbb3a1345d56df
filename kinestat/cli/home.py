"""``kinestat home``: the PUMA 762's start-up and homing (Vibhute 2011 App. D.4) on a Galil.

Thin: parses, calls :func:`kinestat.app.homing_run.run_home`, prints. Exit status 0 when
homed, 2 otherwise.
"""

from __future__ import annotations

import time
from pathlib import Path

import typer

from kinestat.app.homing_run import run_home
from kinestat.cli._options import flag
from kinestat.cli._output import console, err_console, print_json
from kinestat.errors import InputError, KinestatError


def register(app: typer.Typer) -> None:
    app.command("home")(home_command)


def _host_port(text: str) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError(f"--galil: expected HOST:PORT with a port in 1..65535, got {text!r}")
    return host, int(port)


def home_command(
    galil: str = typer.Option(..., "--galil", help="Galil controller HOST:PORT (a real DMC "
                              "or `kinestat sim galil`).", metavar="HOST:PORT"),
    samples: int = typer.Option(100, "--samples", help="Pot readings averaged per axis.",
                                metavar="N"),
    log: Path = typer.Option(None, "--log", help="Step log, JSON lines (default: "
                             "./kinestat-runs/home-<timestamp>.jsonl).", metavar="FILE"),
    as_json: bool = flag(False, "--json", help="Print the report as JSON."),
) -> None:
    """Power-on checks, pot-based coarse positioning, index search and home definition
    (startup_initialize.m). Refuses (amplifiers off via MO) when a check fails.

    JSON keys: homed, axes, stop_reason, elapsed_s, log.
    """
    host, port = _host_port(galil)
    if samples < 1:
        raise InputError(f"--samples must be at least 1, got {samples}")
    log_path = log or Path("kinestat-runs") / f"home-{time.strftime('%Y%m%d-%H%M%S')}.jsonl"
    rep = run_home(host, port, log_path, samples=samples)
    out = rep.as_dict()
    out["log"] = str(log_path)
    if as_json:
        print_json(out)
    else:
        ok = "[green]homed[/]" if rep.homed else "[red]not homed[/]"
        console.print(f"PUMA {ok}: {rep.stop_reason}")
        for ax in rep.axes:
            if "pot_volts" in ax:
                console.print(f"  axis {ax['axis']}: pot {ax['pot_volts']:.4f} V, coarse move "
                              f"{ax['coarse_move']:+d} counts"
                              + (f", now {ax['position']}" if "position" in ax else ""))
        console.print(f"log: {log_path}")
    if not rep.homed:
        err_console.print(f"[red]not homed[/]: {rep.stop_reason}")
        raise KinestatError(f"not homed: {rep.stop_reason}")
