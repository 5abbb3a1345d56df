"""The top's weight on MuJoCo's physics: the legs carry it, the measurement chain subtracts it
(:mod:`kinestat.control.payload`), judged by MuJoCo's own contact force."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.app.mujoco_cell import MujocoIO
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.control.payload import Payload
from kinestat.control.wrench import measure
from kinestat.sim.mujoco_plant import MujocoPlant
from kinestat.sim.mujoco_scene import SceneParams, build_scene

pytest.importorskip("mujoco")

START = np.array([-400.0, 800.0, -100.0])


def _weighted(friction: float = 0.0):
    """The default MuJoCo cell with gravity on the top + tool, and the controller's model with
    and without the payload the scene reports."""
    prep = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=START,
                                          cell=SimulatedCell(plant="mujoco", friction=friction)))
    s0 = prep.plant.scene
    scene = build_scene(prep.cell, s0.arm, s0.q_start, s0.top_pose_start,
                        params=SceneParams(top_weight=True))
    plant = MujocoPlant(scene)
    plant.settle()
    mass, com, g = scene.top_load()
    bare = prep.config.model
    return prep, plant, bare, replace(bare, payload=Payload(mass, com, g))


def _measure(model, plant, sensor):
    io = MujocoIO(plant, model, sensor)
    q = plant.joints()
    counts = io.sensor().counts
    return measure(model, q, counts, model.platform.home_pose)


def test_scene_reports_the_top_and_tool_mass():
    _, plant, _, model = _weighted()
    assert model.payload.mass_kg == pytest.approx(SceneParams().top_mass, rel=1e-3)
    assert model.payload.weight_n > 3.0


def test_weight_compensated_at_rest_out_of_contact():
    """Out of contact the legs carry the weight only: uncompensated it reads as a force of a
    good fraction of the weight; compensated, the leg encoders' resolution remains."""
    prep, plant, bare, model = _weighted()
    assert plant.truth()["true_force"] is None or np.linalg.norm(plant.truth()["true_force"]) == 0
    raw = _measure(bare, plant, prep.sensor)
    comp = _measure(model, plant, prep.sensor)
    assert np.linalg.norm(raw.force) > 0.3 * model.payload.weight_n
    assert np.linalg.norm(comp.force) < 0.05
    assert np.linalg.norm(comp.point_force) < 0.05


def test_weight_compensated_in_contact_against_mujocos_contact_force():
    """The tool pushed 2 mm into the plane along its normal: the compensated measurement is
    MuJoCo's contact force to 0.1 N, the uncompensated one is off by about the weight."""
    prep, plant, bare, model = _weighted()
    wp = prep.cell.workpiece
    n = np.asarray(wp.normal)
    gap = float(wp.gap(plant.truth()["tip"]))
    T = plant.flange_pose()
    tool_point = T[:3, :3] @ model.tool_point_6 + T[:3, 3] - (gap + 2.0) * n
    axis = model.arm.solve_axis(tool_point, T[:3, 2], T[:3, 0], model.tool_point_6,
                                plant.joints(), model.limits_deg)
    plant.set_reference(model.arm.q_from_axis(axis))
    _, rested = plant.settle(5.0)
    assert rested
    true = plant.truth()["true_force"]
    assert np.linalg.norm(true) > 1.0
    comp = _measure(model, plant, prep.sensor)
    raw = _measure(bare, plant, prep.sensor)
    assert np.linalg.norm(comp.point_force - true) <= 0.1
    assert np.linalg.norm(raw.point_force - true) > 0.3
