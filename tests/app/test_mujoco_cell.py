"""``kinestat control --sim mujoco``: the controller on MuJoCo's physics, judged by MuJoCo's
own contact force (``mj_contactForce``), never the controller's estimate."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from kinestat.app.control_run import (
    ControlRequest,
    SimulatedCell,
    prepare_control,
    report_dict,
    run_control,
)
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.errors import InputError
from kinestat.sim.mujoco_plant import MujocoPlant
from kinestat.sim.mujoco_scene import M_PER_MM, build_scene

pytest.importorskip("mujoco")

START = np.array([-400.0, 800.0, -100.0])


def _request(**cell_kw) -> ControlRequest:
    return ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                          cell=SimulatedCell(plant="mujoco", **cell_kw))


@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_press_converges_on_mujoco_and_measures_its_true_force(tmp_path, friction):
    prep = prepare_control(_request(friction=friction))
    rep = run_control(prep, tmp_path / "log.jsonl")
    out = report_dict(prep, rep)
    assert rep.converged, rep.stop_reason
    assert out["plant"] == "mujoco"
    assert abs(rep.true_force_magnitude - 4.0) <= prep.config.force_tol
    assert rep.axis_error_deg < 1.0
    assert np.linalg.norm(rep.force - rep.true_force) <= 0.1
    assert out["sim_time_s"] > 0 and out["moves_unsettled"] == 0
    header = json.loads((tmp_path / "log.jsonl").read_text().splitlines()[0])
    assert header["plant"] == "mujoco"


def test_compliant_workpiece_yields_by_its_stiffness():
    """A plane on a spring of k N/mm: the contact force over the surface's retreat is k."""
    prep = prepare_control(_request())
    k = 5.0  # N/mm, a soft wood's order
    plant0 = prep.plant
    scene0 = plant0.scene
    scene = build_scene(prep.cell, scene0.arm, scene0.q_start, scene0.top_pose_start,
                        workpiece_stiffness=k)
    plant = MujocoPlant(scene)
    # push the tool 3 mm beyond the plane along its normal, S6 and a67 kept
    wp = prep.cell.workpiece
    n = np.asarray(wp.normal)
    gap = float(wp.gap(plant.truth()["tip"]))
    model = prep.config.model
    T = plant.flange_pose()
    tool_point = T[:3, :3] @ model.tool_point_6 + T[:3, 3] - (gap + 3.0) * n
    axis = model.arm.solve_axis(tool_point, T[:3, 2], T[:3, 0], model.tool_point_6,
                                plant.joints(), model.limits_deg)
    plant.set_reference(model.arm.q_from_axis(axis))
    t, rested = plant.settle(5.0)
    assert rested
    f = plant.truth()["true_force"]
    import mujoco

    j = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_JOINT, "wp0")
    retreat = -plant.data.qpos[scene.model.jnt_qposadr[j]] / M_PER_MM  # mm into the material
    fn = float(f @ -np.asarray(wp.normal))
    assert fn > 1.0
    assert math.isclose(fn / retreat, k, rel_tol=0.01)


def test_unknown_plant_is_refused_before_anything_moves():
    with pytest.raises(InputError, match="--sim must be one of kinestat, mujoco"):
        prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                                       cell=SimulatedCell(plant="bullet")))


def test_whole_stack_through_the_simulated_devices_converges_on_mujoco(tmp_path):
    """``kinestat sim galil --plant mujoco`` + ``kinestat control --galil/--serial``: the Galil
    client, the encoder reader, the 4 -> 5 coupling and its compensation, in real time."""
    from kinestat.app.mujoco_harness import MujocoHarness
    from kinestat.app.sim_cell import start_counts
    from kinestat.control.envelope import sent_command_guard
    from kinestat.control.log import CycleLog
    from kinestat.control.loop import run

    prep = prepare_control(_request())
    cfg = prep.config
    with MujocoHarness(prep.plant, cfg.model, prep.sensor, start_counts=start_counts(cfg)) as h:
        io = h.device_io(guard=sent_command_guard(cfg.envelope, cfg.model))
        with CycleLog(tmp_path / "log.jsonl") as log:
            rep = run(cfg, io, log)
    assert h.controller.coupling != 0.0
    assert rep.converged, rep.stop_reason
    assert abs(rep.true_force_magnitude - 4.0) <= cfg.force_tol
    assert rep.axis_error_deg < 1.0
    assert np.linalg.norm(rep.force - rep.true_force) <= 0.1


def test_the_controller_is_told_the_tops_mass_and_moves_honour_an_accel_limit():
    """The MuJoCo run's controller is told the scene's top + tool mass (its follow task then
    limits its accelerations); a move with ``accel_limit`` keeps every axis at most that
    times its travel, takes longer, and the top's peak acceleration in MuJoCo falls."""
    import mujoco

    from kinestat.app.mujoco_cell import MujocoIO
    from kinestat.sim.mujoco_scene import SceneParams

    prepared = prepare_control(_request())
    model = prepared.config.model
    assert model.top_mass == pytest.approx(SceneParams().top_mass)
    assert prepared.header["top_mass_kg"] == pytest.approx(SceneParams().top_mass)
    peaks, plans = [], []
    for limit in (None, 0.5):
        s0 = prepared.plant.scene
        plant = MujocoPlant(build_scene(prepared.cell, s0.arm, s0.q_start, s0.top_pose_start))
        io = MujocoIO(plant, model, prepared.sensor)
        target = io.robot_counts() + np.array([400, -300, 200, 0, 0, 0])
        jid = mujoco.mj_name2id(plant.model, mujoco.mjtObj.mjOBJ_JOINT, "top")
        dof = int(plant.model.jnt_dofadr[jid])
        dt = plant.model.opt.timestep
        seen = {"v": None, "peak": 0.0}
        step = plant.step

        def watched(n=1, _step=step, _seen=seen, _plant=plant, _dof=dof, _dt=dt):
            _step(n)
            v = np.array(_plant.data.qvel[_dof:_dof + 3])
            if _seen["v"] is not None:
                _seen["peak"] = max(_seen["peak"], float(np.linalg.norm(v - _seen["v"])) / _dt)
            _seen["v"] = v

        plant.step = watched
        plan = io.move(target) if limit is None else io.move(target, accel_limit=limit)
        if limit is not None:
            delta = np.abs(np.asarray(plan["delta_counts"], dtype=float))
            moving = delta > 0
            assert np.all(np.asarray(plan["accel"])[moving] <= limit * delta[moving] + 1e-3)
        plans.append(plan)
        peaks.append(seen["peak"])
    assert plans[1]["sim_move_s"] > plans[0]["sim_move_s"]
    assert peaks[1] < 0.5 * peaks[0]


def test_top_mass_option_sets_the_scenes_mass_and_the_controllers():
    prepared = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                              start_tool_point=START, top_mass=0.5,
                                              cell=SimulatedCell(plant="mujoco")))
    assert prepared.plant.scene.params.top_mass == 0.5
    assert prepared.config.model.top_mass == 0.5
    assert prepared.header["top_mass_kg"] == 0.5


def test_follow_on_soft_wood_measures_its_give_and_keeps_the_force(tmp_path):
    """The follow task on MuJoCo over a 6.3 N/mm workpiece with μ = 0.3 (a campaign draw,
    `scripts/follow_campaign.py 30 --seed 20261208 --wood 5 500 --sim mujoco`'s run 0, which
    ended 4.3 N off before the give was measured): the settle's give is MuJoCo's spring,
    and the travel keeps the true normal force within issue 40's bounds."""
    k_w, force = 6.292427831092623, 5.665301339149183
    f_hat = np.asarray(THESIS_FORCE_DIRECTION, dtype=float)
    cell = SimulatedCell(plant="mujoco", plane_point=START + 2.477601084316164 * f_hat,
                         plane_normal=np.array([-0.9350875263126384, -0.006427428616535641,
                                                0.35435858434062295]),
                         friction=0.3, ideal_sensor=True, workpiece_stiffness=k_w)
    req = ControlRequest(force=force * f_hat, start_tool_point=START, cell=cell,
                         task="follow", travel=47.269978749860456,
                         travel_dir=np.array([-0.3135271723312466, 0.9001072064517767,
                                              -0.3718405450593023]))
    prep = prepare_control(req)
    out = report_dict(prep, run_control(prep, tmp_path / "log.jsonl"))
    assert out["workpiece_compliance_estimate"] == pytest.approx(1.0 / k_w, rel=0.05)
    assert out["completed"] and out["contact_lost"] == 0
    assert out["true_normal_force_max_error"] <= 0.5
    assert out["true_normal_force_rms_error"] <= 0.2
