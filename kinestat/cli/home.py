"""``kinestat home``: the PUMA 762's start-up and homing (Vibhute 2011 App. D.4) on a Galil.

Thin: parses, calls :func:`kinestat.app.homing_run.run_home`, prints. Exit status 0 when
homed, 2 otherwise.
"""

from __future__ import annotations

import time
from pathlib import Path

import typer

from kinestat.app.homing_run import run_home
from kinestat.app.signals import stop_on_signals
from kinestat.cli._options import check_output_file, flag, path_value
from kinestat.cli._output import console, print_json
from kinestat.errors import InputError, KinestatError

MAX_SAMPLES = 1000
"""Ceiling of ``--samples`` (pot readings averaged per axis), as ``kinestat control``'s."""


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
    samples: int = typer.Option(100, "--samples", help=f"Pot readings averaged per axis, "
                                f"1..{MAX_SAMPLES}.", metavar="N"),
    log: Path = typer.Option(None, "--log", parser=path_value,
                             help="Step log, JSON lines (default: "
                             "./kinestat-runs/home-<timestamp>.jsonl).", metavar="FILE"),
    as_json: bool = flag(False, "--json", help="Print the report as JSON."),
) -> None:
    """Power-on checks, pot-based coarse positioning, index search and home definition
    (startup_initialize.m). Refuses (amplifiers off via MO) when a check fails.

    JSON keys: homed, axes, stop_reason, elapsed_s, log.
    """
    host, port = _host_port(galil)
    check_output_file(log, "--log", makes_folders=True)  # the step log makes its folder
    if not 1 <= samples <= MAX_SAMPLES:
        raise InputError(f"--samples must be in 1..{MAX_SAMPLES}, got {samples}")
    log_path = log or Path("kinestat-runs") / f"home-{time.strftime('%Y%m%d-%H%M%S')}.jsonl"
    with stop_on_signals():  # SIGTERM and SIGHUP stop the robot (ST, MO) as Ctrl-C does
        rep = run_home(host, port, log_path, samples=samples)
    out = rep.as_dict()
    out["log"] = str(log_path)
    if as_json:
        print_json(out)
    else:
        if rep.homed:  # a failure's reason is printed once, as the error line below
            console.print(f"PUMA [green]homed[/]: {rep.stop_reason}")
        for ax in rep.axes:
            if "pot_volts" in ax:
                console.print(f"  axis {ax['axis']}: pot {ax['pot_volts']:.4f} V, coarse move "
                              f"{ax['coarse_move']:+d} counts"
                              + (f", now {ax['position']}" if "position" in ax else ""))
        console.print(f"log: {log_path}")
    if not rep.homed:
        raise KinestatError(f"not homed: {rep.stop_reason}")
