"""Option parsing for ``kinestat control`` (:mod:`kinestat.cli.control`): each option string
turned into the request's fields, and every refusal made before anything starts or moves."""

from __future__ import annotations

import math
import time
from pathlib import Path

from kinestat.cli._model import load_model
from kinestat.cli._output import parse_floats, parse_pose
from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.devices.ceilings import MAX_SAMPLES
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
    """A new run directory ``base/<timestamp>[-k]``, created here: two runs started in the
    same second each get their own (mkdir is atomic; checking for it first was not, and two
    runs wrote one interleaved log)."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    base.mkdir(parents=True, exist_ok=True)
    k = 1
    while True:
        d = base / (stamp if k == 1 else f"{stamp}-{k}")
        try:
            d.mkdir()
            return d
        except FileExistsError:
            k += 1


def parse_workpiece(text: str | None):
    """``--workpiece``: "plane" (None) or "cylinder:radius=R,axis=x,y,z[,point=x,y,z]" (a
    :class:`~kinestat.app.control_run.CylinderSpec`)."""
    from kinestat.app.control_run import CylinderSpec  # lazy: start-up (numba)

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
          workpiece_stiffness=None):
    """The cell the options describe: simulated (no device options) or the real devices."""
    from kinestat.app.control_run import (  # lazy: start-up (numba)
        PLANTS,
        RealDevices,
        SimulatedCell,
    )

    if sim not in PLANTS:
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
    if cylinder is not None and (plane_point or plane_normal):
        raise InputError("--plane-point/--plane-normal describe a plane workpiece; with "
                         "--workpiece cylinder:... give the cylinder's point= instead")
    if serial_format not in ("ks", "legacy"):
        raise InputError(f"--serial-format must be 'ks' or 'legacy', got {serial_format!r}")
    if ideal_sensor and noise:
        raise InputError("--ideal-sensor and --noise exclude each other")
    if not (math.isfinite(noise) and noise >= 0):
        raise InputError(f"--noise must be >= 0 mm, got {noise}")
    if workpiece_stiffness is not None and not (math.isfinite(workpiece_stiffness)
                                                and workpiece_stiffness > 0):
        raise InputError(f"--workpiece-stiffness must be a finite number of N/mm > 0, got "
                         f"{workpiece_stiffness}")

    if galil is None:
        return SimulatedCell(
            plane_point=parse_floats(plane_point, 3, "plane-point") if plane_point else None,
            plane_normal=parse_floats(plane_normal, 3, "plane-normal") if plane_normal else None,
            friction=friction, ideal_sensor=ideal_sensor, noise=noise, rate_hz=rate, seed=seed,
            sim_legs=sim_legs, cylinder=cylinder, plant=sim,
            workpiece_stiffness=workpiece_stiffness)
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
    """``--tool-offset``, ``--a67`` and ``--mount`` as :class:`ControlRequest` fields."""
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


def check_task_options(task: str, **given) -> None:
    """The follow task's options given to another task: one clear error naming them (they
    would be ignored)."""
    if task != "press":  # follow, or an unknown task (refused with its own error)
        return
    named = [f"--{k.replace('_', '-')}" for k, v in given.items() if v is not None]
    if named:
        raise InputError(f"{', '.join(named)} only apply to --task follow (this run is "
                         f"--task {task})")


def check_counts(samples: int, max_iterations: int | None) -> None:
    """The documented ceilings of --samples and --max-iterations, before anything starts."""
    if not 1 <= samples <= MAX_SAMPLES:
        raise InputError(f"--samples must be in 1..{MAX_SAMPLES} (packets averaged per "
                         f"measurement), got {samples}")
    if max_iterations is not None and not 1 <= max_iterations <= MAX_ITERATIONS:
        raise InputError(f"--max-iterations must be in 1..{MAX_ITERATIONS}, got "
                         f"{max_iterations}")


def check_rate_and_log(rate: float, log: Path | None) -> None:
    """--rate (the simulated encoder's packet rate) and --log (a file, not a directory), before
    anything starts or is printed."""
    from kinestat.sim.encoder_emitter import MAX_RATE_HZ  # lazy: start-up

    if not (math.isfinite(rate) and 0 < rate <= MAX_RATE_HZ):
        raise InputError(f"--rate must be in (0, {MAX_RATE_HZ:g}] Hz, got {rate}")
    if log is not None and log.is_dir():
        raise InputError(f"--log {str(log)!r} is a directory; give the cycle log's file name")


def check_plot_dir(plot: Path | None, no_plot: bool) -> None:
    """--plot names a directory: refuse an existing file before running (as ``disp --plot``)."""
    if plot is not None and not no_plot and plot.exists() and not plot.is_dir():
        raise InputError(f"--plot {str(plot)!r} exists and is not a directory; give a "
                         "directory for the wrench-vs-state plot")
