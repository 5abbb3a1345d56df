"""``kinestat sim``: stand-ins for the cell's hardware (Galil DMC simulator, encoder emitter)."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import typer

from kinestat.app.signals import stop_on_signals
from kinestat.cli._options import check_seed, flag, name_value
from kinestat.cli._output import console, literal, parse_floats, print_json
from kinestat.errors import InputError
from kinestat.hardware.encoder_packets import (
    CHANNELS,
    COUNT_MAX,
    COUNT_MIN,
    THESIS_WIRING,
    legs_to_channels,
)
from kinestat.sim.dmc import DmcSimulator
from kinestat.sim.encoder_emitter import EncoderEmitter, constant_counts
from kinestat.sim.galil_server import GalilSimServer

sim_app = typer.Typer(help="Simulated hardware: the Galil DMC controller and the platform's "
                           "encoder stream.", no_args_is_help=True)


def _check_duration(duration: float | None) -> None:
    if duration is not None and (duration < 0 or duration != duration):
        raise InputError(f"--duration must be >= 0 seconds, got {duration}")


def _int_counts(text: str, option: str) -> np.ndarray:
    """Six whole encoder counts within the signed 32-bit range both protocols carry."""
    vals = parse_floats(text, 6, option)
    if any(v != int(v) for v in vals):
        raise InputError(f"--{option} must be integers, got {text!r}")
    if np.any(vals < COUNT_MIN) or np.any(vals > COUNT_MAX):
        raise InputError(f"--{option} must lie in [{COUNT_MIN}, {COUNT_MAX}] (signed 32-bit), "
                         f"got {text!r}")
    return vals


@contextmanager
def _until_stopped() -> Iterator[None]:
    """Ctrl-C, SIGTERM and SIGHUP end the block quietly
    (:func:`kinestat.app.signals.stop_on_signals`): installed BEFORE a simulator announces
    its address, so a signal sent as soon as it is announced is handled, and the ``with``
    blocks inside close the simulators' sockets and pty."""
    with stop_on_signals():
        try:
            yield
        except KeyboardInterrupt:  # Ctrl-C, or StopRequested (SIGTERM / SIGHUP)
            pass


def _run_until_stopped(duration: float | None, stop_event: threading.Event | None = None) -> None:
    """Block until ``duration`` seconds pass (forever if None) or ``stop_event`` is set; a
    signal ends it through :func:`_until_stopped`."""
    _check_duration(duration)
    ev = stop_event or threading.Event()
    t_end = None if duration is None else time.monotonic() + duration
    while not ev.is_set():
        left = None if t_end is None else t_end - time.monotonic()
        if left is not None and left <= 0:
            break
        ev.wait(0.2 if left is None else min(0.2, left))


@sim_app.command("galil")
def galil(
    port: int = typer.Option(0, "--port", help="TCP port (0: any free port; the real "
                             "controller uses 23)."),
    host: str = typer.Option("127.0.0.1", "--host", help="Address to bind (loopback only, "
                             "unless --allow-remote)."),
    allow_remote: bool = flag(False, "--allow-remote", help="Allow a non-loopback "
                                      "address: anyone who can reach it can command motion."),
    initial_counts: str = typer.Option("0,0,0,0,0,0", "--initial-counts",
                                       help="Encoder counts of axes A..F at start."),
    no_coupling: bool = flag(False, "--no-coupling", help="Disable the axis 4 -> 5 "
                                     "coupling of the thesis's PUMA."),
    duration: float = typer.Option(None, "--duration", help="Stop after this many seconds "
                                   "(default: run until Ctrl-C)."),
    seed: int = typer.Option(None, "--seed", help="Start the robot at an arbitrary, unknown "
                             "position drawn with this seed (encoders read 0 at power-up; "
                             "home it with `kinestat home`)."),
    as_json: bool = flag(False, "--json", help="Print the address as JSON."),
    plant: str = typer.Option(
        "none", "--plant", metavar="none|mujoco",
        help="'mujoco': the Galil drives a MuJoCo cell (the arm, the platform, the workpiece) "
        "and an encoder stream on a pty reads its legs, for `kinestat control --galil "
        "--serial` (the cell's options below; docs/mujoco.md)."),
    start: str = typer.Option(None, "--start", help="--plant mujoco: the start tool point "
                              "(mm), where the robot is placed (default as kinestat control)."),
    direction: str = typer.Option(None, "--direction", help="--plant mujoco: the force's "
                                  "direction (places the default workpiece and the start)."),
    friction: float = typer.Option(0.0, "--friction", help="--plant mujoco: Coulomb friction "
                                   "of the workpiece."),
    workpiece: str = typer.Option(None, "--workpiece", help="--plant mujoco: "
                                  "cylinder:radius=R,axis=x,y,z[,point=x,y,z] (default a plane)."),
    plane_point: str = typer.Option(None, "--plane-point", help="--plant mujoco: a point of "
                                    "the plane workpiece (mm)."),
    plane_normal: str = typer.Option(None, "--plane-normal", help="--plant mujoco: the plane's "
                                     "outward normal."),
    sim_legs: str = typer.Option("thesis", "--sim-legs", parser=name_value,
                                 help="--plant mujoco: the legs' TRUE "
                                 "law ('thesis', 'nominal' or a calibration TOML file)."),
    rate: float = typer.Option(200.0, "--rate", help="--plant mujoco: encoder packets per "
                               "second."),
) -> None:
    """Run a simulated Galil DMC (six axes, trapezoidal profiles) until Ctrl-C."""
    _check_duration(duration)
    check_seed(seed)
    if not 0 <= port <= 65535:
        raise InputError(f"--port must be 0..65535 (0: any free port), got {port}")
    if not 0 < rate <= 5000:  # also refuses NaN; checked with either plant
        raise InputError(f"--rate must be in (0, 5000] packets per second, got {rate}")
    if plant not in ("none", "mujoco"):
        raise InputError(f"--plant must be 'none' or 'mujoco', got {plant!r}")
    if plant == "mujoco":
        if seed is not None or initial_counts != "0,0,0,0,0,0" or no_coupling:
            raise InputError("--plant mujoco places the robot at the start pose of the cell "
                             "(--start, --direction); --seed, --initial-counts and "
                             "--no-coupling do not apply")
        _galil_mujoco(host, port, allow_remote, duration, as_json,
                      dict(start=start, direction=direction, friction=friction,
                           workpiece=workpiece, plane_point=plane_point,
                           plane_normal=plane_normal, sim_legs=sim_legs, rate=rate))
        return
    cell_opts = {"--start": start, "--direction": direction, "--workpiece": workpiece,
                 "--plane-point": plane_point, "--plane-normal": plane_normal}
    given = [k for k, v in cell_opts.items() if v is not None]
    if given or friction or sim_legs != "thesis":
        raise InputError(f"{', '.join(given) or '--friction/--sim-legs'}: options of "
                         "--plant mujoco")
    c0 = _int_counts(initial_counts, "initial-counts")
    kw = {"coupling": 0.0} if no_coupling else {}
    if seed is not None:
        if initial_counts != "0,0,0,0,0,0":
            raise InputError("--seed (an unknown start) and --initial-counts exclude each other")
        ctrl = DmcSimulator.unknown_start(seed, **kw)
    else:
        ctrl = DmcSimulator(initial_counts=c0, **kw)
    server = GalilSimServer(host, port, allow_remote=allow_remote, controller=ctrl)
    with _until_stopped(), server:
        if as_json:
            print_json({"host": server.host, "port": server.port, "axes": "ABCDEF"})
        else:
            console.print(f"Galil DMC simulator listening on {literal(server.host)}:{server.port} "
                          "(axes A-F). Ctrl-C to stop.")
        _run_until_stopped(duration)
    if not as_json:
        console.print("Galil DMC simulator stopped.")


@sim_app.command("encoders")
def encoders(
    rate: float = typer.Option(100.0, "--rate", help="Packets per second."),
    counts: str = typer.Option("0,0,0,0,0,0", "--counts",
                               help="Constant leg counts, legs 1..6 (a,b,c,d,e,f)."),
    fmt: str = typer.Option("ks", "--format", help="'ks' (framed, checksummed) or 'legacy' "
                            "(the thesis's 23-byte line)."),
    duration: float = typer.Option(None, "--duration", help="Stop after this many seconds "
                                   "(default: run until Ctrl-C)."),
    as_json: bool = flag(False, "--json", help="Print the pty path as JSON."),
) -> None:
    """Stream encoder packets onto a pseudo-terminal and print its path until Ctrl-C."""
    _check_duration(duration)
    if fmt not in ("ks", "legacy"):
        raise InputError(f"--format must be 'ks' or 'legacy', got {fmt!r}")
    if not 0 < rate <= 5000:  # also refuses NaN
        raise InputError(f"--rate must be in (0, 5000] packets per second, got {rate}")
    # legacy lines carry 16 bits and wrap, as the thesis's counters did
    legs = _int_counts(counts, "counts")
    emitter = EncoderEmitter(constant_counts(legs), rate_hz=rate, fmt=fmt)
    with _until_stopped(), emitter:
        channels = legs_to_channels(legs.astype(int)).tolist()
        if as_json:
            print_json({"path": emitter.path, "rate_hz": rate, "format": fmt,
                        "leg_counts": legs.astype(int).tolist(),
                        "channel_counts": dict(zip(CHANNELS, channels, strict=True))})
        else:
            console.print(f"Encoder stream ({fmt}, {rate:g} Hz) on {literal(emitter.path)} — "
                          "open it at 115200 baud. Ctrl-C to stop.")
            console.print("channels " + ", ".join(
                f"{c}=leg {w}: {v}" for c, w, v in zip(CHANNELS, THESIS_WIRING, channels,
                                                        strict=True)))
        _run_until_stopped(duration)
        if emitter.error is not None:
            raise InputError(f"the encoder emitter stopped: {emitter.error}")
    if not as_json:
        console.print(f"Encoder emitter stopped after {emitter.sent} packets.")


def _galil_mujoco(host: str, port: int, allow_remote: bool, duration: float | None,
                  as_json: bool, opts: dict) -> None:
    """The simulated Galil and encoder stream on a MuJoCo cell, until Ctrl-C."""
    # lazy: the cell (numba, scipy, mujoco) only for --plant mujoco
    from kinestat.app.control_defaults import DEFAULT_DIRECTION, DEFAULT_START  # lazy: as above
    from kinestat.app.control_run import ControlRequest, prepare_control  # lazy: as above
    from kinestat.app.mujoco_harness import MujocoHarness  # lazy: mujoco
    from kinestat.app.sim_cell import start_counts  # lazy: as above
    from kinestat.cli._control_options import cell as sim_cell  # lazy: as above

    d = parse_floats(opts["direction"] or DEFAULT_DIRECTION, 3, "direction")
    if not np.linalg.norm(d) > 0:
        raise InputError("--direction must not be the zero vector")
    p0 = parse_floats(opts["start"] or DEFAULT_START, 3, "start")
    if not (0 < opts["rate"] <= 5000):
        raise InputError(f"--rate must be in (0, 5000] packets per second, got {opts['rate']}")
    cell = sim_cell(None, None, "ks", opts["plane_point"], opts["plane_normal"], False, 0.0,
                    opts["friction"], opts["rate"], 0, opts["sim_legs"], opts["workpiece"],
                    "mujoco")
    prep = prepare_control(ControlRequest(force=4.0 * d / np.linalg.norm(d),
                                          start_tool_point=p0, cell=cell))
    harness = MujocoHarness(prep.plant, prep.config.model, prep.sensor,
                            start_counts=start_counts(prep.config), host=host, port=port,
                            allow_remote=allow_remote, rate_hz=opts["rate"])
    with _until_stopped(), harness:
        info = harness.describe()
        if as_json:
            print_json(dict(info, axes="ABCDEF"))
        else:
            console.print(f"Galil DMC simulator on a MuJoCo cell: {literal(info['galil'])}, "
                          f"encoder stream on {literal(info['serial'])}. Ctrl-C to stop.")
        _run_until_stopped(duration)
    if harness.error is not None:
        raise InputError(f"the MuJoCo cell stopped: {harness.error}")


def register(app: typer.Typer) -> None:
    """Add the ``sim`` command group."""
    app.add_typer(sim_app, name="sim")
