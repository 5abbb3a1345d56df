"""Another arm in the kinestatic cell (``ControlRequest.arm``, ``kinestat control --arm``): a UR5
from its URDF and the PUMA 560 press the tool and follow the plane on the in-process simulated
cell. Every figure is checked against something the run did not compute: the true force by
solving the cell's contact equilibrium again at the flange pose of the arm's OWN model (loaded
afresh, in its own unit) at the logged joints, the joint limits from the model file."""

from __future__ import annotations

import math

import numpy as np
import pytest

import kinestat
from kinestat.app.arm_cell import ArmSpec, arm_io, in_millimetres, place_arm
from kinestat.app.control_run import (
    ControlRequest,
    SimulatedCell,
    prepare_control,
    report_dict,
    run_control,
)
from kinestat.control.controller import THESIS_FORCE_DIRECTION, default_a67
from kinestat.control.log import read_log
from kinestat.errors import DeviceError, InputError
from kinestat.sim.arm import SimulatedArm
from kinestat.sim.contact import equilibrium
from tests.serial.analytic.arms import jaco6
from tests.urdf_arms import arm_path

START = np.array([-400.0, 800.0, -100.0])
D = np.asarray(THESIS_FORCE_DIRECTION)
P6 = np.array([0.0, 0.0, 235.0])


def _arm(name: str):
    """The arm's model as a user loads it (the UR5 URDF in metres, the PUMA 560 TOML in m)."""
    if name == "ur5":
        return kinestat.load(arm_path("ur5"), tip="tool0")
    return kinestat.load(name)


def _request(model, task="press", base=None, **kw) -> ControlRequest:
    if task == "follow":
        kw.setdefault("travel", 4.0)
        kw.setdefault("travel_dir", np.array([0.0, 1.0, 0.0]))
    return ControlRequest(force=4.0 * D, start_tool_point=START, cell=kw.pop("cell",
                          SimulatedCell()), arm=ArmSpec(model, base=base, name=model.name),
                          task=task, **kw)


def _run(req, path):
    prep = prepare_control(req)
    report = run_control(prep, path)
    return prep, report_dict(prep, report), read_log(path)


def _independent_flange(model, base_mm, joints_deg) -> np.ndarray:
    """``T_cell_flange`` (mm) from the user's model in its own unit: FK, then metres to mm and
    the base's translation — not the run's converted, placed model."""
    T = kinestat.fk(model, np.radians(joints_deg))
    scale = {"m": 1000.0, "mm": 1.0}[model.length_unit]
    T = T.copy()
    T[:3, 3] = T[:3, 3] * scale + np.asarray(base_mm)
    return T


def _limits_deg(model) -> np.ndarray:
    return np.degrees(np.column_stack([model.lower, model.upper]))


def _joint_vectors(records):
    """Every joint vector the run logged: the true joints of each cycle, each command and each
    move actually made (degrees)."""
    for r in records:
        if r["type"] == "cycle":
            yield r["true"]["joints_deg"]
            if r["commanded"] is not None:
                yield r["commanded"]["joints_deg"]
        elif r["type"] == "move":
            yield r["move"]["joints_deg"]
        elif r["type"] == "command" and r["commanded"] is not None:
            yield r["commanded"]["joints_deg"]


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_press_converges_with_another_arm(tmp_path, name):
    model = _arm(name)
    prep, out, records = _run(_request(model), tmp_path / "log.jsonl")
    assert out["converged"], out["stop_reason"]
    assert out["states"].endswith("e") and out["iterations"] <= 20
    arm = out["arm"]
    assert arm["placement"] == "auto" and arm["name"] == model.name
    # the true force, recomputed: the user's model at the last logged true joints, placed at
    # the reported base, through the cell's contact equilibrium
    last = [r for r in records if r["type"] == "cycle"][-1]
    T = _independent_flange(model, arm["base"], last["true"]["joints_deg"])
    eq = equilibrium(prep.cell, T)
    assert eq.in_contact
    np.testing.assert_allclose(eq.tool_force, out["true_force"], atol=1e-4)
    assert abs(np.linalg.norm(eq.tool_force) - 4.0) <= 0.5
    # the tool axis is along the force (the true force vs the tool axis, degrees)
    s6 = T[:3, 2]
    ang = math.degrees(math.acos(min(1.0, eq.tool_force @ s6 / np.linalg.norm(eq.tool_force))))
    assert ang < 1.0
    # every joint vector of the run inside the model file's own limits
    lim = _limits_deg(model)
    qs = np.array(list(_joint_vectors(records)))
    assert len(qs) >= 2 * out["iterations"]
    assert np.all(qs >= lim[:, 0] - 1e-6) and np.all(qs <= lim[:, 1] + 1e-6)
    assert records[-1]["type"] == "end"


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_follow_a_few_mm_on_the_plane(tmp_path, name):
    model = _arm(name)
    prep, out, records = _run(_request(model, task="follow"), tmp_path / "log.jsonl")
    assert out["completed"], out["stop_reason"]
    assert out["travel"] == pytest.approx(4.0, abs=1.0)
    assert out["contact_lost"] == 0 and out["normal_force_max_error"] <= 0.5
    wp = prep.cell.workpiece
    travel_cycles = [r for r in records if r["type"] == "cycle" and r.get("task")
                     and r["task"]["travel"] > 0]
    assert travel_cycles
    for r in travel_cycles:  # the true tip on the plane, the true joints in limits
        T = _independent_flange(model, out["arm"]["base"], r["true"]["joints_deg"])
        eq = equilibrium(prep.cell, T)
        assert eq.in_contact and abs(float(wp.normal @ (eq.tip - wp.point))) < 1e-6
    lim = _limits_deg(model)
    qs = np.array(list(_joint_vectors(records)))
    assert np.all(qs >= lim[:, 0] - 1e-6) and np.all(qs <= lim[:, 1] + 1e-6)


def _edge_of_reach(model) -> float:
    """The largest distance behind the start (along −F_req) the base can be (bisection)."""
    a67 = default_a67(D)
    lo, hi = 100.0, 3000.0
    for _ in range(25):
        t = 0.5 * (lo + hi)
        try:
            place_arm(model, START, D, a67, P6, base=START - t * D)
            lo = t
        except InputError:
            hi = t
    return lo


def test_unreachable_target_stops_with_a_reason_and_a_complete_log(tmp_path):
    """The base 3 mm short of the reach limit, the workpiece 50 mm away: the approach walks
    out of the workspace and the run stops, naming why, with the log complete."""
    model = _arm("ur5")
    t = _edge_of_reach(model) - 3.0
    req = _request(model, base=START - t * D,
                   cell=SimulatedCell(plane_point=START + 50.0 * D, plane_normal=-D))
    _, out, records = _run(req, tmp_path / "log.jsonl")
    assert not out["converged"]
    assert "not reachable" in out["stop_reason"] and "approach" in out["stop_reason"]
    assert [r["type"] for r in records][-2:] == ["fault", "end"]
    assert 1 <= out["iterations"] <= 10
    lim = _limits_deg(model)
    qs = np.array(list(_joint_vectors(records)))
    assert np.all(qs >= lim[:, 0] - 1e-6) and np.all(qs <= lim[:, 1] + 1e-6)


def _toml_arm(tmp_path, rows, kinds=None) -> str:
    """A TOML model file of standard DH ``rows`` (theta, d, a, alpha; mm, degrees)."""
    text = 'name = "test-arm"\nnotation = "standard_dh"\nlength_unit = "mm"\nangle_unit = "deg"\n'
    for i, (th, d, a, al) in enumerate(rows):
        kind = "revolute" if kinds is None else kinds[i]
        lim = "[0.0, 300.0]" if kind == "prismatic" else "[-170.0, 170.0]"
        text += (f'\n[[joints]]\nname = "j{i + 1}"\ntype = "{kind}"\ntheta = {th}\nd = {d}\n'
                 f'a = {a}\nalpha = {al}\nlimits = {lim}\n')
    p = tmp_path / "arm.toml"
    p.write_text(text)
    return str(p)


@pytest.mark.parametrize("n, what", [(5, "has 5 joints"), (7, "has 7 joints")])
def test_arms_without_six_joints_are_refused_before_any_motion(tmp_path, n, what):
    rows = [(0.0, 100.0, 300.0, 90.0)] * n
    model = kinestat.load(_toml_arm(tmp_path, rows))
    with pytest.raises(InputError, match=what):
        prepare_control(_request(model))


def test_a_seven_joint_urdf_is_refused(tmp_path):
    model = kinestat.load(arm_path("panda"), tip="panda_hand_tcp")
    with pytest.raises(InputError, match="has 7 joints"):
        prepare_control(_request(model))


def test_an_arm_without_an_analytic_solver_is_refused(tmp_path):
    rows = [(0.0, 300.0, 0.0, 90.0), (0.0, 0.0, 400.0, 0.0), (0.0, 100.0, 0.0, 90.0),
            (0.0, 400.0, 0.0, -90.0), (0.0, 0.0, 0.0, 90.0), (0.0, 100.0, 0.0, 0.0)]
    kinds = ["revolute", "revolute", "prismatic", "revolute", "revolute", "revolute"]
    model = kinestat.load(_toml_arm(tmp_path, rows, kinds))
    with pytest.raises(InputError, match="no analytic inverse-kinematics solver"):
        prepare_control(_request(model))


def test_an_unreachable_start_is_refused_before_any_motion():
    model = _arm("puma560")
    with pytest.raises(InputError, match="out of reach") as exc:
        prepare_control(_request(model, base=START + np.array([5000.0, 0.0, 0.0])))
    assert "puma560" in str(exc.value) and "--arm-base" in str(exc.value)


def test_millimetres_and_placement_keep_the_kinematics():
    m = kinestat.load("puma560")
    mm = in_millimetres(m)
    q = np.random.default_rng(3).uniform(-2, 2, (20, 6))
    T, Tmm = kinestat.fk(m, q), kinestat.fk(mm, q)
    np.testing.assert_allclose(Tmm[..., :3, :3], T[..., :3, :3], atol=1e-12)
    np.testing.assert_allclose(Tmm[..., :3, 3], 1000.0 * T[..., :3, 3], atol=1e-9)


def test_the_simulated_arm_refuses_a_joint_outside_its_limits(tmp_path):
    """Below the controller's envelope: a command outside the limits that reached the
    simulated cell anyway is refused there, nothing moves."""
    model = _arm("puma560")
    prep = prepare_control(_request(model))
    io = arm_io(prep.cell, prep.sensor, prep.arm)
    before = io.robot_counts()
    bad = before.copy()
    bad[4] = round(150.0 / 1e-4)  # joint 5 to 150 deg, limits ±100 deg
    with pytest.raises(DeviceError, match="joint 5 commanded to 150"):
        io.move(bad)
    np.testing.assert_array_equal(io.robot_counts(), before)
    arm = SimulatedArm(in_millimetres(model), np.zeros(6))
    with pytest.raises(DeviceError, match="joint 2"):
        arm.move_to([0.0, math.radians(230.0), 0.0, 0.0, 0.0, 0.0])


def test_embedded_ur5_is_the_urdf_ur5():
    """The embedded ur5 (manufacturer's DH) and ur_description's URDF are the same arm: the
    flange's displacement between any two configurations has the same length."""
    dh, urdf = kinestat.load("ur5"), _arm("ur5")
    q = np.random.default_rng(1).uniform(-3, 3, (30, 6))
    a, b = kinestat.fk(dh, q)[:, :3, 3], kinestat.fk(urdf, q)[:, :3, 3]
    np.testing.assert_allclose(np.linalg.norm(np.diff(a, axis=0), axis=1),
                               np.linalg.norm(np.diff(b, axis=0), axis=1), atol=1e-9)
    np.testing.assert_allclose(_limits_deg(dh), _limits_deg(urdf), atol=1e-6)


@pytest.mark.parametrize("name, direction", [("puma560", (0.0, 0.0, -1.0)),
                                             ("ur5", (-1.0, 0.0, 0.0))])
def test_automatic_placement_for_other_directions(tmp_path, name, direction):
    """Pressing straight down (the wrist must not be placed near its singularity, where a few
    degrees of reorientation turn axis 4 by more than the envelope's step) and along −x;
    the embedded DH models."""
    model = kinestat.load(name)
    f = np.asarray(direction)
    req = ControlRequest(force=4.0 * f, start_tool_point=np.array([100.0, -200.0, 300.0]),
                         cell=SimulatedCell(), arm=ArmSpec(model, name=name))
    prep, out, records = _run(req, tmp_path / "log.jsonl")
    assert out["converged"], out["stop_reason"]
    assert abs(out["true_force_magnitude"] - 4.0) <= 0.5
    # the shoulder stands behind the workpiece plane (the tool pushes away from it)
    # (both DH tables have a1 = 0: the shoulder is on joint 1's axis, d1 above the base)
    sh = np.array([0.0, 0.0, 1000.0 * model.parameters[0][1]]) + out["arm"]["base"]
    assert float((np.array([100.0, -200.0, 300.0]) - sh) @ f) > 0
    lim = _limits_deg(model)
    qs = np.array(list(_joint_vectors(records)))
    assert np.all(qs >= lim[:, 0] - 1e-6) and np.all(qs <= lim[:, 1] + 1e-6)


def test_a_general_6r_arm_presses(tmp_path):
    """An arm without closed-form structure (a Jaco2-type 60° wrist: ``ik_all``'s general 6R
    solver) in the cell: converged, the true force recomputed from its own model."""
    model = jaco6()
    prep, out, records = _run(_request(model), tmp_path / "log.jsonl")
    assert out["converged"], out["stop_reason"]
    last = [r for r in records if r["type"] == "cycle"][-1]
    eq = equilibrium(prep.cell, _independent_flange(model, out["arm"]["base"],
                                                    last["true"]["joints_deg"]))
    assert abs(np.linalg.norm(eq.tool_force) - 4.0) <= 0.5
