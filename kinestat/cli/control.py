"""``kinestat control``: kinestatic force control of the PUMA 762 + compliant platform cell.

With no device arguments the command starts the Galil simulator and the encoder emitter
itself (loopback TCP and a pty), builds the simulated cell (the thesis's experiment by
default: Vibhute 2011 §5.1) and drives it through the real client and reader. With
``--galil HOST:PORT --serial DEVICE`` it drives real hardware. With ``--arm MODEL`` another
6-joint arm with an analytic solver carries the platform in the in-process simulated cell
(:mod:`kinestat.app.arm_cell`). This module only parses and prints: the options
(:mod:`kinestat.cli._control_params`) become one :class:`~kinestat.control.runspec.RunSpec`
(:func:`kinestat.cli._control_options.run_spec`), which :mod:`kinestat.app.control_run`
assembles and runs.
"""

from __future__ import annotations

import inspect

import typer

from kinestat.app.signals import stop_on_signals
from kinestat.cli import _control_options as opts
from kinestat.cli import _control_output as show
from kinestat.cli._control_params import HELP, PARAMETERS
from kinestat.cli._output import print_json
from kinestat.errors import KinestatError


def register(app: typer.Typer) -> None:
    app.command("control", help=HELP)(control_command)


def control_command(**o) -> None:
    """Kinestatic control (options: :data:`kinestat.cli._control_params.PARAMETERS`)."""
    opts.check_invocation(o)
    spec = opts.run_spec(o)
    # lazy: start-up (the cell loads numba and scipy; `kinestat --help` should not)
    from kinestat.app.control_api import execute
    from kinestat.app.control_run import prepare_control
    from kinestat.cli._compile import warm_cold_kernels

    warm_cold_kernels()  # compiled before the run, so that its timing is the loop's own
    prepared = prepare_control(spec)
    log_path, plot_dir = opts.paths(o["log"], o["plot"], o["no_plot"])
    show.announce(prepared, o)
    live = show.start_live(log_path, o["platform"]) if o["serve"] else None
    # SIGTERM / SIGHUP stop the cell as Ctrl-C does: ST, a fault and an end record, status 2
    with stop_on_signals():
        try:
            out, report = execute(prepared, log_path, plot_dir, progress=show.print_progress,
                                  on_plot_error=show.no_plot)
        except KeyboardInterrupt as exc:  # before or after the loop: nothing was moving
            raise KinestatError(f"kinestat control: {exc or 'interrupted'} before the run "
                                "started or after it ended") from exc
        print_json(out) if o["as_json"] else show.print_report(out)
    if live is not None:
        show.serve_until_interrupted(live)
    elif o["view"] or o["html"] is not None:
        from kinestat.viz.show import show_log  # lazy: viewer only with --view

        show_log(log_path, html=o["html"])
    if not report.converged:
        what = ("the follow task did not complete" if spec.task == "follow"
                else "kinestatic control did not converge")
        raise KinestatError(f"{what}: {report.stop_reason}")


control_command.__signature__ = inspect.Signature(PARAMETERS)
