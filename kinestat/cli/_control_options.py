"""Option parsing for ``kinestat control`` (:mod:`kinestat.cli.control`): each option string
turned into the request's fields, and every refusal made before anything starts or moves."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from kinestat.cli._model import load_model
from kinestat.cli._options import check_output_dir, check_output_file, check_seed
from kinestat.cli._output import parse_floats, parse_pose
from kinestat.control.defaults import PLANTS
from kinestat.errors import InputError


def host_port(text: str) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep or not host:
        raise InputError(f"--galil: expected HOST:PORT, got {text!r}")
    try:
        p = int(port)
    except ValueError as exc:
        raise InputError(f"--galil: port {port!r} is not a number") from exc
    if not 0 < p < 65536:
        raise InputError(f"--galil: port {p} outside 1..65535")
    return host, p


def run_dir(base: Path) -> Path:
    """A new run directory (:func:`kinestat.app.control_api.run_dir`)."""
    from kinestat.app.control_api import run_dir as claim  # lazy: start-up (numba)

    return claim(base)


def parse_workpiece(text: str | None):
    """``--workpiece``: "plane" (None) or "cylinder:radius=R,axis=x,y,z[,point=x,y,z]" (a
    :class:`~kinestat.app.control_run.CylinderSpec`)."""
    from kinestat.control.runspec import CylinderSpec  # lazy: start-up (numba)

    if text is None or text.strip() == "plane":
        return None
    kind, sep, rest = text.partition(":")
    if kind.strip() != "cylinder" or not sep:
        raise InputError(f"--workpiece: expected 'plane' or 'cylinder:radius=R,axis=x,y,z"
                         f"[,point=x,y,z]', got {text!r}")
    fields: dict[str, list[str]] = {}
    key = None
    for tok in rest.split(","):
        name, eq, val = tok.partition("=")
        if eq:
            key = name.strip()
            if key not in ("radius", "axis", "point") or key in fields:
                raise InputError(f"--workpiece: unknown or repeated field {key!r} in {text!r}")
            fields[key] = [val]
        elif key is None:
            raise InputError(f"--workpiece: expected name=value after 'cylinder:', got {text!r}")
        else:
            fields[key].append(tok)
    if "radius" not in fields or "axis" not in fields:
        raise InputError(f"--workpiece: a cylinder needs radius= and axis=, got {text!r}")
    radius = parse_floats(",".join(fields["radius"]), 1, "workpiece radius")[0]
    axis = parse_floats(",".join(fields["axis"]), 3, "workpiece axis")
    point = (parse_floats(",".join(fields["point"]), 3, "workpiece point")
             if "point" in fields else None)
    return CylinderSpec(radius=float(radius), axis=axis, point=point)


def cell(galil, serial, serial_format, plane_point, plane_normal, ideal_sensor, noise, friction,
          rate, seed, sim_legs="thesis", workpiece=None, sim="kinestat",
          workpiece_stiffness=None, top_weight=False):
    """The cell the options describe: simulated (no device options) or the real devices."""
    from kinestat.control.runspec import (  # lazy: start-up (numba)
        SERIAL_FORMATS,
        RealDevices,
        SimulatedCell,
    )

    if serial_format not in SERIAL_FORMATS:  # checked with the simulated cell too
        raise InputError(f"--serial-format must be one of {', '.join(SERIAL_FORMATS)}, got "
                         f"{serial_format!r}")

    if sim not in PLANTS:  # before the next check names --sim's other values
        raise InputError(f"--sim must be one of {', '.join(PLANTS)}, got {sim!r}")
    if galil is not None and sim != "kinestat":
        raise InputError("--sim chooses the simulated cell's physics; with real devices "
                         "(--galil/--serial) run `kinestat sim galil --plant mujoco` and give "
                         "its addresses instead")

    if (galil is None) != (serial is None):
        raise InputError("give both --galil HOST:PORT and --serial DEVICE for real devices, or "
                         "neither to run the simulated cell")
    if galil is not None and (plane_point or plane_normal or ideal_sensor or noise or friction
                              or sim_legs != "thesis" or workpiece is not None
                              or workpiece_stiffness is not None):
        raise InputError("--plane-point/--plane-normal/--ideal-sensor/--noise/--friction/"
                         "--sim-legs/--workpiece/--workpiece-stiffness describe the simulated "
                         "cell; they cannot be used "
                         "with real devices")
    cylinder = parse_workpiece(workpiece)
    if galil is None:
        return SimulatedCell(
            plane_point=parse_floats(plane_point, 3, "plane-point") if plane_point else None,
            plane_normal=parse_floats(plane_normal, 3, "plane-normal") if plane_normal else None,
            friction=friction, ideal_sensor=ideal_sensor, noise=noise, rate_hz=rate, seed=seed,
            sim_legs=sim_legs, cylinder=cylinder, plant=sim,
            workpiece_stiffness=workpiece_stiffness, top_weight=top_weight)
    host, port = host_port(galil)
    return RealDevices(host=host, port=port, serial=serial, serial_format=serial_format)


THESIS_ARM_NAME = "puma762"
"""``--arm`` naming the thesis's PUMA 762 (the default): today's cell, Galil and encoders."""


def arm(arm, tip, base, scale, length_unit, arm_base, galil, serial):
    """The ``--arm`` of the run (an :class:`~kinestat.app.arm_cell.ArmSpec`), or None for the
    thesis's PUMA 762; every refusal before anything is loaded or moves."""
    urdf = [o for o, v in (("--tip", tip), ("--base", base), ("--scale", scale),
                           ("--length-unit", length_unit)) if v is not None]
    if arm is None:
        if urdf or arm_base is not None:
            raise InputError(f"{'/'.join(urdf + (['--arm-base'] if arm_base else []))}: "
                             "options of --arm MODEL; give --arm")
        return None
    if arm == THESIS_ARM_NAME and not urdf:
        if arm_base is not None:
            raise InputError("--arm-base: the thesis's PUMA 762 is the cell's fixed frame; "
                             "--arm-base places another arm")
        return None
    if galil is not None or serial is not None:
        raise InputError(f"--arm {arm}: another arm runs on the in-process simulated cell "
                         "only; the Galil and encoder protocols are the PUMA 762's hardware "
                         "(drop --galil/--serial)")
    from kinestat.app.arm_cell import ArmSpec  # lazy: start-up (numba)

    b = None if arm_base is None else parse_floats(arm_base, 3, "arm-base")
    return ArmSpec(model=load_model(arm, tip, base, scale, length_unit), base=b, name=arm)


def tool_and_mount(tool_offset: str | None, a67: str | None, mount: str | None) -> dict:
    """``--tool-offset``, ``--a67`` and ``--mount`` as :class:`RunSpec` fields."""
    out: dict = {}
    if tool_offset is not None:
        out["tool_point_6"] = parse_floats(tool_offset, 3, "tool-offset")
    if a67 is not None:
        out["a67"] = parse_floats(a67, 3, "a67")
    if mount is not None:
        text = mount.strip()
        if text in ("centred", "centered") or (Path(text).suffix.lower() == ".toml"
                                              and Path(text).is_file()):
            out["mount"] = text
        else:
            out["mount"] = parse_pose(text, "mount")
    return out


def check_rate_and_log(rate: float, log: Path | None) -> None:
    """--rate (the simulated encoder's packet rate) and --log (a file, not a directory), before
    anything starts or is printed."""
    from kinestat.sim.encoder_emitter import MAX_RATE_HZ  # lazy: start-up

    if not (math.isfinite(rate) and 0 < rate <= MAX_RATE_HZ):
        raise InputError(f"--rate must be in (0, {MAX_RATE_HZ:g}] Hz, got {rate}")
    check_output_file(log, "--log", makes_folders=True)  # the cycle log makes its folder


def check_plot_dir(plot: Path | None, no_plot: bool) -> None:
    """--plot names a directory that can be written (as ``disp --plot``), and does not go with
    --no-plot: refused before running."""
    if plot is not None and no_plot:
        raise InputError("give --plot DIR or --no-plot, not both")
    check_output_dir(plot, "--plot")


def check_invocation(o: dict) -> None:
    """The options about the command itself (outputs, viewer, seed), before anything starts."""
    check_seed(o["seed"])
    check_plot_dir(o["plot"], o["no_plot"])
    check_rate_and_log(o["rate"], o["log"])
    check_output_file(o["html"], "--html")
    if o["serve"] and (not o["view"] or o["html"] is not None):
        raise InputError("--serve goes with --view (and not with --html)")


def direction(o: dict) -> np.ndarray:
    """``--direction`` as a unit vector."""
    d = parse_floats(o["direction"], 3, "direction")
    if np.linalg.norm(d) == 0:
        raise InputError("--direction must not be the zero vector")
    return d / np.linalg.norm(d)


def run_spec(o: dict):
    """The :class:`~kinestat.control.runspec.RunSpec` of the options ``o`` (every setting
    checked there once)."""
    force = o["force"]
    if not (math.isfinite(force) and force > 0):
        raise InputError(f"--force must be a positive number of newtons, got {force}")
    d, p0 = direction(o), parse_floats(o["start"], 3, "start")
    from kinestat.control.runspec import RunSpec  # lazy: start-up (numba)

    same = ("force_tol", "align_tol_deg", "method", "step", "approach_step", "estimator",
            "samples", "max_iterations", "calibration", "platform", "procedure", "move_rule",
            "assume_homed", "task", "travel", "travel_step", "tilt_deg", "auto_tilt",
            "probe_span", "max_approach")
    travel_dir = o["travel_dir"]
    return RunSpec(
        force=force * d, start_tool_point=p0, **{k: o[k] for k in same},
        travel_dir=None if travel_dir is None else parse_floats(travel_dir, 3, "travel-dir"),
        arm=arm(o["arm"], o["tip"], o["base"], o["scale"], o["length_unit"], o["arm_base"],
                o["galil"], o["serial"]),
        cell=cell(o["galil"], o["serial"], o["serial_format"], o["plane_point"],
                  o["plane_normal"], o["ideal_sensor"], o["noise"], o["friction"], o["rate"],
                  o["seed"], o["sim_legs"], o["workpiece"], o["sim"],
                  o["workpiece_stiffness"], o["top_weight"]),
        top_mass=o["top_mass"], **tool_and_mount(o["tool_offset"], o["a67"], o["mount"]))


def paths(log: Path | None, plot: Path | None, no_plot: bool) -> tuple[Path, Path | None]:
    """The cycle log's path and the plots' directory (None: no plots); the run directory
    ``kinestat-runs/<timestamp>`` is claimed only when one of them needs it."""
    run_directory = None
    if log is None or (plot is None and not no_plot):
        run_directory = run_dir(Path("kinestat-runs"))
    log_path = log if log is not None else run_directory / "log.jsonl"
    return log_path, None if no_plot else (plot if plot is not None else run_directory)
