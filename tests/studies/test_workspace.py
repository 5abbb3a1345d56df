"""Workspace study: known reaches, the PUMA 762's geometry, a plain reference in the test."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.optimize import minimize

import kinestat
from kinestat.errors import InputError
from kinestat.studies.base import build_study
from kinestat.studies.engine import run_reference
from kinestat.studies.workspace import workspace_spec

from .conftest import L1, L2


def _plain_reference(model, grid):
    """Summary numbers computed here, directly from the kernels over the whole grid."""
    axes = [np.linspace(lo, hi, grid) for lo, hi in zip(model.lower, model.upper, strict=True)]
    q = np.array(list(itertools.product(*axes)))
    T = kinestat.fk(model, q)
    J = kinestat.jacobian(model, q)
    p = T[:, :3, 3]
    # end-point velocity rows v_p = v_O + w x p, then Yoshikawa sqrt(det(J J^T))
    vp = J[:, 3:, :] + np.cross(J[:, :3, :], p[:, :, None], axis=1)
    return q, np.linalg.norm(p, axis=1), vp


def test_planar_two_link_reach_is_exact(planar_model):
    study = build_study("workspace", workspace_spec(planar_model, grid=9, chunk_size=10))
    s = run_reference(study)
    assert s["points"] == 81 and s["task"] == "planar"
    # q2 = 0 and q2 = +-180 deg are grid points: the reach extremes are exact
    assert s["reach_max"] == pytest.approx(L1 + L2, abs=1e-14)
    assert s["reach_min"] == pytest.approx(abs(L1 - L2), abs=1e-14)
    # planar manipulability |l1 l2 sin q2|: max at q2 = +-90 deg (a grid point), min 0
    assert s["manipulability"]["max"] == pytest.approx(L1 * L2, rel=1e-12)
    assert s["manipulability"]["min"] == pytest.approx(0.0, abs=1e-12)
    assert s["singular"] == 3 * 9  # q2 in {-180, 0, 180}


def test_planar_summary_matches_plain_reference(planar_model):
    model = kinestat.load(planar_model)
    q, reach, vp = _plain_reference(model, 13)
    Jt = vp[:, :2, :]
    w = np.abs(np.linalg.det(Jt))  # sqrt(det(Jt Jt^T)) of the square 2x2 task Jacobian
    np.testing.assert_allclose(w, L1 * L2 * np.abs(np.sin(q[:, 1])), atol=1e-15)
    s = run_reference(build_study("workspace", workspace_spec(planar_model, grid=13,
                                                              chunk_size=50)))
    assert s["points"] == len(q)
    assert s["reach_max"] == pytest.approx(reach.max(), rel=1e-12)
    assert s["reach_min"] == pytest.approx(reach.min(), rel=1e-12, abs=1e-12)
    assert s["reach_mean"] == pytest.approx(reach.mean(), rel=1e-12)
    assert s["manipulability"]["mean"] == pytest.approx(w.mean(), rel=1e-12)
    assert s["manipulability"]["max"] == pytest.approx(w.max(), rel=1e-12)


def test_puma_summary_matches_plain_reference():
    model = kinestat.load("puma762")
    q, reach, vp = _plain_reference(model, 4)
    J = kinestat.jacobian(model, q)
    w = np.abs(np.linalg.det(J))  # sqrt(det(J J^T)) = |det J| for a 6x6 Jacobian
    s = run_reference(build_study("workspace", workspace_spec("puma762", grid=4,
                                                              chunk_size=1000)))
    assert s["points"] == 4 ** 6
    assert s["reach_max"] == pytest.approx(reach.max(), rel=1e-12)
    assert s["reach_min"] == pytest.approx(reach.min(), rel=1e-12)
    assert s["manipulability"]["max"] == pytest.approx(w.max(), rel=1e-9)
    assert s["manipulability"]["mean"] == pytest.approx(w.mean(), rel=1e-9)


def test_puma_reach_against_its_geometry():
    model = kinestat.load("puma762")
    P = model.parameters  # modified DH rows (alpha, a, theta, d)
    link_sum = float(np.sum(np.abs(P[:, 1])) + np.sum(np.abs(P[:, 3])))
    # without joint limits: S2 is perpendicular to the arm plane, a23 + S4 in it, S6 last
    a23, s2, s4, s6 = P[2, 1], P[1, 3], P[3, 3], P[5, 3]
    geometric = float(np.hypot(s2, a23 + s4) + s6)
    # with joint limits: a multi-start bounded optimisation of |p| (independent of the study)
    rng = np.random.default_rng(4)
    best = 0.0
    for _ in range(8):
        r = minimize(lambda x: -np.linalg.norm(kinestat.fk(model, np.asarray(x))[:3, 3]),
                     rng.uniform(model.lower, model.upper),
                     bounds=list(zip(model.lower, model.upper, strict=True)))
        best = max(best, -r.fun)
    s = run_reference(build_study("workspace", workspace_spec("puma762", samples=40000,
                                                              seed=1)))
    assert s["reach_bound"] == pytest.approx(link_sum)
    assert s["reach_max"] <= best + 1e-6 <= geometric + 1e-6 <= link_sum
    assert s["reach_max"] >= 0.995 * best  # dense samples come close to the true maximum
    assert s["reach_min"] >= 0.0


def test_bad_workspace_specs(planar_model):
    with pytest.raises(InputError, match="unknown model"):
        workspace_spec("no-such-robot", grid=3)
    with pytest.raises(InputError, match="at least 2"):
        workspace_spec("puma762", grid=1)
    with pytest.raises(InputError, match="exactly one"):
        workspace_spec("puma762", grid=3, samples=10)
    with pytest.raises(InputError, match="task rows"):
        workspace_spec(planar_model, grid=3, task="full")
