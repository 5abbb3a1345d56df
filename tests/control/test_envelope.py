"""The safety envelope: limits, the worst-case prediction, verdicts."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kinestat.app.sim_cell import start_counts
from kinestat.control.controller import axis_counts_to_q
from kinestat.control.envelope import (
    Envelope,
    check_command,
    check_measurement,
    check_target,
    require,
)
from kinestat.control.predict import (
    predict,
    predict_sliding,
    sliding_force,
    sliding_push,
    tip_compliance,
    tip_stiffness,
)
from kinestat.control.wrench import measure
from kinestat.errors import InputError, SafetyStop
from kinestat.parallel.stiffness import equilibrium_pose
from kinestat.parallel.stiffness import tip_compliance as platform_tip_compliance
from kinestat.parallel.stiffness import tip_stiffness as platform_tip_stiffness
from kinestat.serial import puma762
from kinestat.sim.contact import equilibrium
from kinestat.sim.sensor import Sensor
from kinestat.spatial.transforms import apply, trans

from .conftest import F_HAT, PLATFORM, scenario

ENV = Envelope()


def _loaded(scn, push=0.4):
    """Flange at a pose pushing ``push`` mm into the plane; its exact measurement."""
    cfg = scn.config(start_tool_point=scn.cell.workpiece.point + push * F_HAT)
    q = axis_counts_to_q(scn.model, start_counts(cfg))
    T = puma762.forward(q).pose
    eq = equilibrium(scn.cell, T)
    exact = Sensor(calibration=scn.sensor.calibration, quantize=False)
    m = measure(scn.model, q, exact.counts(PLATFORM, eq.leg_lengths), PLATFORM.home_pose)
    return T, eq, m


def test_target_beyond_the_load_limit_is_refused():
    assert check_target(ENV, [0, 0, 4]) == []
    bad = check_target(ENV, [0, 0, 60])
    assert bad and "50" in bad[0]
    with pytest.raises(SafetyStop, match="load limit"):
        require(bad)


def test_tip_compliance_is_symmetric_unloaded_and_positive():
    scn = scenario(distance=50.0, ideal=True)  # far away: no load
    q = axis_counts_to_q(scn.model, start_counts(scn.config()))
    m = measure(scn.model, q, scn.sensor.counts(PLATFORM, PLATFORM.free_lengths),
                PLATFORM.home_pose)
    C = tip_compliance(scn.model, m)
    np.testing.assert_allclose(C, C.T, atol=1e-8 * np.abs(C).max())
    assert np.all(np.linalg.eigvalsh(C) > 0)
    K = tip_stiffness(scn.model, m)
    # axially the platform is far stiffer than sideways at the end of a 175 mm tool
    s6 = m.s6
    lateral = np.cross(s6, [0, 0, 1.0])
    lateral /= np.linalg.norm(lateral)
    assert s6 @ K @ s6 > 5 * (lateral @ K @ lateral)


@pytest.mark.parametrize("move", ["push", "pull", "sideways", "turn"])
def test_prediction_matches_a_sticking_contact(move):
    """Worst case = the tip pinned: compare with the cell solved with a sticking contact."""
    scn = scenario(tilt_deg=4.0, friction=5.0)
    T, eq, m = _loaded(scn)
    d = {"push": 0.02 * m.s6, "pull": -0.02 * m.s6,
         "sideways": 0.02 * np.cross(m.s6, [0, 1.0, 0])}.get(move)
    if d is not None:
        Tn = trans(d) @ T
    else:  # turn 0.05° about an axis through the tool point

        R = np.eye(4)
        R[:3, :3] = Rotation.from_rotvec(np.radians(0.05) * np.array([0, 1.0, 0])).as_matrix()
        Tn = trans(m.tool_point) @ R @ trans(-m.tool_point) @ T
    pred = predict(scn.model, m, Tn)
    after = equilibrium(scn.cell, Tn, anchor=eq.anchor)
    assert after.sticking
    dF_true = after.tool_force - eq.tool_force
    dF_pred = pred.force - m.force
    assert np.linalg.norm(dF_pred - dF_true) <= 0.03 * np.linalg.norm(dF_true) + 1e-6
    dl_true = after.leg_lengths - eq.leg_lengths
    dl_pred = pred.deflections - m.deflections(scn.model)
    assert np.max(np.abs(dl_pred - dl_true)) <= 0.03 * np.max(np.abs(dl_true)) + 1e-7


@pytest.mark.parametrize("move", ["push", "pull", "sideways", "turn", "turn-far"])
@pytest.mark.parametrize("tilt", [4.0, 30.0])
def test_sliding_prediction_matches_a_frictionless_contact(move, tilt):
    """The frictionless slide (the force stays along the normal, the tip moves in the tangent
    plane): compare with the cell solved with a frictionless contact, to first order."""
    scn = scenario(tilt_deg=tilt, friction=0.0)
    T, eq, m = _loaded(scn, push=0.3)
    side = np.cross(m.s6, [0, 1.0, 0])
    d = {"push": 0.02 * m.s6, "pull": -0.02 * m.s6, "sideways": 0.02 * side}.get(move)
    if d is not None:
        Tn = trans(d) @ T
    else:  # turn about an axis through the tool point: 0.2°, or 2° (the press's turns)
        R = np.eye(4)
        deg = 0.2 if move == "turn" else 2.0
        R[:3, :3] = Rotation.from_rotvec(np.radians(deg) * np.array([0, 1.0, 0])).as_matrix()
        Tn = trans(m.tool_point) @ R @ trans(-m.tool_point) @ T
    pred = predict_sliding(scn.model, m, Tn)
    assert sliding_force(scn.model, m, Tn) == pytest.approx(pred.force_magnitude, rel=1e-12)
    after = equilibrium(scn.cell, Tn)
    assert after.in_contact and not after.sticking
    dF_true = after.tool_force - eq.tool_force
    dF_pred = pred.force - m.force
    # a turn about the tool point changes the force by a second-order amount (about 1e-3 N at
    # 0.2°, 4° off the force): 4-6 % of it is the calibrated model against the simulated legs;
    # the pinned prediction is off by 100-2000 % there
    rel = 0.03 if not move.startswith("turn") else 0.08
    assert np.linalg.norm(dF_pred - dF_true) <= rel * np.linalg.norm(dF_true) + 1e-6
    dl_true = after.leg_lengths - eq.leg_lengths
    dl_pred = pred.deflections - m.deflections(scn.model)
    assert np.max(np.abs(dl_pred - dl_true)) <= rel * np.max(np.abs(dl_true)) + 1e-7
    # the force stays along the measured normal (the force direction): no friction to tilt it
    n = m.force / np.linalg.norm(m.force)
    assert np.linalg.norm(np.cross(pred.force, n)) <= 1e-9 * np.linalg.norm(pred.force)


@pytest.mark.parametrize("tilt", [4.0, 30.0])
def test_sliding_push_rate_is_the_force_change_of_a_push(tilt):
    """``sliding_push``'s rate: a further push ``s`` along an axis changes the predicted force
    by ``k s`` (the slide is linear in the flange's translation), and matches the simulator's
    frictionless contact to the model's accuracy."""
    scn = scenario(tilt_deg=tilt, friction=0.0)
    T, eq, m = _loaded(scn, push=0.3)
    R = np.eye(4)
    R[:3, :3] = Rotation.from_rotvec(np.radians(1.0) * np.array([0, 1.0, 0])).as_matrix()
    Tn = trans(m.tool_point) @ R @ trans(-m.tool_point) @ T  # a 1° turn about the tool point
    axis = R[:3, :3] @ m.s6
    f0, k = sliding_push(scn.model, m, Tn, axis)
    assert f0 == pytest.approx(sliding_force(scn.model, m, Tn), rel=1e-12)
    s = 0.05
    f1 = sliding_force(scn.model, m, trans(s * axis) @ Tn)
    assert f1 == pytest.approx(f0 + k * s, rel=1e-9)
    true0 = np.linalg.norm(equilibrium(scn.cell, Tn).tool_force)
    true1 = np.linalg.norm(equilibrium(scn.cell, trans(s * axis) @ Tn).tool_force)
    assert (true1 - true0) / s == pytest.approx(k, rel=0.08)
    assert 0.0 < k <= float(axis @ tip_stiffness(scn.model, m) @ axis) * (1 + 1e-9)


def _unit(rng) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _rotated(T, rotvec_deg, shift) -> np.ndarray:
    out = np.array(T, dtype=float)
    R = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    out[:3, :3] = R @ out[:3, :3]
    out[:3, 3] = out[:3, 3] + shift
    return out


def test_command_checks():
    scn = scenario()
    model = scn.model
    now = np.zeros(6)
    assert check_command(ENV, model, np.full(6, 1.0), now, None) == []
    bad = check_command(ENV, model, [0, 0, 0, 0, 101.0, 0], now, None)
    assert any("axis 5" in b and "limits" in b for b in bad)
    bad = check_command(Envelope(max_joint_step_deg=5), model, [0, 6.0, 0, 0, 0, 0], now, None)
    assert any("axis 2 would move" in b for b in bad)
    _, _, m = _loaded(scn)
    heavy = predict(model, m, trans(6.0 * m.s6) @ m.flange_pose)  # 6 mm further in
    bad = check_command(ENV, model, np.zeros(6), now, heavy)
    assert any("predicted load" in b for b in bad) and any("deflect" in b for b in bad)
    assert check_command(ENV, model, [np.nan] * 6, now, None)


def test_measurement_checks():
    scn = scenario()
    _, _, m = _loaded(scn)
    assert check_measurement(ENV, scn.model, m) == []
    crushed = PLATFORM.free_lengths - 5.5
    c = scn.sensor.counts(PLATFORM, crushed)
    mc = measure(scn.model, np.zeros(6), c, PLATFORM.home_pose)
    bad = check_measurement(ENV, scn.model, mc)
    assert any("deflected" in b for b in bad) and any("load" in b for b in bad)


def test_envelope_values_are_checked():
    with pytest.raises(InputError):
        Envelope(max_load=0)
    with pytest.raises(InputError):
        Envelope(max_stream_faults=-1)


def test_platform_tip_compliance_matches_the_springs_and_batches():
    """parallel.stiffness.tip_compliance: a small force at the tip, solved by the springs'
    equilibrium, moves the tip by C δF; a batch equals its items; tip_stiffness inverts it."""
    pf = PLATFORM
    tip_top = np.array([3.0, -2.0, 120.0])
    home = pf.home_pose
    p = apply(home, tip_top)
    C = platform_tip_compliance(pf, home, p)
    dF = np.array([0.3, -0.2, 0.5]) * 1e-2  # small: the tip moves ~10 µm
    T = equilibrium_pose(pf, np.concatenate([dF, np.cross(p, dF)]))
    moved = apply(T, tip_top) - p
    np.testing.assert_allclose(moved, C @ dF, rtol=1e-3, atol=1e-3 * np.abs(moved).max())
    poses = np.stack([home, T])
    tips = np.stack([p, apply(T, tip_top)])
    Cb = platform_tip_compliance(pf, poses, tips)
    assert Cb.shape == (2, 3, 3)
    np.testing.assert_allclose(Cb[1], platform_tip_compliance(pf, T, tips[1]), rtol=1e-12)
    R = Rotation.from_rotvec([0.1, 0.2, -0.3]).as_matrix()
    K = platform_tip_stiffness(pf, home, p, R)
    np.testing.assert_allclose(R.T @ K @ R @ C, np.eye(3), atol=1e-9)
