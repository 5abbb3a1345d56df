"""One run of ``kinestat control`` as one frozen value: :class:`RunSpec`.

The command line's options, the Python API and the scripts describe a run the same way: a
:class:`RunSpec` — the goal, the task and its settings, the controller's settings, the tool
and mount, and the cell (:class:`SimulatedCell` or :class:`RealDevices`). Its defaults are
written here once, and every setting is checked here once, when the spec is made: a bad value
is one :class:`~kinestat.errors.InputError` naming the setting (by its command-line option)
before anything is built or moves. The cell factory
(:func:`kinestat.app.control_run.prepare_control`) turns a spec into the cell, the
controller's settings and the task; the loop (:func:`kinestat.control.loop.run`) runs it.
In Python, :func:`kinestat.app.run` does both::

    from kinestat.app import run
    from kinestat.control import RunSpec
    report = run(RunSpec(task="follow", travel=20.0))   # the JSON report as a dict

Defaults that depend on the task are resolved here too: ``approach_step`` (1 mm for the press,
0.25 mm for follow: its first contact force stays below 3 N), ``max_iterations`` (60 for the
press, :data:`~kinestat.control.ceilings.MAX_ITERATIONS` for follow) and the follow task's
``travel`` (50 mm), ``travel_step`` (1 mm), ``tilt_deg`` (0) and ``probe_span``
(:attr:`~kinestat.control.probe.ProbeTuning.span_mm`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.control.controller import ESTIMATORS, METHODS, PROCEDURES, Procedure, StepMethod
from kinestat.control.defaults import PLANTS, RUN_DEFAULTS, TASKS
from kinestat.control.probe import PROBE_TUNING
from kinestat.control.wrench import Estimator
from kinestat.errors import InputError

#: ``--serial-format``: the encoder box's packet formats (kinestat's "ks", the thesis's "legacy")
SERIAL_FORMATS = ("ks", "legacy")

__all__ = ["RunSpec", "SimulatedCell", "RealDevices", "CylinderSpec", "TASKS", "PLANTS"]

def _floats(text: str) -> np.ndarray:
    return np.array([float(x) for x in text.split(",")])


def _default_force() -> np.ndarray:
    d = _floats(RUN_DEFAULTS.direction)
    return RUN_DEFAULTS.force * d / np.linalg.norm(d)


def _vec3(v, option: str, *, nonzero: bool = False) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or (nonzero and not np.any(a)):
        what = "a nonzero vector of 3 finite numbers" if nonzero else "3 finite numbers"
        raise InputError(f"{option} must be {what}, got {np.asarray(v).tolist()}")
    return a.copy()


def _positive(value, option: str, unit: str) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise InputError(f"{option} must be a positive number of {unit}, got {value}")


@dataclass(frozen=True, eq=False)
class CylinderSpec:
    """A simulated cylindrical workpiece: ``radius`` (mm), ``axis`` direction and, optionally,
    a ``point`` on its axis (default: its surface 2.5 mm ahead of the start tool point along
    F_req, as the default plane)."""

    radius: float
    axis: np.ndarray
    point: np.ndarray | None = None

    def __post_init__(self) -> None:
        _positive(self.radius, "--workpiece radius", "mm")
        object.__setattr__(self, "axis", _vec3(self.axis, "--workpiece axis", nonzero=True))
        if self.point is not None:
            object.__setattr__(self, "point", _vec3(self.point, "--workpiece point"))


@dataclass(frozen=True, eq=False)
class SimulatedCell:
    """Settings of the simulated cell (``kinestat control`` without devices).

    ``cylinder`` None: a plane workpiece; ``plane_point``/``plane_normal`` None: 2.5 mm ahead
    of the start tool point, its normal −F_req tilted by 5°
    (:func:`kinestat.app.control_run.default_plane`). ``plant``: "kinestat" (the built-in
    contact simulator behind the simulated devices) or "mujoco"
    (:mod:`kinestat.app.mujoco_cell`, in process). ``workpiece_stiffness``: the workpiece's
    normal stiffness (N/mm, :attr:`kinestat.sim.contact.Workpiece.stiffness`; None: rigid).
    ``noise``: leg-length noise (mm, standard deviation); ``ideal_sensor``: 1 nm leg
    encoders; ``rate_hz``: packet rate; ``sim_legs``: the legs' true law. ``top_weight``
    (MuJoCo only): gravity on the top plate + tool, whose weight and centre of mass the
    controller is then given (:mod:`kinestat.control.payload`).
    """

    plane_point: np.ndarray | None = None
    plane_normal: np.ndarray | None = None
    friction: float = 0.0
    ideal_sensor: bool = False
    noise: float = 0.0
    rate_hz: float = RUN_DEFAULTS.rate_hz
    seed: int = 0
    sim_legs: str = "thesis"
    cylinder: CylinderSpec | None = None
    plant: str = "kinestat"
    workpiece_stiffness: float | None = None
    top_weight: bool = False

    def __post_init__(self) -> None:
        if self.plant not in PLANTS:
            raise InputError(f"--sim must be one of {', '.join(PLANTS)}, got {self.plant!r}")
        if self.top_weight and self.plant != "mujoco":
            raise InputError("--top-weight needs --sim mujoco: the built-in simulator's top "
                             "plate and tool are weightless, as the thesis's model")
        if self.cylinder is not None and (self.plane_point is not None
                                          or self.plane_normal is not None):
            raise InputError("--plane-point/--plane-normal describe a plane workpiece; with "
                             "--workpiece cylinder:... give the cylinder's point= instead")
        for name in ("plane_point", "plane_normal"):
            if getattr(self, name) is not None:
                option = "--" + name.replace("_", "-")
                object.__setattr__(self, name, _vec3(getattr(self, name), option,
                                                     nonzero=name == "plane_normal"))
        if self.ideal_sensor and self.noise:
            raise InputError("--ideal-sensor and --noise exclude each other")
        if not (math.isfinite(self.noise) and self.noise >= 0):
            raise InputError(f"--noise must be >= 0 mm, got {self.noise}")
        if not (math.isfinite(self.friction) and self.friction >= 0):
            raise InputError(f"--friction must be a coefficient >= 0, got {self.friction}")
        if self.workpiece_stiffness is not None and not (
                math.isfinite(self.workpiece_stiffness) and self.workpiece_stiffness > 0):
            raise InputError(f"--workpiece-stiffness must be a finite number of N/mm > 0, got "
                             f"{self.workpiece_stiffness}")
        if not (isinstance(self.seed, (int, np.integer)) and self.seed >= 0):
            raise InputError(f"--seed must be a non-negative integer, got {self.seed}")
        _positive(self.rate_hz, "--rate", "Hz")


@dataclass(frozen=True)
class RealDevices:
    """The real cell: the Galil at ``host``:``port``, the encoder stream on ``serial`` in
    packet format ``serial_format`` ("ks" or the thesis's "legacy")."""

    host: str
    port: int
    serial: str
    serial_format: str = "ks"

    def __post_init__(self) -> None:
        if not 0 < self.port < 65536:
            raise InputError(f"--galil: port {self.port} outside 1..65535")
        if self.serial_format not in SERIAL_FORMATS:
            raise InputError(f"--serial-format must be 'ks' or 'legacy', got "
                             f"{self.serial_format!r}")


@dataclass(frozen=True, eq=False)
class RunSpec:
    """One ``kinestat control`` run: the goal, the task, the controller's settings and the cell.

    Attributes (the command line's option in brackets; units as there):
        force: (3,) ``F_req`` (N, fixed frame): its magnitude the target force, its direction
            the approach and the start pose's S6 [--force times the unit --direction].
        start_tool_point: (3,) the start tool point ``P_tool_F`` (mm) [--start].
        cell: :class:`SimulatedCell` (default) or :class:`RealDevices` [--galil/--serial].
        task: "press" or "follow" [--task]; procedure: "kinestat" or "thesis" (the press's
            procedure) [--procedure].
        force_tol (N), align_tol_deg (degrees), method, step (mm), approach_step (mm),
            estimator, max_iterations, max_approach (mm): the controller's settings
            (:class:`~kinestat.control.controller.ControllerConfig`).
        samples: sensor packets averaged per measurement; move_rule: the moves' axis speeds;
            assume_homed: move a real robot not homed in this session.
        calibration, platform: the controller's leg calibration and platform file.
        travel, travel_dir, travel_step, tilt_deg, auto_tilt, probe_span: the follow task's
            settings (:class:`~kinestat.control.follow.FollowConfig`); refused for the press.
        arm: another arm (:class:`~kinestat.app.arm_cell.ArmSpec`; None the PUMA 762).
        tool_point_6 (mm, frame 6), a67 (unit, ⟂ S6), mount: the tool and the platform's
            mount on the flange [--tool-offset, --a67, --mount].
        top_mass: kg, the top plate + tool's moving mass [--top-mass]
            (:attr:`~kinestat.control.model.ControlModel.top_mass`); None: 0 (the thesis's
            massless model), or the MuJoCo scene's with ``--sim mujoco``, which it also sets.
    """

    force: np.ndarray = field(default_factory=lambda: _default_force())
    start_tool_point: np.ndarray = field(default_factory=lambda: _floats(RUN_DEFAULTS.start))
    cell: SimulatedCell | RealDevices = field(default_factory=SimulatedCell)
    force_tol: float = RUN_DEFAULTS.force_tol
    align_tol_deg: float = RUN_DEFAULTS.align_tol_deg
    method: StepMethod = "stiffness"
    step: float = RUN_DEFAULTS.step
    approach_step: float | None = None
    estimator: Estimator = "point"
    samples: int = 1
    max_iterations: int | None = None
    calibration: str = "thesis"
    platform: str | None = None
    procedure: Procedure = "kinestat"
    move_rule: str = "coordinated"
    assume_homed: bool = False
    task: str = "press"
    travel: float | None = None
    travel_dir: np.ndarray | None = None
    travel_step: float | None = None
    tilt_deg: float | None = None
    auto_tilt: bool | None = None
    arm: Any = None
    probe_span: float | None = None
    max_approach: float = RUN_DEFAULTS.max_approach
    tool_point_6: np.ndarray | None = None
    a67: np.ndarray | None = None
    mount: Any = None
    top_mass: float | None = None

    def __post_init__(self) -> None:
        self._check_goal()
        self._check_task()
        self._check_controller()
        if not isinstance(self.cell, (SimulatedCell, RealDevices)):
            raise InputError(f"cell must be a SimulatedCell or RealDevices, got "
                             f"{type(self.cell).__name__}")
        if isinstance(self.cell, RealDevices) and self.arm is not None:
            raise InputError("--arm: another arm runs on the in-process simulated cell only; "
                             "the Galil and encoder protocols are the PUMA 762's hardware "
                             "(drop --galil/--serial)")
        if self.tool_point_6 is not None:
            self._set("tool_point_6", _vec3(self.tool_point_6, "--tool-offset"))
        if self.top_mass is not None:
            m = self.top_mass
            if isinstance(m, bool) or not isinstance(m, (int, float)) or not (
                    math.isfinite(m) and m >= 0):
                raise InputError(f"--top-mass must be a number of kg >= 0, got {m!r}")
            self._set("top_mass", float(m))

    def _set(self, name: str, value) -> None:
        object.__setattr__(self, name, value)

    def _check_goal(self) -> None:
        self._set("force", _vec3(self.force, "force (F_req)", nonzero=True))
        self._set("start_tool_point", _vec3(self.start_tool_point, "--start"))
        self._set("a67", _a67(self.a67, self.force))

    def _check_task(self) -> None:
        if self.task not in TASKS:
            raise InputError(f"--task must be one of {', '.join(TASKS)}, got {self.task!r}")
        follow = self.task == "follow"
        follow_defaults = {"travel": RUN_DEFAULTS.travel, "travel_step": RUN_DEFAULTS.travel_step,
                           "tilt_deg": RUN_DEFAULTS.tilt_deg, "probe_span": PROBE_TUNING.span_mm}
        given = {k: getattr(self, k) for k in (*follow_defaults, "travel_dir", "auto_tilt")}
        if not follow:
            named = [f"--{k.replace('_', '-')}" for k, v in given.items() if v is not None]
            if named:
                raise InputError(f"{', '.join(named)} only apply to --task follow (this run is "
                                 f"--task {self.task})")
        for key, default in follow_defaults.items():
            if follow and getattr(self, key) is None:
                self._set(key, default)
        if self.travel_dir is not None:
            self._set("travel_dir", _vec3(self.travel_dir, "--travel-dir (the travel direction)",
                                          nonzero=True))
        if self.approach_step is None:
            self._set("approach_step", RUN_DEFAULTS.follow_approach_step if follow
                      else RUN_DEFAULTS.press_approach_step)
        if self.max_iterations is None:
            self._set("max_iterations",
                      MAX_ITERATIONS if follow else RUN_DEFAULTS.press_max_iterations)

    def _check_controller(self) -> None:
        for option, value, allowed in (("--method", self.method, METHODS),
                                       ("--estimator", self.estimator, ESTIMATORS),
                                       ("--procedure", self.procedure, PROCEDURES)):
            if value not in allowed:
                raise InputError(f"{option} must be one of {', '.join(allowed)}, got {value!r}")
        for option, value, unit in (("--force-tol", self.force_tol, "N"),
                                    ("--align-tol-deg", self.align_tol_deg, "degrees"),
                                    ("--step", self.step, "mm"),
                                    ("--approach-step", self.approach_step, "mm"),
                                    ("--max-approach", self.max_approach, "mm")):
            _positive(value, option, unit)
        if not self.align_tol_deg < 180.0:  # the largest angle between S6 and the force
            raise InputError(f"--align-tol-deg must be below 180 degrees (the widest angle "
                             f"between S6 and the force), got {self.align_tol_deg}")
        if not (isinstance(self.max_iterations, (int, np.integer))
                and 1 <= self.max_iterations <= MAX_ITERATIONS):
            raise InputError(f"--max-iterations must be in 1..{MAX_ITERATIONS}, got "
                             f"{self.max_iterations}")

    @property
    def force_magnitude(self) -> float:
        """|F_req| (N)."""
        return float(np.linalg.norm(self.force))

    @property
    def direction(self) -> np.ndarray:
        """F_req's unit direction."""
        return self.force / self.force_magnitude

    def replace(self, **changes) -> RunSpec:
        """A copy with ``changes`` (checked again; task defaults resolved for the new task)."""
        given = {f.name: getattr(self, f.name) for f in fields(self)}
        if "task" in changes:  # the task's defaults follow the task
            for key in ("approach_step", "max_iterations", "travel", "travel_step", "tilt_deg",
                        "probe_span"):
                given[key] = None
        return replace(self, **{**given, **changes})


def _a67(a67, force) -> np.ndarray | None:
    """``--a67`` as a unit vector exactly perpendicular to the start S6 (along F_req)."""
    if a67 is None:
        return None
    a = np.asarray(a67, dtype=float)
    s6 = force / np.linalg.norm(force)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
        raise InputError(f"--a67 must be 3 finite numbers, not all zero, got {a.tolist()}")
    a = a / np.linalg.norm(a)
    dot = float(a @ s6)
    tol = RUN_DEFAULTS.a67_dot_tol
    if abs(dot) > tol:
        raise InputError(f"--a67 must be perpendicular to the start tool axis S6 (along "
                         f"--direction): a67 · S6 = {dot:.4g}, more than {tol:g}")
    a = a - dot * s6
    return a / np.linalg.norm(a)
