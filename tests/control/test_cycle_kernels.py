"""The prediction against independent formulations: the platform's compiled pinned-tip kernel
(Gaussian elimination) against NumPy solves written out here, on random stiffness matrices,
tips and moves (incl. singular ones); and :func:`~kinestat.control.predict.predict` (NumPy
solves) on recorded measurements with random flange moves against the prediction rebuilt from
that kernel, with :func:`~kinestat.control.envelope.check_command`'s verdicts compared for
envelopes whose limits sit just around the predicted values."""

from __future__ import annotations

import copy
import tempfile
from pathlib import Path

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.app.sim_cell import InProcessIO, start_counts
from kinestat.control.controller import THESIS_FORCE_DIRECTION, decide
from kinestat.control.envelope import Envelope, check_command, top_motion
from kinestat.control.log import CycleLog
from kinestat.control.loop import run
from kinestat.control.predict import Prediction, predict
from kinestat.io.library import prototype
from kinestat.parallel.stiffness import (
    pinned_tip_step,
    stiffness,
    stiffness_axis_trusted,
    tip_compliance,
    tip_compliance_one,
)
from kinestat.spatial.se3 import twist_exp
from kinestat.spatial.transforms import skew

START = np.array([-400.0, 800.0, -100.0])


def _numpy_step(K, p, u, F, platform, T):
    """The prediction's linear algebra as NumPy solves (the formulation of
    :func:`kinestat.control.predict.predict`'s NumPy path), written out independently."""
    A = np.vstack([np.eye(3), skew(p)])
    B = np.hstack([-skew(p), np.eye(3)])
    b = np.concatenate([np.zeros(3), np.cross(u, F)])
    C = B @ np.linalg.solve(K, A)
    dF = np.linalg.solve(C, u - B @ np.linalg.solve(K, b))
    D = np.linalg.solve(K, A @ dF + b)
    d = (T[:3, :3] @ platform.top_points.T).T + T[:3, 3] - platform.base_points
    S = d / np.linalg.norm(d, axis=1)[:, None]
    dl = np.cross(platform.base_points, S) @ D[:3] + S @ D[3:]
    return dF, D, dl


@pytest.fixture(scope="module")
def recorded():
    prep = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                          start_tool_point=START, cell=SimulatedCell()))
    meas: list = []
    base = prep.config

    def recording(state, m):
        meas.append(m)
        return decide(base, state, m)

    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(base))
    with tempfile.TemporaryDirectory() as tmp, CycleLog(Path(tmp) / "log.jsonl") as log:
        run(base, io, log, decide_fn=recording)
    return base.model, meas


def test_pinned_tip_kernel_equals_numpy_solves():
    plat = prototype()
    rng = np.random.default_rng(21)
    for i in range(300):
        T = twist_exp(np.concatenate([rng.normal(0, 0.03, 3), rng.normal(0, 2, 3)])) \
            @ plat.home_pose
        K = stiffness(plat, T, twist_order="axis") if i % 3 else rng.normal(size=(6, 6))
        p = rng.normal(0.0, 100.0, 3) * 10.0 ** rng.uniform(-3, 0.5)
        u = rng.normal(size=3) * 10.0 ** rng.uniform(-6, 1)
        F = rng.normal(size=3) * 10.0 ** rng.uniform(-3, 2) if i % 7 else np.zeros(3)
        C_ref = tip_compliance(plat, T, p, stiffness_axis=K)
        C = tip_compliance_one(K, p)
        np.testing.assert_allclose(C, C_ref, rtol=0, atol=1e-10 * np.max(np.abs(C_ref)))
        dF_ref, D_ref, dl_ref = _numpy_step(K, p, u, F, plat, T)
        dF, D, dl, top = pinned_tip_step(plat, T, K, p, u, F)
        for x, y in ((dF, dF_ref), (D, D_ref), (dl, dl_ref)):
            np.testing.assert_allclose(x, y, rtol=1e-7, atol=1e-9 * max(1.0, np.max(np.abs(y))))
        R = top[:3, :3]
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)


def test_singular_stiffness_falls_back_to_numpy_and_raises():
    plat = prototype()
    K = stiffness_axis_trusted(plat, plat.home_pose)
    K[5] = K[4]  # two equal rows: singular
    assert pinned_tip_step(plat, plat.home_pose, K, np.zeros(3), np.ones(3), np.ones(3)) is None
    with pytest.raises(np.linalg.LinAlgError):
        tip_compliance_one(np.zeros((6, 6)), np.zeros(3))


def _kernel_predict(model, meas, Tn) -> Prediction:
    """The pinned-tip prediction rebuilt from the platform's compiled kernel
    (:func:`kinestat.parallel.stiffness.pinned_tip_step`), independently of
    :func:`~kinestat.control.predict.predict`'s NumPy solves."""
    top = np.asarray(meas.top_pose, dtype=float)
    K = stiffness(model.platform, top, twist_order="axis")
    TB_new = Tn @ model.mount
    tip_F = meas.tip(model)
    p = top[:3, :3] @ model.tool_tip_top + top[:3, 3]
    R_new, t_new = TB_new[:3, :3], TB_new[:3, 3]
    u = (tip_F - t_new) @ R_new - p
    F = -(meas.estimate("point") @ meas.base_pose[:3, :3])
    dF, _, dl, top_new = pinned_tip_step(model.platform, top, K, p, u, F)
    Tf = meas.flange_pose
    local = (tip_F - Tf[:3, 3]) @ Tf[:3, :3]
    return Prediction(force=-(R_new @ (F + dF)), deflections=meas.deflections(model) + dl,
                      tip_motion=Tn[:3, :3] @ local + Tn[:3, 3] - tip_F, top_pose=top_new)


def _verdicts(env, model, axis, pred):
    return check_command(env, model, axis, axis, pred)


def test_prediction_equals_the_kernels_with_the_same_verdicts_near_the_limits(recorded):
    model, meas = recorded
    rng = np.random.default_rng(8)
    axis = np.zeros(6)
    compared = 0
    for m in meas:
        for _ in range(12):
            dT = twist_exp(np.concatenate([rng.normal(0, 0.01, 3), rng.normal(0, 1.0, 3)])
                           * 10.0 ** rng.uniform(-3, 0.5))
            Tn = m.flange_pose @ dT
            fast = predict(model, copy.copy(m), Tn)
            ref = _kernel_predict(model, m, Tn)
            for x, y in ((fast.force, ref.force), (fast.deflections, ref.deflections),
                         (fast.tip_motion, ref.tip_motion), (fast.top_pose, ref.top_pose)):
                np.testing.assert_allclose(x, y, rtol=1e-9, atol=1e-9)
            # envelopes whose limits sit 1e-6 relative around the predicted values: both
            # formulations on the same side of every limit
            motion = np.abs(top_motion(model, ref.top_pose))
            for f in (1.0 - 1e-6, 1.0 + 1e-6):
                env = Envelope(max_load=ref.force_magnitude * f,
                               max_deflection=float(np.max(np.abs(ref.deflections))) * f,
                               motion_range=tuple(np.maximum(motion * f, 1e-9)))
                assert _verdicts(env, model, axis, fast) == _verdicts(env, model, axis, ref)
                compared += 1
    assert compared > 50
    # the defaults too, with a real refusal among them (a large move)
    env = Envelope()
    m = meas[-1]
    Tn = m.flange_pose.copy()
    Tn[:3, 3] += 5.0 * m.s6
    fast, ref = predict(model, copy.copy(m), Tn), _kernel_predict(model, m, Tn)
    bad = _verdicts(env, model, axis, fast)
    assert bad and bad == _verdicts(env, model, axis, ref)
