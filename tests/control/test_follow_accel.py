"""The follow task keeps its moves slow enough for the top's inertia: a top + tool of mass m
accelerating at a loads the tip across the tool by m a, which the platform's soft tangential
stiffness turns into a run of m a / k_t; the follow task keeps it within its slip test's
resolution, and each move's accelerations are capped accordingly."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.linalg import expm

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.control.follow.law import accel_limit
from kinestat.control.follow.tuning import derive_tuning
from kinestat.control.model import ControlModel
from kinestat.errors import ModelError

START = np.array([-400.0, 800.0, -100.0])


@pytest.fixture(scope="module")
def follow_config():
    prepared = prepare_control(ControlRequest(
        force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START, task="follow",
        cell=SimulatedCell(friction=0.3)))
    return prepared.follow


@pytest.mark.parametrize("mass", [0.1, 0.35, 2.0])
def test_tool_accel_is_the_soft_stiffness_times_the_slip_resolution_over_the_mass(
        follow_config, mass):
    base = follow_config.base
    from dataclasses import replace

    model = replace(base.model, top_mass=mass)
    tun = derive_tuning(model, 4.0, START, follow_config.travel_step)
    resolution = max(3.0 * math.sqrt(2.0) * tun.tip_sigma, tun.step_resolution)
    expected_m_s2 = tun.tangential_stiffness * resolution / mass  # N/mm * mm / kg
    assert tun.tool_accel == pytest.approx(1000.0 * expected_m_s2, rel=1e-12)


def test_a_massless_top_leaves_the_moves_alone(follow_config):
    assert follow_config.base.model.top_mass == 0.0
    assert math.isinf(follow_config.tuning.tool_accel)
    meas = SimpleNamespace(base_pose=np.eye(4))
    assert accel_limit(follow_config, meas, np.array([0, 0, 0, 1.0, 0, 0])) is None


@pytest.mark.parametrize("mass", [-0.1, float("nan"), float("inf")])
def test_top_mass_must_be_a_number_of_kg(follow_config, mass):
    from dataclasses import replace

    with pytest.raises(ModelError, match="top_mass"):
        replace(follow_config.base.model, top_mass=mass)
    assert isinstance(follow_config.base.model, ControlModel)


def _hat(T):
    w, v = T[:3], T[3:]
    X = np.zeros((4, 4))
    X[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    X[:3, 3] = v
    return X


@pytest.mark.parametrize("seed", range(6))
def test_accel_limit_is_tool_accel_over_the_largest_displacement(follow_config, seed):
    """Against the matrix exponential of the twist (scipy): the rate times the larger of the
    flange origin's and the tool point's displacements is the tuning's tool acceleration."""
    from dataclasses import replace

    rng = np.random.default_rng(seed)
    cfg = replace(follow_config, tuning=replace(follow_config.tuning, tool_accel=20.0))
    model = cfg.base.model
    A = rng.normal(size=(3, 3))
    R = np.linalg.qr(A)[0] * np.sign(np.linalg.det(np.linalg.qr(A)[0]))
    TB = np.eye(4)
    TB[:3, :3], TB[:3, 3] = R, rng.uniform(-500, 500, 3)
    T = np.concatenate([rng.normal(scale=0.01, size=3), rng.normal(scale=1.0, size=3)])
    rate = accel_limit(cfg, SimpleNamespace(base_pose=TB), T)
    M6 = np.linalg.inv(np.asarray(model.mount))
    now, new = TB @ M6, TB @ expm(_hat(T)) @ M6
    d = max(np.linalg.norm((new - now) @ np.append(p, 1.0)) for p in
            (np.zeros(3), np.asarray(model.tool_point_6)))
    assert rate * d == pytest.approx(20.0, rel=1e-9)


@pytest.mark.parametrize("bad", [-0.1, float("nan"), float("inf"), True, "heavy"])
def test_top_mass_option_refuses_what_is_not_a_mass(bad):
    from kinestat.errors import InputError

    with pytest.raises(InputError, match="--top-mass"):
        ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                       top_mass=bad)


def test_top_mass_option_reaches_the_follow_tasks_tuning():
    from kinestat.control.follow.tuning import advance_limit, tool_accel_limit

    prepared = prepare_control(ControlRequest(
        force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START, task="follow",
        cell=SimulatedCell(friction=0.3), top_mass=0.35))
    tun = prepared.follow.tuning
    assert prepared.config.model.top_mass == 0.35
    assert tun.tool_accel == pytest.approx(
        tool_accel_limit(0.35, tun.tangential_stiffness, advance_limit(tun)), rel=1e-12)
    assert math.isfinite(tun.tool_accel)
