"""Probing the surface's normal before the force is raised (the follow task, issue 13): the
plane fitted to touches around the first contact, and its use on the simulated cell."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinestat.app.control_run import SimulatedCell
from kinestat.control.contact_estimate import fit_plane
from kinestat.control.follow import FollowConfig
from kinestat.control.probe import (
    PROBE_TUNING,
    probe_normal,
    probe_offsets,
    probe_step,
    start_probe,
)
from kinestat.errors import InputError

from .test_follow import F_HAT, Y, _base, _follow, _true_normal_force


def _frame(n):
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, a)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def test_fit_plane_recovers_random_planes_in_a_batch():
    rng = np.random.default_rng(5)
    B, k = 40, 7
    n_true = rng.normal(size=(B, 3))
    n_true /= np.linalg.norm(n_true, axis=1, keepdims=True)
    approach = -n_true + rng.uniform(-0.5, 0.5, (B, 3))  # touched from outside, obliquely
    pts = np.empty((B, k, 3))
    for i in range(B):
        u, v = _frame(n_true[i])
        c = rng.uniform(-500, 500, 3)
        a, b = rng.uniform(-5, 5, (2, k))
        pts[i] = c + a[:, None] * u + b[:, None] * v
    n, rms, spread = fit_plane(pts, approach)
    assert n.shape == (B, 3) and rms.shape == (B,) and spread.shape == (B,)
    assert np.allclose(np.sum(n * n_true, axis=1), 1.0, atol=1e-12)  # facing the tool
    assert np.all(rms < 1e-9) and np.all(spread > 0.5)
    for i in range(3):  # the batch equals one call per row
        ni, ri, si = fit_plane(pts[i], approach[i])
        assert np.allclose(ni, n[i], atol=1e-14) and si == pytest.approx(spread[i])
    # heights off the plane by ±h alternately: the RMS residual is h
    sq = np.array([[1, 1, 0.1], [-1, -1, 0.1], [1, -1, -0.1], [-1, 1, -0.1]])
    n1, rms1, _ = fit_plane(sq, [0.0, 0.0, -1.0])
    assert n1[2] == pytest.approx(1.0) and rms1 == pytest.approx(0.1)
    with pytest.raises(ValueError):
        fit_plane(np.zeros((2, 3)), [0.0, 0.0, 1.0])


def _angle_deg(a, b) -> float:
    return math.degrees(math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b)))


def _quadric_touches(offsets, approach, grad, hess):
    """Surface points of the height field h(o) = g·o + ½ oᵀ H o over the plane ⊥ approach
    (height measured against the approach): the touch at each lateral offset o."""
    approach = approach / np.linalg.norm(approach)
    u, v = _frame(approach)
    pts = []
    for o in offsets:
        x, y = float(o @ u), float(o @ v)
        xy = np.array([x, y])
        h = float(grad @ xy + 0.5 * xy @ hess @ xy)
        pts.append(o - h * approach)
    normal = -approach - grad[0] * u - grad[1] * v  # ∇ of (height − h(x, y)) at the centre
    return np.asarray(pts), normal / np.linalg.norm(normal)


@pytest.mark.parametrize("seed", range(6))
def test_the_probe_pattern_measures_a_curved_surface_normal_at_its_centre(seed):
    # the pattern is symmetric about the centre, so the fitted slope is the central
    # difference: exact for any quadric (a cylinder of 150 mm is near one over ±3 mm)
    rng = np.random.default_rng(seed)
    approach = F_HAT + rng.uniform(-0.2, 0.2, 3)
    approach /= np.linalg.norm(approach)
    travel = Y + rng.uniform(-0.3, 0.3, 3)
    offs = [np.zeros(3), *probe_offsets(travel, approach, PROBE_TUNING.span_mm)]
    grad = rng.uniform(-0.15, 0.15, 2)
    A = rng.uniform(-1 / 150, 1 / 150, (2, 2))
    hess = A + A.T
    pts, n_true = _quadric_touches(offs, approach, grad, hess)
    n, fit = probe_normal(pts, n_true, approach)
    assert fit["used"] and fit["points"] == 6
    assert _angle_deg(n, n_true) < 1e-9
    # a one-sided pattern (centre, across, ahead) is biased by the curvature: the symmetry
    # is what makes the centre's normal exact
    one_sided = [offs[0], offs[1], offs[4]]
    p3, _ = _quadric_touches(one_sided, approach, grad, hess)
    n3, _ = probe_normal(p3, n_true, approach)
    if np.abs(hess).max() > 1e-3:
        assert _angle_deg(n3, n_true) > 1e-3


def test_probe_normal_falls_back_on_collinear_or_rough_touches():
    guess = np.array([0.0, 0.0, 1.0])
    down = np.array([0.0, 0.0, -1.0])
    line = [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0.001]]
    n, fit = probe_normal(line, guess, down)
    assert not fit["used"] and np.array_equal(n, guess)
    step = [[0, 0, 0], [3, 0, 0], [0, 3, 2.0], [-3, 0, 0], [0, -3, 2.0], [0, 0, 0]]  # a groove
    n, fit = probe_normal(step, guess, down)
    assert not fit["used"] and fit["fit_rms"] > 0.5
    steep = [[0, 0, 0], [3, 0, 3.5], [0, 3, 0], [-3, 0, -3.5], [0, -3, 0]]
    n, fit = probe_normal(steep, guess, down)  # 49° from the force's direction: not this
    assert not fit["used"]
    # the normal faces against the approach, whatever the SVD's sign
    flat = [[0, 0, 0], [3, 0, 0.3], [0, 3, 0], [-3, 0, -0.3], [0, -3, 0]]
    for a in (down, -down):
        n, fit = probe_normal(flat, a * -1.0, a)
        assert float(n @ a) < 0 and fit["used"]


def test_probe_span_is_checked(tmp_path):
    base = _base(tmp_path)
    for bad in (-1.0, 25.0, float("nan")):
        with pytest.raises(InputError, match="probe_span"):
            FollowConfig(base=base, travel=10.0, travel_dir=Y, probe_span=bad)


@pytest.mark.parametrize("ideal", [True, False])
def test_with_friction_the_probe_finds_the_normal_the_force_cannot(tmp_path, ideal):
    # mu = 0.3 on the default plane (tilted from F_req): at first contact the tip sticks and
    # its force lies inside the friction cone, off the normal; the probe's touches give the
    # normal, and before the first slip the true normal force is then held as measured
    cell = SimulatedCell(friction=0.3, ideal_sensor=ideal)
    prep, rep, out = _follow(tmp_path / "probe", cell=cell, travel=10.0)
    assert out["completed"], rep.stop_reason
    probe = [c for c in rep.cycles if c.get("action") == "probe"]
    assert probe and "p" in out["states"]
    # S6 is not turned while probing, and it ends with the fit
    s6 = np.array([c["s6"] for c in probe])
    assert np.allclose(s6, s6[0], atol=1e-9)
    fit = next(c["probe"] for c in rep.cycles if c.get("probe"))
    assert fit["used"] and fit["points"] >= 6
    settle = [c for c in rep.cycles if c["phase"] == "settle"]
    ang = math.degrees(math.acos(min(1.0, float(settle[0]["normal_estimate"]
                                                 @ settle[0]["true_normal"]))))
    assert ang < (0.05 if ideal else 1.5)
    # without the probe the first contact force's direction is the normal estimate: off by
    # about the plane's tilt from the approach (the stuck tip's force stays near the tool axis)
    prep0, rep0, out0 = _follow(tmp_path / "none", cell=cell, travel=10.0, probe_span=0.0)
    assert "p" not in out0["states"]
    settle0 = [c for c in rep0.cycles if c["phase"] == "settle"]
    ang0 = math.degrees(math.acos(min(1.0, float(settle0[0]["normal_estimate"]
                                                  @ settle0[0]["true_normal"]))))
    assert ang0 > 3.0 * max(ang, 0.3)
    if ideal:  # while the tip sticks before the first slip (the simulator's tip has not
        # moved 0.05 mm) the true normal force is the measured one (the probe's gain)
        def pre_slip_err(rep_):
            trav = [c for c in rep_.cycles if c["phase"] == "travel"]
            tip0 = np.asarray(trav[0]["true_tip"])
            pre = []
            for c in trav:
                if np.linalg.norm(np.asarray(c["true_tip"]) - tip0) > 0.05:
                    break
                pre.append(c)
            assert len(pre) > 30  # the breakaway tilt grows for a while
            return max(abs(_true_normal_force(c) - 4.0) for c in pre[5:])
        assert pre_slip_err(rep) < 0.05 < pre_slip_err(rep0)


def _run_probe(surface_height, approach, travel_dir, span=PROBE_TUNING.span_mm, step=0.25,
               max_cycles=400):
    """Drive :func:`probe_step` against a rigid height field (no compliance: the tip is the
    surface point under the commanded tool point once that point reaches the surface)."""
    d = np.asarray(approach, dtype=float)
    d /= np.linalg.norm(d)
    u, v = _frame(d)

    def height(p):  # the surface's height against d at p's lateral position
        return surface_height(float(p @ u), float(p @ v))

    def touching(p):
        return -float(p @ d) <= height(p)

    tp = np.zeros(3)
    while not touching(tp):  # the approach
        tp = tp + step * d
    tip = tp - (-float(tp @ d) - height(tp)) * -d  # the surface point under the tool point
    pr = start_probe(tip, tp, d, travel_dir, span)
    commanded = [tp]
    for _ in range(max_cycles):
        contact = touching(tp)
        tip = tp + (-float(tp @ d) - height(tp)) * d if contact else tp
        ps = probe_step(pr, tp, contact, tip, step)
        pr = ps.probe
        if ps.reason or ps.done:
            return ps, commanded
        tp = ps.tool_point
        commanded.append(tp)
    raise AssertionError("the probe did not finish")


@pytest.mark.parametrize("seed", range(4))
def test_probe_step_touches_a_surface_and_finds_its_normal(seed):
    rng = np.random.default_rng(seed)
    approach = np.array([0.0, 0.0, -1.0]) + rng.uniform(-0.2, 0.2, 3)
    approach /= np.linalg.norm(approach)
    g = rng.uniform(-0.15, 0.15, 2)  # slopes up to ~8.5°
    k = rng.uniform(-1 / 150, 1 / 150, 2)  # and curvature
    h0 = -rng.uniform(2.0, 4.0)  # the surface ahead of the start

    def h(x, y):
        return h0 + g[0] * x + g[1] * y + 0.5 * (k[0] * x * x + k[1] * y * y)

    travel = np.array([0.0, 1.0, 0.0]) + rng.uniform(-0.2, 0.2, 3)
    step = 0.25
    ps, commanded = _run_probe(h, approach, travel, step=step)
    assert ps.done and not ps.reason
    pr = ps.probe
    assert pr.index == len(pr.offsets) == 5
    # every touch is a surface point; the last is back at the centre
    u, v = _frame(approach)
    for p in pr.points:
        assert -float(p @ approach) == pytest.approx(h(float(p @ u), float(p @ v)), abs=1e-9)
    assert np.linalg.norm(pr.points[-1] - pr.points[0]) < step + 1e-9
    # the line of travel: the first contact, behind, ahead, the centre again
    assert len(pr.line) == 4
    # no command pushes more than one approach step into the surface
    for tp in commanded:
        penetration = h(float(tp @ u), float(tp @ v)) + float(tp @ approach)
        assert penetration <= step + 1e-9
    n, fit = probe_normal(pr.points, -approach, approach)
    n_true = -approach - g[0] * u - g[1] * v
    n_true /= np.linalg.norm(n_true)
    assert fit["used"]
    # the touches are up to one approach step off the offsets (the descent's resolution):
    # the curvature then leaves a small slope error, |κ| step ≈ 0.002 rad at most
    assert _angle_deg(n, n_true) < 0.15


def test_probe_step_stops_where_there_is_no_surface():
    # a ledge: the surface falls away 30 mm beyond x = 2 mm (the first touch across the
    # travel is at x = +3 mm): the descent gives up with a reason naming the offset
    def h(x, y):
        return -3.0 if x < 2.0 else -33.0

    ps, commanded = _run_probe(h, [0.0, 0.0, -1.0], [0.0, 1.0, 0.0])
    assert ps.reason.startswith("probing: no surface within 20 mm") and not ps.done
    assert "offset" in ps.reason and "--probe-span" in ps.reason
    assert max(-float(tp[2]) for tp in commanded) <= 3.0 + 20.0 + 1.0
