"""The MuJoCo cell built from kinestat's models agrees with kinestat's own kinematics and statics.

Independent values: the arm's pose from kinestat's forward kinematics (``fk``), the legs from
:func:`kinestat.parallel.legs.leg_lengths`, the leg wrench from
:func:`kinestat.parallel.statics.wrench_from_forces` with the calibrated law evaluated by
:mod:`kinestat.hardware.leg_law`; MuJoCo's kinematics, tendons and actuators compute the same
quantities on its side.
"""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.errors import ModelError
from kinestat.hardware.leg_calibration import LegCalibration
from kinestat.hardware.leg_law import tensions_at_lengths, zero_force_counts
from kinestat.io.library import load_calibration
from kinestat.mechanism.chain import from_standard_dh
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import special_6_6
from kinestat.parallel.statics import wrench_from_forces
from kinestat.serial.fk import fk, fk_frames, joint_motion
from kinestat.sim.contact import make_cell
from kinestat.sim.mujoco_scene import M_PER_MM, build_scene

mujoco = pytest.importorskip("mujoco")

PUMA_START = np.radians([125.0, 30.0, -60.0, 10.0, 40.0, -20.0])


def _poly_law() -> LegCalibration:
    """The thesis's maps with a cubic stiffening term (a non-linear true law)."""
    th = load_calibration("thesis").calibration
    e0 = zero_force_counts(th)
    f = np.zeros((6, 4))
    f[:, :2] = th.force_coeffs
    for i in range(6):
        f[i] += -2e-8 * np.array([-e0[i] ** 3, 3 * e0[i] ** 2, -3 * e0[i], 1.0])
    return LegCalibration(length_coeffs=th.length_coeffs, force_coeffs=f, leg_names=th.leg_names)


def _scene(arm, q, *, legs=None, **kw):
    cell = make_cell(special_6_6(), plane_point=[0, 0, -2000.0], plane_normal=[0, 0, 1],
                     legs=legs)
    T_top = fk(arm, q) @ cell.mount @ cell.platform.home_pose
    return cell, build_scene(cell, arm, q, T_top, **kw)


def _pose_of(data, body: int) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = data.xmat[body].reshape(3, 3)
    T[:3, 3] = data.xpos[body] / M_PER_MM
    return T



@pytest.mark.parametrize("name", ["puma762", "ur5", "stanford", "ur5-placed"])
def test_joint_frames_and_flange_equal_kinestat_fk(name):
    if name == "ur5-placed":  # as `kinestat control --arm ur5` places it: mm, base moved
        from kinestat.app.arm_cell import in_millimetres, placed

        arm = placed(in_millimetres(kinestat.load("ur5")), [-900.0, 350.0, -200.0])
    else:
        arm = kinestat.load(name)
    rng = np.random.default_rng(3)
    lo, hi = np.maximum(arm.lower, -np.pi), np.minimum(arm.upper, np.pi)
    _, scene = _scene(arm, PUMA_START if name == "puma762" else np.zeros(6))
    m = scene.model
    d = mujoco.MjData(m)
    k = {"mm": 1.0, "m": 1e3}[arm.length_unit]  # model units -> mm
    for _ in range(5):
        q = rng.uniform(lo, hi)
        d.qpos[scene.ids["arm_qpos"]] = q
        mujoco.mj_kinematics(m, d)
        frames = fk_frames(arm, q)  # F_(i-1): the frame joint i moves in
        Z = joint_motion(arm, q)
        for i in range(6):  # MuJoCo's body i: joint i's frame turned by q_i
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"link{i + 1}")
            F = frames[i] @ Z[i]
            F[:3, 3] *= k
            np.testing.assert_allclose(_pose_of(d, b), F, atol=1e-9)
        s = scene.ids["flange"]
        Tf = np.eye(4)
        Tf[:3, :3] = d.site_xmat[s].reshape(3, 3)
        Tf[:3, 3] = d.site_xpos[s] / M_PER_MM
        T_ref = fk(arm, q)
        T_ref[:3, 3] *= k
        np.testing.assert_allclose(Tf, T_ref, atol=1e-9)


def test_leg_lengths_and_leg_forces_follow_the_true_nonlinear_law():
    from kinestat.sim.mujoco_plant import MujocoPlant

    arm = kinestat.load("puma762")
    cell, scene = _scene(arm, PUMA_START, legs=_poly_law())
    assert cell.leg_law is not None
    plant = MujocoPlant(scene)
    d = plant.data
    TB = fk(arm, PUMA_START) @ cell.mount  # the base plate in the fixed frame
    rng = np.random.default_rng(7)
    for _ in range(4):  # the top displaced from home by up to ~2 mm and ~1 degree
        from scipy.spatial.transform import Rotation

        X = cell.platform.home_pose.copy()
        X[:3, :3] = Rotation.from_rotvec(rng.normal(0, 0.01, 3)).as_matrix() @ X[:3, :3]
        X[:3, 3] += rng.normal(0, 1.0, 3)
        T = TB @ X
        a = scene.ids["top_qpos"]
        d.qpos[a:a + 3] = T[:3, 3] * M_PER_MM
        mujoco.mju_mat2Quat(d.qpos[a + 3:a + 7], np.ascontiguousarray(T[:3, :3]).ravel())
        d.qvel[:] = 0.0
        mujoco.mj_forward(scene.model, d)
        L = leg_lengths(cell.platform, X)
        np.testing.assert_allclose(plant.leg_lengths(), L, atol=1e-9)
        plant._apply_legs()
        mujoco.mj_forward(scene.model, d)
        f = tensions_at_lengths(cell.leg_law, L, cell.platform.leg_names)
        w = wrench_from_forces(cell.platform, X, f)  # the external wrench the legs balance
        on_top = -(TB[:3, :3] @ w[:3])  # the legs' force on the top, fixed frame
        dof = scene.model.jnt_dofadr[mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_JOINT,
                                                       "top")]
        np.testing.assert_allclose(d.qfrc_actuator[dof:dof + 3], on_top, atol=1e-9)


def test_screw_joint_arm_is_refused_with_one_clear_error():
    rows = [[0.0, 0.0, 100.0, 0.0]] * 6
    arm = from_standard_dh(rows, ["revolute"] * 5 + ["screw"], pitches=[0] * 5 + [2.0],
                           name="screwy")
    with pytest.raises(ModelError, match="MuJoCo cannot load arm 'screwy'.*screw"):
        _scene(arm, np.zeros(6))
