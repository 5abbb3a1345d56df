"""One run as one frozen RunSpec: its defaults are the command line's, resolved per task once,
and every bad setting is one InputError naming it (issue 41)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from kinestat.cli import _control_options as opts
from kinestat.cli._control_params import PARAMETERS
from kinestat.control.ceilings import MAX_ITERATIONS
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.control.probe import PROBE_TUNING
from kinestat.control.runspec import CylinderSpec, RealDevices, RunSpec, SimulatedCell
from kinestat.errors import InputError


def _cli_defaults() -> dict:
    return {p.name: p.default.default for p in PARAMETERS}


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return a is not None and b is not None and np.allclose(a, b, rtol=0, atol=1e-12)
    if dataclasses.is_dataclass(a) and dataclasses.is_dataclass(b):
        return all(_same(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
    return a == b


def test_the_command_lines_defaults_are_the_specs():
    """`kinestat control` without options and RunSpec() describe the same run."""
    cli, py = opts.run_spec(_cli_defaults()), RunSpec()
    for f in dataclasses.fields(RunSpec):
        assert _same(getattr(cli, f.name), getattr(py, f.name)), f.name


def test_the_default_run_is_the_thesiss_experiment():
    spec = RunSpec()
    assert np.allclose(spec.force, 4.0 * THESIS_FORCE_DIRECTION)
    assert spec.start_tool_point.tolist() == [-400.0, 800.0, -100.0]
    assert isinstance(spec.cell, SimulatedCell) and spec.cell.plant == "kinestat"


def test_task_defaults_are_resolved_once_for_the_task():
    press, follow = RunSpec(), RunSpec(task="follow")
    assert (press.approach_step, press.max_iterations) == (1.0, 60)
    assert (follow.approach_step, follow.max_iterations) == (0.25, MAX_ITERATIONS)
    assert (follow.travel, follow.travel_step, follow.tilt_deg, follow.probe_span) == (
        50.0, 1.0, 0.0, PROBE_TUNING.span_mm)
    assert press.travel is None and press.probe_span is None
    back = follow.replace(task="press")
    assert (back.approach_step, back.max_iterations, back.travel) == (1.0, 60, None)
    assert press.replace(task="follow").approach_step == 0.25
    assert RunSpec(task="follow", approach_step=0.5).approach_step == 0.5


def test_a_spec_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        RunSpec().step = 2.0


@pytest.mark.parametrize("kw, message", [
    ({"travel": 20.0}, "--travel only apply to --task follow"),
    ({"travel_dir": [0, 1, 0], "auto_tilt": True}, "--travel-dir, --auto-tilt only apply"),
    ({"task": "peg"}, "--task must be one of press, follow"),
    ({"method": "newton"}, "--method must be one of"),
    ({"estimator": "both"}, "--estimator must be one of"),
    ({"procedure": "matlab"}, "--procedure must be one of"),
    ({"force_tol": 0.0}, "--force-tol must be a positive number of N"),
    ({"step": float("nan")}, "--step must be a positive number of mm"),
    ({"max_approach": -1.0}, "--max-approach must be a positive number of mm"),
    ({"max_iterations": MAX_ITERATIONS + 1}, f"--max-iterations must be in 1..{MAX_ITERATIONS}"),
    ({"force": [0.0, 0.0, 0.0]}, "force (F_req) must be a nonzero vector"),
    ({"start_tool_point": [1.0, 2.0]}, "--start must be 3 finite numbers"),
    ({"a67": [0.9713, 0.0, -0.2375]}, "--a67 must be perpendicular"),
    ({"task": "press", "travel_step": 1.0}, "--travel-step only apply"),
    ({"cell": RealDevices("127.0.0.1", 5000, "/dev/null"), "arm": object()},
     "another arm runs on the in-process simulated cell only"),
])
def test_bad_settings_are_one_error_naming_them(kw, message):
    with pytest.raises(InputError) as exc:
        RunSpec(**kw)
    assert message in str(exc.value)


@pytest.mark.parametrize("make, message", [
    (lambda: SimulatedCell(noise=-0.1), "--noise must be >= 0 mm"),
    (lambda: SimulatedCell(noise=0.01, ideal_sensor=True), "exclude each other"),
    (lambda: SimulatedCell(plant="bullet"), "--sim must be one of kinestat, mujoco"),
    (lambda: SimulatedCell(workpiece_stiffness=0.0), "--workpiece-stiffness must be"),
    (lambda: SimulatedCell(plane_normal=[0, 0, 0]), "--plane-normal must be a nonzero"),
    (lambda: SimulatedCell(plane_point=[0, 0, 0],
                           cylinder=CylinderSpec(100.0, [0, 0, 1])), "give the cylinder's"),
    (lambda: CylinderSpec(-5.0, [0, 0, 1]), "--workpiece radius must be a positive"),
    (lambda: RealDevices("h", 0, "/dev/ttyUSB0"), "port 0 outside 1..65535"),
    (lambda: RealDevices("h", 23, "/dev/ttyUSB0", "binary"), "--serial-format must be"),
])
def test_bad_cell_settings_are_one_error_naming_them(make, message):
    with pytest.raises(InputError) as exc:
        make()
    assert message in str(exc.value)


def test_a_given_a67_is_made_exactly_perpendicular():
    s6 = THESIS_FORCE_DIRECTION
    a = np.array([0.0, 0.0, 1.0]) - s6[2] * s6
    a = a / np.linalg.norm(a) + 2e-4 * s6  # typed to four decimals
    spec = RunSpec(a67=a)
    assert abs(float(spec.a67 @ s6)) < 1e-12 and np.isclose(np.linalg.norm(spec.a67), 1.0)


def test_top_weight_needs_the_mujoco_plant():
    from kinestat.control.runspec import SimulatedCell
    from kinestat.errors import InputError

    assert SimulatedCell(plant="mujoco", top_weight=True).top_weight
    with pytest.raises(InputError, match="--top-weight needs --sim mujoco"):
        SimulatedCell(top_weight=True)
