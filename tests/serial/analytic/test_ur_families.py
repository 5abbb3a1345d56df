"""UR-type arms (three parallel axes): the wrist singularity (axis 6 parallel to axes 2-4,
θ5 = 0 or 180°) is reported as a singular family whose every member reproduces the pose."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.serial.analytic import ik_all, method_for
from tests.urdf_arms import arm_path

from .arms import PI, slot_residuals, ur5, wrapped_distance

T6 = np.linspace(-PI, PI, 25, endpoint=False)


def _models():
    return [ur5(), kinestat.load(arm_path("ur10"), tip="tool0")]


def _singular_configs(model, n, seed):
    q = np.random.default_rng(seed).uniform(-PI, PI, (n, 6))
    q[: n // 2, 4] = 0.0
    q[n // 2:, 4] = PI
    s = np.linalg.svd(kinestat.jacobian(model, q), compute_uv=False)
    assert np.all(s[:, -1] < 1e-9 * s[:, 0])  # these are wrist-singular for these arms
    return q


@pytest.mark.parametrize("which", [0, 1])
def test_wrist_family_reported_and_every_member_reproduces_the_pose(which):
    model = _models()[which]
    assert method_for(model) == "three-parallel"
    q = _singular_configs(model, 60, seed=11 + which)
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    assert res.family_joints is None and res.family_curve is not None
    assert res.singular.any(axis=1).all(), "a wrist-singular pose without its family"
    for i in range(q.shape[0]):
        member_of = False
        for k in np.flatnonzero(res.singular[i]):
            # near the reported member the family continues (the member has elbow margin)
            near = res.family_members((i,), k, res.q[i, k, 5] + np.linspace(-0.01, 0.01, 5))
            assert np.all(np.isfinite(near)), "an isolated point, not a one-parameter family"
            Q = np.concatenate([near, res.family_members((i,), k, T6)])
            ok = ~np.isnan(Q[:, 0])
            F = kinestat.fk(model, Q[ok])
            assert np.max(np.abs(F - T[i])) < 1e-9
            # θ1 and θ5 stay fixed along the family, the others move
            assert np.ptp(Q[ok, 0]) < 1e-9 and np.ptp(Q[ok, 4]) < 1e-9
            assert np.ptp(Q[ok, 1]) > 1e-3
            g = res.family_members((i,), k, q[i, 5])
            member_of |= bool(np.all(np.isfinite(g)) and wrapped_distance(g[0], q[i]) < 1e-7)
        assert member_of, f"pose {i}: the generating configuration is in no reported family"
    # the regular solutions of the other θ1 branch are still there, verified
    assert np.max(np.hypot(*slot_residuals(model, res, T))) < 1e-9


def test_backends_agree_and_batch_shape():
    model = ur5()
    q = _singular_configs(model, 8, seed=3).reshape(2, 4, 6)
    T = kinestat.fk(model, q)
    a = ik_all(model, T)
    b = ik_all(model, T, backend="numpy")
    np.testing.assert_array_equal(a.singular, b.singular)
    np.testing.assert_array_equal(a.n_solutions, b.n_solutions)
    Q = a.family_members((1, 2), int(np.flatnonzero(a.singular[1, 2])[0]), [0.3])
    np.testing.assert_allclose(kinestat.fk(model, Q[0]), T[1, 2], atol=1e-9)


def test_regular_poses_have_no_family():
    model = ur5()
    q = np.random.default_rng(4).uniform(-PI, PI, (200, 6))
    q[:, 4] = np.clip(np.abs(q[:, 4]), 0.2, PI - 0.2)
    res = ik_all(model, kinestat.fk(model, q))
    assert not res.singular.any()


def test_cli_all_json_reports_the_family(capsys):
    from kinestat.cli.main import main

    model = kinestat.load(arm_path("ur10"), tip="tool0")
    q = np.array([0.3, -1.0, 1.2, 0.4, 0.0, -0.7])
    T = kinestat.fk(model, q)
    pose = ",".join(f"{v:.17g}" for v in T.ravel())
    assert main(["ik", str(arm_path("ur10")), "--tip", "tool0", "--pose", pose, "--all",
                 "--json"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    fams = doc["singular_families"]
    assert fams and all(f["free_joint"] for f in fams)
    for f in fams:
        s = doc["solutions"][f["solution"]]
        assert s["singular"]
        np.testing.assert_allclose(kinestat.fk(model, np.asarray(s["q"])), T, atol=1e-9)
    assert main(["ik", str(arm_path("ur10")), "--tip", "tool0", "--pose", pose, "--all"]) == 0
    assert "is a family" in capsys.readouterr().out


def _shoulder_singular_configs(model, n, seed):
    """Configurations whose wrist point (axes 5 and 6 meet) lies in the plane of axis 1 and
    axis 2's normal: θ2 by root finding on the signed distance from that plane."""
    from scipy.optimize import brentq

    from kinestat.serial.analytic.geometry import classify
    from kinestat.serial.analytic.subproblems import rotation_matrix

    _, data = classify(model)
    ax = data["axes"]
    T0inv = np.linalg.inv(ax.T0)

    def signed(q):
        g = kinestat.fk(model, q) @ T0inv
        v = g[:3, :3] @ data["p56"] + g[:3, 3] - ax.r[0]
        return float(v @ np.cross(ax.w[0], rotation_matrix(ax.w[0], q[0]) @ ax.w[1]))

    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        q = rng.uniform(-3, 3, 6)
        ts = np.linspace(-3, 3, 61)
        f = [signed(np.r_[q[0], t, q[2:]]) for t in ts]
        k = next((i for i in range(60) if f[i] * f[i + 1] < 0), None)
        if k is not None:
            t = brentq(lambda t, q=q: signed(np.r_[q[0], t, q[2:]]), ts[k], ts[k + 1],
                       xtol=1e-15)
            out.append(np.r_[q[0], t, q[2:]])
    return np.array(out)


def test_ur_shoulder_singularity_is_a_double_root_not_a_family():
    """The UR's shoulder singularity (wrist point on the cylinder of radius |d| about axis 1,
    d the shoulder offset ≠ 0) merges the two θ1 branches: a finite set, no self-motion."""
    model = ur5()
    q = _shoulder_singular_configs(model, 8, seed=1)
    s = np.linalg.svd(kinestat.jacobian(model, q), compute_uv=False)
    assert np.all(s[:, -1] < 1e-12 * s[:, 0])
    T = kinestat.fk(model, q)
    res = ik_all(model, T)
    assert not res.singular.any()
    d = np.where(res.valid, wrapped_distance(res.q, q[:, None]), np.inf).min(axis=1)
    assert np.all(d < 1e-6)  # a double root: about sqrt(eps) accurate
    assert np.max(np.hypot(*slot_residuals(model, res, T))) < 1e-9
