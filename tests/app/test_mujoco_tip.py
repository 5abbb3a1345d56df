"""The tool's ball tip: the controller is told the MuJoCo scene's radius, and the centre it
measures through the legs is MuJoCo's own sphere centre whatever the tool's orientation."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.app.mujoco_cell import MujocoIO
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.control.wrench import measure
from kinestat.sim.mujoco_scene import M_PER_MM, SceneParams

pytest.importorskip("mujoco")

START = np.array([-400.0, 800.0, -100.0])


@pytest.fixture(scope="module")
def prepared():
    return prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=START,
                                          cell=SimulatedCell(plant="mujoco", friction=0.3)))


def test_the_controller_is_told_the_scenes_tip_radius(prepared):
    r_mm = SceneParams().tip_radius / M_PER_MM
    assert prepared.config.model.tip_radius == pytest.approx(r_mm)
    assert prepared.follow is None or prepared.follow.base.model.tip_radius == pytest.approx(r_mm)
    assert prepared.header["tip_radius_mm"] == pytest.approx(r_mm)


@pytest.mark.parametrize("turn_deg", [(0.0, 0.0), (0.0, 12.0), (-8.0, 6.0)])
def test_measured_ball_centre_is_mujocos_sphere_centre(prepared, turn_deg):
    """The wrist turned (axes 4 and 5) so that the tool points elsewhere: the centre measured
    from the robot's and the legs' counts is the centre of MuJoCo's tip sphere to the sensor's
    resolution, and the foremost point is the radius from it."""
    from kinestat.sim.mujoco_plant import MujocoPlant
    from kinestat.sim.mujoco_scene import build_scene

    s0 = prepared.plant.scene
    plant = MujocoPlant(build_scene(prepared.cell, s0.arm, s0.q_start, s0.top_pose_start))
    q = np.array(plant.joints(), dtype=float)
    q[3] += np.radians(turn_deg[0])
    q[4] += np.radians(turn_deg[1])
    plant.set_reference(q)
    _, rested = plant.settle(5.0)
    assert rested
    model = prepared.config.model
    io = MujocoIO(plant, model, prepared.sensor)
    m = measure(model, plant.joints(), io.sensor().counts, model.platform.home_pose)
    centre = m.tip_centre(model)
    truth = np.asarray(plant.data.geom_xpos[plant.scene.ids["tip"]]) / M_PER_MM
    assert np.linalg.norm(centre - truth) < 0.05
    assert np.linalg.norm(m.tip(model) - centre) == pytest.approx(model.tip_radius, rel=1e-9)
