"""The follow task (issue 13 items 3-5): slide along an unknown plane or cylinder holding the
normal force, on the in-process simulated cell (the thesis's calibrated cell)."""

from __future__ import annotations

import functools
import math
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest

from kinestat.app.control_run import (
    DEFAULT_START,
    ControlRequest,
    CylinderSpec,
    SimulatedCell,
    prepare_control,
    report_dict,
)
from kinestat.app.sim_cell import InProcessIO, start_counts
from kinestat.control.controller import THESIS_FORCE_DIRECTION, start
from kinestat.control.follow import (
    CONE_SLACK_DEG,
    LEARN_CHORDS,
    ROLL_WEIGHT,
    TRAVEL_TOL,
    FollowConfig,
    FollowState,
    _creeping,
    _engages,
    _friction_hint,
    _normal_in_cone,
    _track_roll,
    decide_follow,
    default_travel_dir,
    estimate_normal,
)
from kinestat.control.log import CycleLog
from kinestat.control.loop import run
from kinestat.control.wrench import measure
from kinestat.errors import InputError
from kinestat.sim.surface import Cylinder

START = np.array([float(v) for v in DEFAULT_START.split(",")])
F_HAT = np.asarray(THESIS_FORCE_DIRECTION)
Y = np.array([0.0, 1.0, 0.0])


def _follow(tmp_path, *, travel=50.0, travel_dir=Y, cell=None, force=4.0, **kw):
    req = ControlRequest(force=force * F_HAT, start_tool_point=START,
                         cell=cell or SimulatedCell(), task="follow", travel=travel,
                         travel_dir=np.asarray(travel_dir, dtype=float), **kw)
    prep = prepare_control(req)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with CycleLog(tmp_path / "log.jsonl") as log:
        rep = run(prep.config, io, log, decide_fn=functools.partial(decide_follow, prep.follow))
    return prep, rep, report_dict(prep, rep)


def _true_normal_force(c) -> float:
    return -float(np.asarray(c["true_force"]) @ np.asarray(c["true_normal"]))


def _true_arc(prep, cycles) -> float:
    """The true tip's distance travelled on the surface, computed from the simulator's tips:
    a straight line on a plane; on a cylinder the arc about the axis and the axial part."""
    trav = [c for c in cycles if c["phase"] == "travel"]
    a, b = trav[0]["true_tip"], trav[-1]["true_tip"]
    wp = prep.cell.workpiece
    if not isinstance(wp, Cylinder):
        return float(np.linalg.norm(b - a))
    ra, rb = wp._radial(a), wp._radial(b)
    ang = math.atan2(np.linalg.norm(np.cross(ra, rb)), float(ra @ rb))
    axial = float((b - a) @ wp.axis)
    return math.hypot(wp.radius * ang, axial)


def _check_acceptance(prep, rep, out, *, rms_limit: float, travel=50.0) -> None:
    assert out["completed"] and rep.converged, rep.stop_reason
    assert out["contact_lost"] == 0
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    err = np.array([_true_normal_force(c) - 4.0 for c in trav])
    assert np.max(np.abs(err)) <= 0.5
    assert math.sqrt(np.mean(err ** 2)) <= rms_limit
    assert out["normal_force_rms_error"] <= rms_limit
    assert abs(out["travel"] - travel) <= 1.0
    assert abs(_true_arc(prep, rep.cycles) - travel) <= 1.0
    # the normal estimate follows the true normal (friction-free: the force direction)
    ang = [math.degrees(math.acos(min(1.0, float(c["normal_estimate"] @ c["true_normal"]))))
           for c in trav]
    assert max(ang) < 3.0


@pytest.mark.parametrize("ideal, rms_limit", [(False, 0.2), (True, 0.05)])
def test_follow_the_default_tilted_plane(tmp_path, ideal, rms_limit):
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(ideal_sensor=ideal))
    _check_acceptance(prep, rep, out, rms_limit=rms_limit)
    for key in ("tool_point", "force", "true_force", "normal_estimate", "true_normal",
                "travel"):
        assert key in out["cycles"][-1]


@pytest.mark.parametrize("ideal, rms_limit", [(False, 0.2), (True, 0.05)])
def test_follow_a_cylinder_of_radius_200(tmp_path, ideal, rms_limit):
    cyl = CylinderSpec(radius=200.0, axis=np.array([0.0, 0.0, 1.0]))
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(ideal_sensor=ideal, cylinder=cyl))
    _check_acceptance(prep, rep, out, rms_limit=rms_limit)
    # the path really curved: the true normal turned by about travel / radius
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    turn = math.degrees(math.acos(float(trav[0]["true_normal"] @ trav[-1]["true_normal"])))
    assert turn == pytest.approx(math.degrees(50.0 / 200.0), abs=1.0)


@pytest.mark.parametrize("seed", [3, 11])
def test_follow_random_workpieces(tmp_path, seed):
    rng = np.random.default_rng(seed)
    if seed % 2:  # a plane: tilt 0-8° from -F_req in a random azimuth
        tilt, az = math.radians(rng.uniform(0, 8)), rng.uniform(0, 2 * math.pi)
        u = np.cross(F_HAT, Y)
        u /= np.linalg.norm(u)
        v = np.cross(F_HAT, u)
        n = -(math.cos(tilt) * F_HAT + math.sin(tilt) * (math.cos(az) * u + math.sin(az) * v))
        cell = SimulatedCell(plane_point=START + rng.uniform(1.5, 4.0) * F_HAT, plane_normal=n)
    else:  # a cylinder, radius 150-400 mm, axis roughly across the travel
        axis = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.2, 0.2), 1.0])
        cell = SimulatedCell(cylinder=CylinderSpec(radius=rng.uniform(150, 400), axis=axis))
    travel_dir = Y + rng.uniform(-0.2, 0.2, 3)
    prep, rep, out = _follow(tmp_path, cell=cell, travel=20.0, travel_dir=travel_dir)
    _check_acceptance(prep, rep, out, rms_limit=0.2, travel=20.0)


def _deg(a, b) -> float:
    return math.degrees(math.acos(max(-1.0, min(1.0, float(a @ b) / math.sqrt(
        float(a @ a) * float(b @ b))))))


def test_a_kept_normal_is_brought_into_the_measured_force_cone():
    rng = np.random.default_rng(5)
    for _ in range(300):
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        n0 = u + rng.uniform(0.0, 0.5) * rng.normal(size=3)
        n0 /= np.linalg.norm(n0)
        mu = float(rng.choice([0.0, rng.uniform(0.0, 0.6)]))
        n = _normal_in_cone(n0, u, mu)
        bound = math.degrees(math.atan(mu)) + CONE_SLACK_DEG
        assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
        if _deg(n0, u) <= bound:  # inside the cone (with the slack): kept as it was
            assert n is n0
            continue
        # onto the cone's bound, in the plane of the kept estimate and the force, towards it
        assert _deg(n, u) == pytest.approx(bound, abs=1e-9)
        assert abs(float(np.cross(u, n0) @ n)) < 1e-12
        assert _deg(n, n0) == pytest.approx(_deg(n0, u) - bound, abs=1e-9)


def test_a_frictionless_tip_pushed_back_across_the_travel_keeps_a_fresh_normal(tmp_path):
    # a frictionless R = 159 mm cylinder travelled 35° off its axis (a random workpiece of a
    # wider campaign, 2026-12-03): the tip swings across the travel (the top's soft tangential
    # mode less N/R), so in some cycles its advance is negative and it counts as not sliding.
    # The normal kept then (1.2-1.9° stale) drove a limit cycle: S6 turned onto it, the tip
    # jumped 4.5 mm every four cycles and the run overshot its travel by 3 mm. Once μ̂ (≈ 0) is
    # measured the kept normal lies in the force's cone (here: the force's own direction).
    cyl = CylinderSpec(radius=159.17, axis=np.array([-0.1292, -0.5368, -0.8370]))
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(cylinder=cyl), travel=35.0,
                             travel_dir=np.array([-0.2308, 0.0596, -0.9712]), force=4.1)
    assert out["completed"] and out["contact_lost"] == 0, rep.stop_reason
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    ang = [_deg(np.asarray(c["normal_estimate"]), np.asarray(c["true_normal"])) for c in trav]
    assert max(ang[5:]) < 1.0  # 1.9° with the normal kept stale
    assert abs(out["travel"] - 35.0) <= 1.0
    assert abs(_true_arc(prep, rep.cycles) - 35.0) <= 1.0
    err = np.array([_true_normal_force(c) - 4.1 for c in trav])
    assert math.sqrt(np.mean(err ** 2)) <= 0.2 and np.max(np.abs(err)) <= 0.5


@dataclass(frozen=True)
class _Roll:
    roll_rate: float = 0.0


def test_the_roll_rate_is_the_mean_turn_about_the_travel_per_mm():
    t = np.array([0.0, 1.0, 0.0])
    st = _Roll()
    for _ in range(200):  # a steady roll (a surface's geodesic torsion): its rate per mm
        st = _track_roll(st, 0.004 * 0.5 * t + np.array([0.003, 0.0, 0.0]), t, 0.5)
    assert st.roll_rate == pytest.approx(0.004, rel=1e-9)
    assert _track_roll(st, t, t, 0.0) is st  # no step: unchanged
    st = _Roll()
    for k in range(200):  # a swing back and forth averages out to ROLL_WEIGHT / (2 - w)
        st = _track_roll(st, (-1.0) ** k * 0.017 * t, t, 1.0)
    assert abs(st.roll_rate) == pytest.approx(ROLL_WEIGHT / (2.0 - ROLL_WEIGHT) * 0.017,
                                              rel=1e-6)


def test_a_frictionless_tip_does_not_swing_across_a_tight_cylinder_travelled_near_its_axis(
        tmp_path):
    # R = 165 mm, 5.2 N, frictionless, travelled 12° off the axis (a wider campaign's random
    # workpiece, 2026-12-03): N/R is near the top's tangential stiffness at the tip, and each
    # turn of S6 about the travel, with the force turning with the tool, swung the tip 15 mm
    # round the cylinder and the normal ~4° (RMS 0.568 N, max 0.801 N). Held along the normal
    # while S6 turns, the force keeps the tip on its line.
    cyl = CylinderSpec(radius=165.4, axis=np.array([-0.1985, -0.3602, -0.9118]))
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(cylinder=cyl), travel=30.0,
                             travel_dir=np.array([0.2958, 0.1596, 0.9439]), force=5.17)
    assert out["completed"] and out["contact_lost"] == 0, rep.stop_reason
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    axis = prep.cell.workpiece.axis
    swing = [float((np.asarray(b["true_tip"]) - np.asarray(a["true_tip"]))
                   @ np.cross(np.asarray(b["true_normal"]), axis))
             for a, b in zip(trav, trav[1:], strict=False)]
    # mm a cycle round the cylinder, RMS: 3.5 mm now, 14 mm (±15 mm every cycle) without
    assert math.sqrt(np.mean(np.square(swing))) < 6.0
    err = np.array([_true_normal_force(c) - 5.17 for c in trav])
    assert math.sqrt(np.mean(err ** 2)) <= 0.2 and np.max(np.abs(err)) <= 0.5
    assert abs(_true_arc(prep, rep.cycles) - 30.0) <= 1.0


@pytest.mark.parametrize("radius", [200.0, 300.0])
def test_a_frictionless_slide_feeds_the_surface_turn_forward(tmp_path, radius):
    # Frictionless, S6 used to wait for the 0.3° dead band behind the surface's turn, then
    # turned up to 0.6° in one cycle, and the free tip (held by the top's soft tangential
    # stiffness less N/R) ran ahead and back: over these 30 mm S6 was 0.54° off the true
    # normal at worst (R = 200 mm) and the tip's advance a cycle varied by 0.35 mm (std,
    # R = 300 mm). With κ̂ fed forward once it is known (FEED_CURVATURE_CYCLES) S6 turns with
    # the surface every cycle.
    cyl = CylinderSpec(radius, np.array([0.0, 0.0, 1.0]))
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(cylinder=cyl), travel=30.0)
    assert out["completed"] and out["contact_lost"] == 0, rep.stop_reason
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    tilt = [_deg(-np.asarray(c["s6"]), np.asarray(c["true_normal"])) for c in trav[10:]]
    tips = np.array([c["true_tip"] for c in trav])
    advance = np.linalg.norm(np.diff(tips, axis=0), axis=1)[5:]
    assert max(tilt) < 0.4
    assert float(np.std(advance)) < 0.3
    err = np.array([_true_normal_force(c) - 4.0 for c in trav])
    assert math.sqrt(np.mean(err ** 2)) <= 0.05 and np.max(np.abs(err)) <= 0.3
    assert abs(_true_arc(prep, rep.cycles) - 30.0) <= 1.0


def test_a_frictionless_slide_near_the_soft_limit_turns_s6_by_half_its_misalignment(tmp_path):
    # 5.95 N on R = 285 mm, travelled 47° off the axis (the fourth campaign draw's run 17,
    # 2026-12-04): near the soft mode's limit a turn of S6 swings the tip back across the
    # surface, where the normal differs by about as much as the turn. Turned onto the whole
    # misalignment, S6 overshot the new normal every time and the tip swung ±3 mm a cycle
    # (over these 30 mm: advance std 1.52 mm, RMS 0.123 N, max 0.378 N; over the draw's 62 mm
    # it ended 2.8 mm long). Half the misalignment a cycle (FRICTIONLESS_TURN_GAIN) converges.
    cyl = CylinderSpec(284.63, np.array([-0.1255, -0.2186, -0.9739]))
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(cylinder=cyl), travel=30.0,
                             travel_dir=np.array([0.0575, 0.8616, 0.5085]), force=5.95)
    assert out["completed"] and out["contact_lost"] == 0, rep.stop_reason
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    tips = np.array([c["true_tip"] for c in trav])
    advance = np.linalg.norm(np.diff(tips, axis=0), axis=1)[5:]
    assert float(np.std(advance)) < 1.0  # 0.58 mm now
    err = np.array([_true_normal_force(c) - 5.95 for c in trav])
    assert math.sqrt(np.mean(err ** 2)) <= 0.08 and np.max(np.abs(err)) <= 0.3
    assert abs(_true_arc(prep, rep.cycles) - 30.0) <= 1.0


def test_only_a_frictionless_slide_damps_the_turn():
    from types import SimpleNamespace

    from kinestat.control import follow

    def st(**kw):
        base = dict(tilting=False, friction_samples=follow.LEARN_CHORDS, friction_ratio=0.0)
        return SimpleNamespace(**{**base, **kw})
    assert follow._frictionless_slide(st())
    assert not follow._frictionless_slide(st(tilting=True))  # the automatic tilt
    assert not follow._frictionless_slide(st(friction_samples=0))  # not slid yet
    assert not follow._frictionless_slide(st(friction_ratio=follow.FRICTION_HINT_RATIO))
    assert 0.0 < follow.FRICTIONLESS_TURN_GAIN < 1.0


def _normal_and_tangent(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A random unit normal and a random unit tangent to it."""
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    t = np.cross(n, rng.normal(size=3))
    return n, t / np.linalg.norm(t)


def test_a_frictionless_turn_halves_its_gain_about_an_axis_it_overshot():
    from dataclasses import dataclass

    from kinestat.control import follow

    @dataclass(frozen=True)
    class _St:
        turn_gain: tuple = (follow.FRICTIONLESS_TURN_GAIN, follow.FRICTIONLESS_TURN_GAIN)
        last_turn: tuple = (0.0, 0.0)

    n, t = np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])
    b = np.cross(n, t)
    g0 = follow.FRICTIONLESS_TURN_GAIN
    w, st = follow._damped_turn(_St(), 0.004 * b + 0.002 * t, n, t)  # no turn before
    np.testing.assert_allclose(w, g0 * (0.004 * b + 0.002 * t), atol=1e-15)
    assert st.turn_gain == (g0, g0) and st.last_turn == pytest.approx((0.004, 0.002))
    # the pitch misalignment changed sign (the turn overshot it): its gain halves; the roll
    # kept its sign: its gain stays at the cap
    w, st = follow._damped_turn(st, -0.003 * b + 0.001 * t, n, t)
    assert st.turn_gain == (0.5 * g0, g0)
    np.testing.assert_allclose(w, -0.003 * 0.5 * g0 * b + 0.001 * g0 * t, atol=1e-15)
    for k in range(10):  # overshot every time: down to the floor, not below
        w, st = follow._damped_turn(st, (-1.0) ** k * 0.003 * b, n, t)
    assert st.turn_gain[0] == follow.MIN_TURN_GAIN
    # the roll had no turn in those cycles: its gain is kept
    assert st.turn_gain[1] == g0
    w, st = follow._damped_turn(st, st.last_turn[0] * b, n, t)  # same sign again: it grows
    assert st.turn_gain[0] == pytest.approx(1.25 * follow.MIN_TURN_GAIN)


def test_a_force_that_pushed_the_tip_along_its_slide_is_not_friction():
    from kinestat.control import follow

    rng = np.random.default_rng(7)
    for _ in range(50):
        n, g = _normal_and_tangent(rng)
        fn, mu = rng.uniform(1.0, 8.0), rng.uniform(0.05, 0.6)
        slide = rng.uniform(follow.CHORD_LENGTH, 10.0) * g
        # Coulomb friction opposes the slip: the tool drags the workpiece along it
        assert not follow._propelled(-fn * n + mu * fn * g, n, slide)
        # a frictionless tip that ran d round a convex surface of radius R: its force lies
        # along the normal there, turned by d/R towards the run from the normal it is
        # measured against
        d, radius = float(np.linalg.norm(slide)), rng.uniform(100.0, 500.0)
        n_there = math.cos(d / radius) * n + math.sin(d / radius) * g
        assert follow._propelled(-fn * n_there, n, slide)
        # too short a slide (the counts' jitter, a recoil) is not tested
        assert not follow._propelled(-fn * n_there, n, 0.1 * g)


def test_the_frictionless_feedforward_waits_for_a_curvature_held_four_cycles():
    """``_surface_turn`` without the automatic tilt: the turn is left alone until κ̂ has been
    estimated ``FEED_CURVATURE_CYCLES`` cycles in a row; from then on S6 turns by κ̂ Δs about
    n × t on top of the feedback turn (with the automatic tilt the ramp starts at once)."""
    from types import SimpleNamespace

    from kinestat.control import follow

    config = SimpleNamespace(max_turn_deg=1.0)
    n, t = np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])
    s6 = -n
    kappa, step = 1.0 / 250.0, 1.0
    feedback = np.array([0.0, 0.0, 0.001])
    need = follow.FEED_CURVATURE_CYCLES
    for cycles in range(need + 3):
        st = SimpleNamespace(tilting=False, friction_samples=3, friction_ratio=0.0,
                             breakaway=0.0, curvature=kappa, curvature_cycles=cycles)
        w, feed = follow._surface_turn(config, st, s6, n, t, step, feedback)
        assert feed == 1.0
        if cycles < need:
            assert w is feedback
        else:
            np.testing.assert_allclose(w, feedback + kappa * step * np.cross(n, t), atol=1e-15)
    st = SimpleNamespace(tilting=False, curvature=kappa, curvature_cycles=need)
    assert follow._surface_turn(config, st, s6, n, t, 0.0, feedback)[0] is feedback  # no step


def test_estimate_normal_removes_friction_along_the_path():
    rng = np.random.default_rng(0)
    for _ in range(20):
        n, t = _normal_and_tangent(rng)
        fn, mu = rng.uniform(1, 8), rng.uniform(0, 0.5)
        F = -fn * n + mu * fn * t  # the tool drags the workpiece along t
        np.testing.assert_allclose(estimate_normal(F, t), n, atol=1e-12)
        np.testing.assert_allclose(estimate_normal(-fn * n), n, atol=1e-12)


def _base(tmp_path, force=4.0, cell=None):
    req = ControlRequest(force=force * F_HAT, start_tool_point=START, cell=cell or SimulatedCell())
    return prepare_control(req).config


def test_bad_requests_are_refused_before_any_motion(tmp_path):
    base = _base(tmp_path)
    with pytest.raises(InputError, match="approach direction"):
        FollowConfig(base=base, travel=50.0, travel_dir=F_HAT + 0.05 * Y)
    with pytest.raises(InputError, match="cannot be carried"):
        FollowConfig(base=_base(tmp_path, force=30.0), travel=50.0, travel_dir=Y)
    with pytest.raises(InputError, match="travel"):
        FollowConfig(base=base, travel=-1.0, travel_dir=Y)
    with pytest.raises(InputError, match="travel direction"):
        FollowConfig(base=base, travel=10.0, travel_dir=[0.0, 0.0, 0.0])


def test_the_default_travel_direction_is_across_the_approach():
    """No --travel-dir: +y made perpendicular to F_req, +x when F_req is within 30° of ±y;
    always a unit vector at 90° from F_req, in the plane of F_req and the axis used."""
    prep = prepare_control(ControlRequest(force=4.0 * F_HAT, start_tool_point=START,
                                          cell=SimulatedCell(), task="follow"))
    t = prep.follow.travel_dir
    assert np.allclose(t, default_travel_dir(F_HAT)) and prep.header["travel_dir"] is not None
    rng = np.random.default_rng(7)
    for d in rng.normal(size=(500, 3)):
        d /= np.linalg.norm(d)
        t = default_travel_dir(d)
        assert abs(np.linalg.norm(t) - 1.0) < 1e-12 and abs(t @ d) < 1e-12
        near_y = abs(d[1]) > math.cos(math.radians(30.0))
        axis = np.array([1.0, 0.0, 0.0]) if near_y else np.array([0.0, 1.0, 0.0])
        assert abs(np.linalg.det(np.stack([t, d, axis]))) < 1e-12  # in span{F_req, axis}
        assert t @ axis > 0.0  # towards the axis, not away from it
    with pytest.raises(InputError, match="approach direction"):
        default_travel_dir([0.0, 0.0, 0.0])


def test_travel_into_the_surface_stops_at_contact_with_a_reason(tmp_path):
    # a plane tilted 20° from -F_req; the travel direction is (minus) its normal: 20° from the
    # approach (accepted before contact), along the normal once it is measured
    u = np.cross(F_HAT, Y)
    u /= np.linalg.norm(u)
    t = math.radians(20.0)
    n = -(math.cos(t) * F_HAT + math.sin(t) * u)
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(plane_normal=n), travel_dir=-n)
    assert not out["completed"]
    assert "into the surface" in rep.stop_reason
    assert out["travel"] == 0.0


def test_decide_follow_is_pure(tmp_path):
    req = ControlRequest(force=4.0 * F_HAT, start_tool_point=START, cell=SimulatedCell(),
                         task="follow", travel_dir=Y)
    prep = prepare_control(req)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    counts = io.robot_counts()
    from kinestat.control.controller import axis_counts_to_q

    q = axis_counts_to_q(prep.config.model, counts)
    cmd0, st = start(prep.config, q, counts_now=counts)
    io.move(cmd0.axis_counts)
    for _ in range(120):  # approach until contact, probe the surface, until settling
        m = measure(prep.config.model, axis_counts_to_q(prep.config.model, io.robot_counts()),
                    io.sensor().counts, st.top_pose)
        c1, s1 = decide_follow(prep.follow, st, m)
        c2, s2 = decide_follow(prep.follow, st, m)
        assert c1.kind == c2.kind and np.array_equal(c1.axis_counts, c2.axis_counts)
        assert s1.phase == s2.phase and s1.cycle == s2.cycle == st.cycle + 1
        st = s1
        io.move(c1.axis_counts)
        if s1.phase not in ("approach", "probe"):
            break
    assert st.phase == "settle" and st.normal is not None


def test_follow_config_rejects_a_finished_state(tmp_path):
    base = _base(tmp_path)
    fc = FollowConfig(base=base, travel=10.0, travel_dir=Y)
    io_q = np.zeros(6)
    _, st = start(base, io_q)
    with pytest.raises(InputError, match="over"):
        decide_follow(fc, replace(st, done=True), None)


def test_friction_without_tilt_stops_safely_on_the_motion_range(tmp_path):
    # a sticking tip lags the flange; the top turns about it (Table 3-1's 4°) long before the
    # platform carries mu * F_n across the tool axis: a safe stop with the reason
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(friction=0.3), auto_tilt=False)
    assert not out["completed"] and not out["auto_tilt"]
    assert "Table 3-1" in rep.stop_reason and "refused by the envelope" in rep.stop_reason
    assert "the tip sticks" in rep.stop_reason and "--auto-tilt" in rep.stop_reason
    assert out["contact_lost"] == 0


def test_the_friction_hint_only_when_friction_is_seen_and_the_tilt_is_off(tmp_path):
    base = _base(tmp_path)
    _, st0 = start(base, np.zeros(6))
    st = FollowState(**vars(st0))
    assert _friction_hint(st) == ""  # a free (frictionless) tip: the refusal as it is
    assert _friction_hint(replace(st, friction_ratio=0.01)) == ""
    for seen in (replace(st, sticking=True), replace(st, friction_ratio=0.3)):
        assert "--auto-tilt" in _friction_hint(seen)
        assert _friction_hint(replace(seen, tilting=True)) == ""  # the tilt is on
    assert "0.30" in _friction_hint(replace(st, friction_ratio=0.3))


def test_the_automatic_tilt_switches_on_only_when_the_tip_sticks_under_a_step(tmp_path):
    base = _base(tmp_path)
    _, st0 = start(base, np.zeros(6))
    st = FollowState(**vars(st0))
    auto = FollowConfig(base=base, travel=10.0, travel_dir=Y)
    assert auto.auto_tilt is None  # the default
    stuck = replace(st, step=1.0, sticking=True)  # the last full step stuck too
    assert _engages(auto, stuck, advance=0.1)
    assert not _engages(auto, replace(stuck, sticking=False), advance=0.1)  # once only
    assert not _engages(auto, stuck, advance=0.6)  # slid
    assert not _engages(auto, replace(stuck, step=0.1), advance=0.0)  # an end step
    # with a travel step below ENGAGE_STEP its full steps count (else the tilt never came on)
    fine = replace(auto, travel_step=0.3)
    assert _engages(fine, replace(stuck, step=0.3), advance=0.05)
    assert not _engages(fine, replace(stuck, step=0.3), advance=0.2)  # it followed
    assert not _engages(fine, replace(stuck, step=0.1), advance=0.0)  # an end step
    assert not _engages(auto, replace(stuck, tilting=True), advance=0.0)  # already on
    # it slid before: only with a measured friction ratio
    assert not _engages(auto, replace(stuck, friction_samples=3, friction_ratio=0.01), 0.0)
    assert _engages(auto, replace(stuck, friction_samples=3, friction_ratio=0.2), 0.0)
    for cfg in (replace(auto, auto_tilt=False), replace(auto, auto_tilt=True),
                replace(auto, tilt_deg=5.0)):  # set either way, or a commanded tilt
        assert not _engages(cfg, stuck, advance=0.0)
    with pytest.raises(InputError, match="auto_tilt"):
        FollowConfig(base=base, travel=10.0, travel_dir=Y, auto_tilt="yes")
    # the first cycle's state carries the setting
    prep = prepare_control(ControlRequest(force=4.0 * F_HAT, start_tool_point=START,
                                          cell=SimulatedCell(), task="follow", travel_dir=Y))
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    from kinestat.control.controller import axis_counts_to_q

    q = axis_counts_to_q(prep.config.model, io.robot_counts())
    _, s0 = start(prep.config, q, counts_now=io.robot_counts())
    m = measure(prep.config.model, q, io.sensor().counts, s0.top_pose)
    for setting in (None, True, False):
        _, s1 = decide_follow(replace(prep.follow, auto_tilt=setting), s0, m)
        assert s1.tilting is (setting is True)


def test_with_a_short_travel_step_friction_still_switches_the_tilt_on(tmp_path):
    """``--travel-step 0.3`` (below ENGAGE_STEP) with μ = 0.3: the automatic tilt comes on and
    the run completes (before, the tip stuck under every step and the run stopped on the
    envelope at the start)."""
    prep, rep, out = _follow(tmp_path, travel=5.0, travel_step=0.3,
                             cell=SimulatedCell(friction=0.3))
    assert out["completed"], rep.stop_reason
    assert out["auto_tilt"] and out["contact_lost"] == 0
    assert abs(out["travel"] - 5.0) <= 1.0


def test_a_creeping_tip_counts_as_sliding_only_while_it_moves(tmp_path):
    """While μ is learnt, a tip that crept a chord counts as sliding (a friction sample) only
    in the cycles it moves on: once it stopped, its force falls back inside the cone and a
    sample would underestimate μ and tilt the normal estimate back."""
    _, st0 = start(_base(tmp_path), np.zeros(6))
    st = replace(FollowState(**vars(st0)), tangent=Y, tilting=True, friction_samples=1)
    path = tuple(np.array([0.0, 0.1 * k, 0.0]) for k in range(6))  # crept 0.5 mm along y
    assert _creeping(st, path, path[-1] + 0.05 * Y, advance=0.05)  # moving on
    assert not _creeping(st, path, path[-1], advance=0.0)  # stopped: the same chord
    assert not _creeping(st, path, path[-1] + 0.01 * Y, advance=0.01)  # below CREEP_MIN
    side = np.array([1.0, 0.0, 0.0])
    assert not _creeping(st, tuple(0.1 * k * side for k in range(6)), 0.55 * side, 0.05)
    assert not _creeping(replace(st, friction_samples=LEARN_CHORDS), path,
                         path[-1] + 0.05 * Y, advance=0.05)  # learnt: full chords only
    # the next sample needs a fresh chord: LEARN_CHORD_LENGTH crept since the last one
    assert not _creeping(replace(st, sample_tip=path[-1]), path, path[-1] + 0.05 * Y, 0.05)
    assert _creeping(replace(st, sample_tip=path[0]), path, path[-1] + 0.05 * Y, 0.05)


def test_by_default_friction_switches_the_automatic_tilt_on_and_the_run_completes(tmp_path):
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(friction=0.3))
    assert out["completed"], rep.stop_reason
    assert out["auto_tilt"] and out["auto_tilt_from_travel"] <= 1.0  # at the first steps
    assert out["contact_lost"] == 0 and abs(out["travel"] - 50.0) <= 1.0
    assert out["friction_estimate"] == pytest.approx(0.3, abs=0.02)
    # the steps the stuck tip did not follow are taken back before the tilt grows: the
    # commanded tool point returns along the travel to where it was before the first step
    cyc = rep.cycles
    first = next(i for i, c in enumerate(cyc) if c["phase"] == "travel")
    on = next(i for i, c in enumerate(cyc) if c.get("auto_tilt"))
    along = [float((c["tool_point"] - cyc[first - 1]["tool_point"]) @ Y)
             for c in cyc[first - 1:on + 4]]
    assert max(along) >= 1.5, along  # two stuck steps of 1 mm
    peak = int(np.argmax(along))  # (the breakaway's hold then moves it, turning the wrench)
    assert min(abs(a) for a in along[peak:]) <= 0.3, along
    # issue 13's acceptance on this default path (thesis sensor, true figures), the first
    # slip included: S6 leads the force when the tip breaks away, so the slip is a creep
    assert out["true_normal_force_max_error"] <= 0.5
    assert out["true_normal_force_rms_error"] <= 0.2
    # the breakaway's first turns hold the force: S6 turns, the stuck tip's force does not
    # (then both turn together)
    brk = [c for c in cyc[on:] if not c["friction_ratio"]]
    assert len(brk) > 30

    def turned(key, a, b):
        u, v = (np.asarray(cyc_[key], dtype=float) for cyc_ in (a, b))
        return math.degrees(math.acos(min(1.0, float(u @ v) / float(np.linalg.norm(u)
                                                                     * np.linalg.norm(v)))))
    held = [i for i in range(15) if turned("s6", brk[i], brk[i + 3]) >= 0.5
            and turned("true_force", brk[i], brk[i + 3]) <= 0.1]
    assert held, "no breakaway cycles turned S6 with the force held"
    # then it turns onto the cone's edge with the tool
    assert turned("true_force", brk[held[-1] + 3], brk[-1]) >= 5.0
    assert all(abs(_true_normal_force(c) - 4.0) <= 0.1 for c in brk[held[0]:held[-1] + 4])


def test_frictionless_runs_never_switch_the_automatic_tilt_on(tmp_path):
    # the default (automatic) gives the very commands of a run with the tilt off
    cyl = CylinderSpec(radius=200.0, axis=np.array([0.0, 0.0, 1.0]))
    for cell in (SimulatedCell(), SimulatedCell(cylinder=cyl, ideal_sensor=True)):
        runs = [_follow(tmp_path, travel=20.0, cell=cell, auto_tilt=a) for a in (None, False)]
        (_, rep_a, out_a), (_, rep_b, _) = runs
        assert out_a["completed"] and not out_a["auto_tilt"]
        assert out_a["auto_tilt_from_travel"] is None
        assert len(rep_a.cycles) == len(rep_b.cycles)
        for ca, cb in zip(rep_a.cycles, rep_b.cycles, strict=True):
            assert ca.get("axis_counts") == cb.get("axis_counts")
            np.testing.assert_array_equal(ca["tip"], cb["tip"])


def test_auto_tilt_follows_with_light_friction_and_learns_mu(tmp_path):
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(friction=0.1), auto_tilt=True)
    assert out["completed"], rep.stop_reason
    assert out["contact_lost"] == 0 and abs(out["travel"] - 50.0) <= 1.0
    assert out["true_normal_force_max_error"] <= 1.0
    # the friction ratio learnt from the chords is the simulator's mu
    assert rep.cycles[-1]["friction_ratio"] == pytest.approx(0.1, abs=0.03)


def test_the_carry_check_matches_what_the_simulated_cell_carries(tmp_path):
    # the simulated cell (thesis legs) has no contact equilibrium at 10 N along F_req: refused
    # before any motion; 7 N passes the check and the cell carries it while following
    with pytest.raises(InputError, match="cannot be carried"):
        FollowConfig(base=_base(tmp_path, force=10.0), travel=10.0, travel_dir=Y)
    prep, rep, out = _follow(tmp_path, force=7.0, travel=10.0)
    assert out["completed"], rep.stop_reason
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    assert max(abs(_true_normal_force(c) - 7.0) for c in trav) <= 0.5


def test_friction_03_the_normal_is_unbiased_and_the_force_held_once_sliding(tmp_path):
    # mu = 0.3 tilts the sliding tip's force 16.7° off the normal; the estimator removes it
    # (kinestat.control.contact_estimate) and the controller regulates F·n̂ along the cone edge
    prep, rep, out = _follow(tmp_path, cell=SimulatedCell(friction=0.3), auto_tilt=True)
    assert out["completed"], rep.stop_reason
    assert out["contact_lost"] == 0 and abs(out["travel"] - 50.0) <= 1.0
    assert out["friction_estimate"] == pytest.approx(0.3, abs=0.02)
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    # the friction force is measured: the simulator's tangential force, to 0.1 N once sliding
    for c in trav:
        tn, tf = np.asarray(c["true_normal"]), np.asarray(c["true_force"])
        true_ft = float(np.linalg.norm(tf - (tf @ tn) * tn))
        if c["friction_ratio"] > 0 and c["travel"] >= 5.0:
            assert c["tangential_force"] == pytest.approx(true_ft, abs=0.1)
    # once mu is measured and the breakaway tilt is gone (the last 30 mm): the normal estimate
    # is within 2° of the true normal, and the true normal force is held
    late = [c for c in trav if c["travel"] >= 20.0]
    assert len(late) >= 20
    ang = [math.degrees(math.acos(min(1.0, float(np.asarray(c["normal_estimate"])
                                                  @ np.asarray(c["true_normal"])))))
           for c in late]
    assert max(ang) <= 2.0
    err = [_true_normal_force(c) - 4.0 for c in late]
    assert float(np.sqrt(np.mean(np.square(err)))) <= 0.1
    assert max(abs(e) for e in err) <= 0.5
    # and over the whole travel, breakaway included: the acceptance (thesis sensor)
    assert out["true_normal_force_rms_error"] <= 0.2
    assert out["true_normal_force_max_error"] <= 0.5


@functools.cache
def _cylinder_friction_03(ideal: bool):
    """The R = 200 mm cylinder with μ = 0.3 on the default path: the automatic tilt switches
    itself on when the tip sticks (one run per sensor, shared by the tests below)."""
    cyl = CylinderSpec(radius=200.0, axis=np.array([0.0, 0.0, 1.0]))
    with tempfile.TemporaryDirectory() as tmp:
        prep, rep, out = _follow(Path(tmp), cell=SimulatedCell(friction=0.3, cylinder=cyl,
                                                               ideal_sensor=ideal))
        assert out["auto_tilt"]
        return prep, rep, out


def test_friction_03_cylinder_no_stick_slip_after_the_breakaway():
    """With the path's curvature fed forward, the tool keeps up with the turning normal: on the
    R = 200 mm cylinder (ideal sensor, μ = 0.3) the curvature estimate is 1/R and, once past
    the breakaway (travel ≥ 15 mm), the tip slides every cycle and the true normal force is
    held to the ideal sensor's 0.05 N RMS (the whole run, thesis sensor: the
    acceptance test below)."""
    prep, rep, out = _cylinder_friction_03(True)
    assert out["completed"], rep.stop_reason
    late = [c for c in rep.cycles if c["phase"] == "travel" and 15.0 <= c["travel"] <= 49.5]
    assert len(late) >= 25
    assert all(c["curvature"] == pytest.approx(1 / 200.0, rel=0.02) for c in late)
    adv = np.diff([c["travel"] for c in late])
    assert np.all(adv >= 0.5)  # slides every cycle: no stick
    err = np.array([_true_normal_force(c) - 4.0 for c in late])
    assert float(np.sqrt(np.mean(err ** 2))) <= 0.05
    assert float(np.max(np.abs(err))) <= 0.15


def test_friction_03_cylinder_meets_the_acceptance():
    """Thesis sensor, μ = 0.3, the R = 200 mm cylinder (issue 13's acceptance with friction):
    completed, contact never lost, travel within 1 mm (measured and the simulator's arc), the
    true normal force within ±0.5 N of the target on every travel cycle and its RMS error
    ≤ 0.2 N, breakaway included; μ̂ is the simulator's μ."""
    prep, rep, out = _cylinder_friction_03(False)
    assert out["completed"] and rep.converged, rep.stop_reason
    assert out["contact_lost"] == 0
    assert abs(out["travel"] - 50.0) <= 1.0
    assert abs(_true_arc(prep, rep.cycles) - 50.0) <= 1.0
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    err = np.array([_true_normal_force(c) - 4.0 for c in trav])
    assert float(np.max(np.abs(err))) <= 0.5
    assert math.sqrt(np.mean(err ** 2)) <= 0.2
    assert out["true_normal_force_max_error"] <= 0.5
    assert out["normal_force_rms_error"] <= 0.2
    assert out["friction_estimate"] == pytest.approx(0.3, abs=0.02)


def _study_workpiece(k: int, seed: int = 13):
    """Workpiece ``k`` of scripts/follow_study.py (``--seed``, 13 by default) and its travel
    direction."""
    import importlib.util  # lazy: only this test loads the study script

    path = Path(__file__).resolve().parents[2] / "scripts" / "follow_study.py"
    spec = importlib.util.spec_from_file_location("follow_study", path)
    study = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study)
    rng = np.random.default_rng(seed)
    for i in range(k + 1):
        name, cell = study.random_cell(rng, i)
        travel_dir = Y + rng.uniform(-0.2, 0.2, 3)
    return name, cell, travel_dir


def test_the_last_step_is_one_the_robot_can_make(tmp_path):
    """A frictionless plane of the 20-workpiece study (ideal sensor) whose last travel step,
    0.021 mm with a 0.02 mm completion tolerance, rounded to no motion: the run repeated it
    until the cycle limit. It completes, within the tolerance, in far fewer cycles."""
    name, cell, travel_dir = _study_workpiece(8)
    assert name.startswith("plane")
    prep, rep, out = _follow(tmp_path, cell=replace(cell, ideal_sensor=True),
                             travel_dir=travel_dir)
    assert out["completed"] and rep.converged, rep.stop_reason
    assert 50.0 - TRAVEL_TOL <= out["travel"] <= 51.0
    assert rep.iterations < prep.config.max_iterations // 2


def test_the_sliding_hold_takes_the_surface_turn_only_from_a_curvature_held_two_cycles(
        tmp_path, monkeypatch):
    """``HOLD_CURVATURE_CYCLES``: the sliding hold pre-changes the wrench for the surface's
    turn under the step, κ Δs (n × t), only once κ̂ has been estimated two cycles in a row (a
    one-cycle false κ̂ on a plane, taken whole, cost +0.54 N). Replayed on the recorded sliding
    cycles of an R = 200 mm cylinder (μ = 0.3) where the hold used κ̂: with the count set back to
    one cycle the hold's turn is zero and the held force the same."""
    import kinestat.control.follow as follow

    pairs: list = []
    prep = None

    def recording(state, meas):
        pairs.append((state, meas))
        return decide_follow(prep.follow, state, meas)

    req = ControlRequest(force=4.0 * F_HAT, start_tool_point=START, task="follow", travel=12.0,
                         travel_dir=Y, auto_tilt=True, cell=SimulatedCell(
                             friction=0.3, cylinder=CylinderSpec(200.0, np.array([0.0, 0.0, 1.0]))))
    prep = prepare_control(req)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with CycleLog(tmp_path / "log.jsonl") as log:
        run(prep.config, io, log, decide_fn=recording)

    holds: list = []
    plain = follow._base_twist

    def spy(*a):
        holds.append(a[-1])
        return plain(*a)

    monkeypatch.setattr(follow, "_base_twist", spy)
    checked = 0
    for state, meas in pairs:
        # the cycle's own estimate adds one to the count (FollowState.curvature_cycles)
        if not (isinstance(state, FollowState) and state.curvature_cycles >= 1):
            continue
        holds.clear()
        decide_follow(prep.follow, state, meas)
        if not holds or holds[-1] is None or not np.any(holds[-1][1]):
            continue  # no hold in this cycle, or no step under it
        f_two, w_two = holds[-1]
        holds.clear()
        decide_follow(prep.follow, replace(state, curvature_cycles=0), meas)  # κ̂'s first cycle
        f_one, w_one = holds[-1]
        np.testing.assert_array_equal(w_one, np.zeros(3))
        np.testing.assert_array_equal(f_one, f_two)  # the held force itself is unchanged
        assert np.linalg.norm(w_two) > 0.0
        checked += 1
    assert checked >= 3  # the run slid with a known curvature under the hold


def test_an_insignificant_path_fit_falls_back_on_the_probe_touches_early_in_the_travel():
    """Just past CURVATURE_SPAN the path's own tips span too little for their jitter (sagitta
    below twice the fit's residual): the curvature comes from the fit with the probe's touches
    while the travel is below CURVATURE_PROBE_TRAVEL, and from the path alone after it."""
    from types import SimpleNamespace

    from kinestat.control import follow
    from kinestat.control.contact_estimate import path_curvature

    R = 150.0

    def on_circle(x, dz=0.0):  # the convex arc z = sqrt(R² − x²) − R, centre on −z
        return np.array([x, 0.0, math.sqrt(R * R - x * x) - R + dz])

    xs = np.linspace(0.0, 4.5, 10)
    path = tuple(on_circle(x, 0.01 * (-1) ** k) for k, x in enumerate(xs[:-1]))  # jitter
    tip = on_circle(xs[-1])
    a = xs[-1] / R
    n, t = np.array([math.sin(a), 0.0, math.cos(a)]), np.array([math.cos(a), 0.0, -math.sin(a)])
    line = tuple(on_circle(x) for x in (-3.0, -1.5, 0.0, 1.5, 3.0))
    # the premise: the path alone is not significant, with the touches it is
    assert path_curvature(np.asarray(path), tip, n, t, follow.CURVATURE_SPAN) == 0.0
    both = path_curvature(np.asarray(line + path), tip, n, t, follow.CURVATURE_SPAN)
    assert both == pytest.approx(1.0 / R, rel=0.1)
    st = SimpleNamespace(probe=SimpleNamespace(line=line), travel=follow.CURVATURE_SPAN + 0.5)
    assert follow._curvature(st, path, tip, n, t) == pytest.approx(both, rel=1e-9)
    st.travel = follow.CURVATURE_PROBE_TRAVEL
    assert follow._curvature(st, path, tip, n, t) == 0.0


def test_the_slip_direction_chord_is_as_short_as_the_measured_tip_jitter_allows():
    """``_slip_chord_length``: the tip's jitter at rest over ``SLIP_DIRECTION_TOL``, between
    ``LEARN_CHORD_LENGTH`` and ``CHORD_LENGTH``; ``CHORD_LENGTH`` when the jitter was not
    measured (too few stuck cycles). The jitters are those measured before the first slip in
    the study's runs: fine encoders ~5e-6 mm, the thesis's counts 0.09–0.13 mm."""
    from types import SimpleNamespace

    from kinestat.control import follow

    def length(jitter, cycles=follow.FIRST_SLIP_CYCLES):
        return follow._slip_chord_length(SimpleNamespace(stick_jitter=jitter,
                                                         stick_cycles=cycles))

    assert length(5e-6) == follow.LEARN_CHORD_LENGTH
    for jitter in (0.09, 0.13):  # no chord shorter than CHORD_LENGTH is precise enough
        assert length(jitter) == follow.CHORD_LENGTH
    mid = 0.5 * (follow.LEARN_CHORD_LENGTH + follow.CHORD_LENGTH)
    assert length(mid * follow.SLIP_DIRECTION_TOL) == pytest.approx(mid)
    assert length(5e-6, cycles=follow.FIRST_SLIP_CYCLES - 1) == follow.CHORD_LENGTH


def test_after_the_breakaway_the_normal_does_not_follow_an_assumed_slip_direction(tmp_path):
    """A steep cylinder met ~28° off its normal (seed 29's workpiece 11, R = 394 mm, ideal
    sensor, μ = 0.3): at the breakaway the tip slides where the platform's stored tangential
    force pushes it, ~5° off the commanded tangent. Until a ``CHORD_LENGTH`` chord exists the
    normal estimate must not assume the slip along the tangent (that read 1.6° off for three
    cycles and left the force 0.1–0.2 N low; RMS 0.053 N): within 0.5° of the true normal on
    every travel cycle from the first slip on, and the run meets the ideal sensor's acceptance
    (RMS ≤ 0.05 N)."""
    name, cell, travel_dir = _study_workpiece(11, seed=29)
    assert name.startswith("cylinder")
    prep, rep, out = _follow(tmp_path, cell=replace(cell, ideal_sensor=True, friction=0.3),
                             travel_dir=travel_dir)
    assert out["completed"] and rep.converged, rep.stop_reason
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    first = next(i for i, c in enumerate(trav) if c["friction_ratio"] > 0)
    ang = [math.degrees(math.acos(min(1.0, float(np.asarray(c["normal_estimate"])
                                                  @ np.asarray(c["true_normal"])))))
           for c in trav[first:]]
    assert max(ang) <= 0.5
    assert out["true_normal_force_rms_error"] <= 0.05


def test_an_overestimated_curvature_does_not_turn_the_tool_back_inside_the_cone(
        tmp_path, monkeypatch):
    """Seed 101's workpiece 7 (R = 273 mm, thesis sensor, μ = 0.3): the first curvature
    estimates, fitted to the probe's touches (±3 mm, each ~0.02 mm off with the thesis's
    counts), read more than 1.5× the true normal curvature. Fed forward whole, the turn put S6
    back inside the cone (tilt 16.0° for a 16.7° edge, +1.3 N); μ̂ read 0.295 for 0.3, so the
    re-stuck tip's ratio counted as on the edge and every few cycles a step pressed it and
    knocked S6 back: 800 cycles at 2.3 mm of travel. While S6 is short of its axis the convex
    feedforward is left out (_short_of_axis) and a tip that did not follow a step is held
    (_held_by_step): the run meets the thesis sensor's acceptance."""
    import kinestat.control.follow as follow

    name, cell, travel_dir = _study_workpiece(7, seed=101)
    assert name.startswith("cylinder")
    axis = np.asarray(cell.cylinder.axis, dtype=float)
    axis /= np.linalg.norm(axis)
    ratios: list = []
    fit = follow._curvature

    def spy(st, path, tip, n, t):
        kappa = fit(st, path, tip, n, t)
        if kappa != 0.0 and st.travel < follow.CURVATURE_SPAN:
            ratios.append(kappa * cell.cylinder.radius / (1.0 - float(t @ axis) ** 2))
        return kappa

    monkeypatch.setattr(follow, "_curvature", spy)
    prep, rep, out = _follow(tmp_path, cell=replace(cell, friction=0.3), travel_dir=travel_dir)
    assert ratios and max(ratios) > 1.5  # the premise: κ̂ over the first mm is far too high
    assert out["completed"] and rep.converged, rep.stop_reason
    assert rep.iterations < 300
    assert out["true_normal_force_max_error"] <= 0.5
    assert out["true_normal_force_rms_error"] <= 0.2
    assert out["contact_lost"] == 0


def test_the_force_line_reconstructs_the_force_and_keeps_its_ratio():
    """``_force_line``: the force on the tool ``−F`` is ``F_n (n − r ŝ)`` with ``r`` its
    tangential-to-normal ratio and ŝ against its tangential part; scaling along that line
    keeps the ratio (what a relief of the normal force at a stuck tip's cone edge must do)."""
    from kinestat.control import follow

    rng = np.random.default_rng(4)
    for _ in range(50):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        F = -(rng.uniform(1.0, 8.0) * n + rng.normal(size=3) * rng.uniform(0.0, 2.0))
        fn = float(-F @ n)
        if fn <= 0.0:
            continue
        r, s = follow._force_line(F, n)
        np.testing.assert_allclose(fn * (n - r * s), -F, atol=1e-12)
        assert abs(float(s @ n)) < 1e-12 and abs(np.linalg.norm(s) - 1.0) < 1e-12
        assert r == pytest.approx(follow._stuck_ratio(F, n), rel=1e-12)
    assert follow._force_line(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))[0] == 0.0


def test_before_the_first_slip_a_force_relief_does_not_break_the_tip_away(tmp_path):
    """Seed 101's workpiece 0 (a plane tilted 7.5°, thesis sensor, μ = 0.3): the tip stuck on
    the cone's edge while the breakaway tilt grew; a travel step pressed it (+0.19 N) and the
    force control relieved the normal force along the normal line, at constant tangential
    force: the ratio passed μ, the tip broke away 0.5 mm and the force dropped 0.59 N. The
    relief is now along the force's own line (``_force_line``: the ratio kept) until μ is
    measured: the run's largest error is far inside the acceptance."""
    name, cell, travel_dir = _study_workpiece(0, seed=101)
    assert name.startswith("plane")
    prep, rep, out = _follow(tmp_path, cell=replace(cell, friction=0.3), travel_dir=travel_dir)
    assert out["completed"] and rep.converged, rep.stop_reason
    assert out["true_normal_force_max_error"] <= 0.3
    assert out["true_normal_force_rms_error"] <= 0.05


def test_the_convex_feedforward_leaves_out_what_the_surface_turn_makes_up():
    """``_feed_fraction``: S6 on its axis (or past it) gets the whole surface turn fed forward;
    S6 short of its axis by more than the dead band gets only what its shortfall beyond the
    dead band and the feedback turn leave of the turn (none when the shortfall exceeds it);
    a concave turn is always fed forward whole."""
    from types import SimpleNamespace

    from kinestat.control import follow

    config = SimpleNamespace(max_turn_deg=1.0)
    mu = 0.3
    st = SimpleNamespace(tilting=True, friction_samples=3, friction_ratio=mu, breakaway=0.0)
    n = np.array([0.0, 0.0, 1.0])
    axis_deg = math.degrees(math.atan(mu)) + follow.AUTO_TILT_MARGIN_DEG

    def s6(tilt_deg):  # S6 into the surface, leaning towards +x
        a = math.radians(tilt_deg)
        return np.array([math.sin(a), 0.0, -math.cos(a)])

    angle = math.radians(0.4)  # κ̂ Δs
    frac = follow._feed_fraction
    assert frac(config, st, s6(axis_deg), n, angle, 0.0) == 1.0
    assert frac(config, st, s6(axis_deg + 0.5), n, angle, 0.0) == 1.0
    assert frac(config, st, s6(axis_deg - follow.TURN_DEADBAND_DEG + 0.01), n, angle, 0.0) == 1.0
    assert frac(config, st, s6(axis_deg - 2.0), n, angle, 0.0) == 0.0
    # short by 0.2° beyond the dead band, 0.1° of it turned by the feedback: 0.3° of 0.4° fed
    short = s6(axis_deg - follow.TURN_DEADBAND_DEG - 0.2)
    assert frac(config, st, short, n, angle, math.radians(0.1)) == pytest.approx(0.75, rel=1e-6)
    assert frac(config, st, s6(axis_deg - 2.0), n, -angle, 0.0) == 1.0
    for other in (SimpleNamespace(**{**vars(st), "tilting": False}),
                  SimpleNamespace(**{**vars(st), "friction_samples": 0})):
        assert frac(config, other, s6(axis_deg - 2.0), n, angle, 0.0) == 1.0


def _first_slip(rep) -> tuple[list, int]:
    """The travel cycles and the index among them of the first with μ̂ measured."""
    trav = [c for c in rep.cycles if c["phase"] == "travel"]
    return trav, next(i for i, c in enumerate(trav) if c["friction_ratio"] > 0)


def test_the_tip_breaks_away_with_s6_about_the_sliding_lead_ahead(tmp_path):
    """The default plane (thesis sensor, μ = 0.3): the breakaway holds the stuck tip's force
    until S6 leads it by ``BREAKAWAY_LEAD`` (the automatic tilt's margin, a sliding tool's
    lead), then turns both. The true lead reaches the margin and drifts about 0.6° on while the
    tip sticks, ending about 1° past it (3.5° through the simulated devices while their axis 5
    drifted, and the tip then ran ahead, −0.6 N); the breakaway stays well inside the
    acceptance."""
    from kinestat.control import follow

    assert follow.BREAKAWAY_LEAD == follow.AUTO_TILT_MARGIN_DEG
    prep, rep, out = _follow(tmp_path, cell=replace(SimulatedCell(), friction=0.3))
    assert out["completed"] and rep.converged, rep.stop_reason
    trav, first = _first_slip(rep)

    def lead(c):  # degrees S6 leads the true force, about the true normal
        n, f = np.asarray(c["true_normal"]), np.asarray(c["true_force"])
        fn = -float(f @ n)
        ft = float(np.linalg.norm(f + fn * n))
        tilt = math.degrees(math.acos(min(1.0, -float(np.asarray(c["s6"]) @ n))))
        return tilt - math.degrees(math.atan2(ft, fn))

    leads = [lead(c) for c in trav[:first]]
    start = next(i for i, v in enumerate(leads) if v >= follow.BREAKAWAY_LEAD - 0.3)
    stuck = leads[start:first - 2]  # the hold done, before the edge
    assert len(stuck) > 30  # the premise: a long stuck breakaway
    assert follow.BREAKAWAY_LEAD - 0.5 < np.mean(stuck[-10:]) < follow.BREAKAWAY_LEAD + 1.25
    assert out["true_normal_force_max_error"] <= 0.3


def test_the_stuck_force_is_held_until_s6_leads_it_by_the_breakaway_lead():
    """``_lead_hold``: the fraction of the breakaway's turn by which the stuck force is held:
    whole until the lead is tracked (it reached ``BREAKAWAY_LEAD``), then none."""
    from types import SimpleNamespace

    from kinestat.control import follow

    assert follow._lead_hold(SimpleNamespace(lead_ref=None)) == 1.0
    for ref in (follow.BREAKAWAY_LEAD, follow.BREAKAWAY_LEAD + 2.0):
        assert follow._lead_hold(SimpleNamespace(lead_ref=ref)) == 0.0


def test_the_breakaway_leads_by_the_sliding_margin_so_the_slip_does_not_run_ahead(tmp_path):
    """Seed 101's workpiece 17 (R = 246 mm, ideal sensor, μ = 0.3): the tip sticks for ~90
    cycles while the breakaway tilt grows. A sliding tool's S6 leads its force by the automatic
    tilt's margin; with S6 only 0.7° ahead of the force when the tip broke away (the old
    ``BREAKAWAY_LEAD``, 0.5°), the platform's soft mode took up the rest: the tip ran 0.4 mm
    in one cycle and the normal force fell 0.47 N (RMS 0.049 N). Leading by the margin, the
    slip starts in the sliding pose: the first slip and the cycles after it stay within
    0.25 N of the request, and the run within the ideal sensor's acceptance."""
    from kinestat.control import follow

    assert follow.BREAKAWAY_LEAD == follow.AUTO_TILT_MARGIN_DEG
    name, cell, travel_dir = _study_workpiece(17, seed=101)
    assert name.startswith("cylinder")
    prep, rep, out = _follow(tmp_path, cell=replace(cell, ideal_sensor=True, friction=0.3),
                             travel_dir=travel_dir)
    assert out["completed"] and rep.converged, rep.stop_reason
    trav, first = _first_slip(rep)
    assert first > 60  # the premise: a long stuck breakaway
    around = [abs(_true_normal_force(c) - 4.0) for c in trav[first - 2:first + 6]]
    assert max(around) <= 0.25
    assert out["true_normal_force_rms_error"] <= 0.05
    assert out["contact_lost"] == 0


def test_while_the_lead_is_tracked_its_jitter_past_the_margin_does_not_step_a_stuck_tip(
        tmp_path):
    """Seed 13's workpiece 0 (a plane tilted 6.9°, thesis sensor, μ = 0.3): the breakaway
    leads the force by the margin, and the measured lead jitters ±0.3° about it. The test
    "S6 past the force by the margin: the tip is on the edge" read that jitter as the edge
    and stepped the stuck tip (+0.25 and +0.31 N). While the lead is tracked the edge is the
    lead's own test (it grows above its recent mean): before the first slip the true normal
    force stays within 0.2 N of the request once travel started."""
    name, cell, travel_dir = _study_workpiece(0, seed=13)
    assert name.startswith("plane")
    prep, rep, out = _follow(tmp_path, cell=replace(cell, friction=0.3), travel_dir=travel_dir)
    assert out["completed"] and rep.converged, rep.stop_reason
    trav, first = _first_slip(rep)
    assert first > 60
    stuck = [abs(_true_normal_force(c) - 4.0) for c in trav[5:first]]
    assert max(stuck) <= 0.2
    assert out["true_normal_force_max_error"] <= 0.3


def test_a_pressed_first_slip_is_taken_back_by_the_force_it_raised():
    """``_pressed``: after a first slip (``direct_slip``), a travel step the tip did not follow
    (advance below ``SLIDE_FRACTION`` of it) that raised the normal force ``PRESS_TOL`` past the
    target shows the tip inside the cone; a step it followed, or a force within the tolerance,
    does not; nor anything before a first slip."""
    from types import SimpleNamespace

    from kinestat.control import follow

    n = np.array([0.0, 0.0, 1.0])
    cfg = SimpleNamespace(base=SimpleNamespace(force_target=4.0))

    def force(fn):  # the measured force on the top: the tool pressed along −n, leaning in x
        return np.array([0.4 * fn, 0.0, -fn])

    st = SimpleNamespace(direct_slip=0.02, step=0.2)
    over = 4.0 + follow.PRESS_TOL + 0.01
    assert follow._pressed(cfg, st, 0.0, force(over), n)
    assert not follow._pressed(cfg, st, 0.0, force(4.0 + follow.PRESS_TOL - 0.01), n)
    assert not follow._pressed(cfg, st, follow.SLIDE_FRACTION * 0.2 + 0.01, force(over), n)
    assert not follow._pressed(cfg, SimpleNamespace(direct_slip=0.0, step=0.2), 0.0,
                               force(over), n)
    assert not follow._pressed(cfg, SimpleNamespace(direct_slip=0.02, step=0.0), 0.0,
                               force(over), n)


def test_a_false_edge_after_a_long_breakaway_does_not_press_the_stuck_tip(tmp_path):
    """A μ = 0.5 cylinder (R = 408 mm, axis 14° off the travel) at 2.45 N, thesis sensor
    (campaign seed 3, run 1): the stuck force's lead behind S6 drifts up over ~140 cycles of
    breakaway and passes its running mean by ``EDGE_LEAD`` while the tip is still 0.6° inside
    the cone. The edge steps pressed the stuck tip +0.61 N before the force's ratio showed the
    slip false; taken back once the first step raised the force (``_pressed``), the run stays
    within 0.3 N of the request. (The force to the draw's digits: with the thesis's counts the
    breakaway's outcome is sensitive to them; at 2.4547 N the old rule passed too.)"""
    cell = replace(SimulatedCell(), friction=0.5, cylinder=CylinderSpec(
        radius=408.243, axis=np.array([-0.31913128, -0.13695865, -0.9417264])))
    prep, rep, out = _follow(tmp_path, cell=cell, force=2.4546880796856136, travel=10.0,
                             travel_dir=[-0.27663958, 0.10498784, -0.95612791])
    assert out["completed"] and rep.converged, rep.stop_reason
    trav, first = _first_slip(rep)
    assert first > 100  # the premise: a long stuck breakaway
    assert out["true_normal_force_max_error"] <= 0.3
    assert out["contact_lost"] == 0


def test_a_refusal_while_the_automatic_tilt_leans_the_tool_says_so():
    """``_tilt_hint``: during the automatic tilt's travel a refusal is explained by the lean
    (measured from S6 and the normal), with μ̂ once measured, or the stuck force's largest
    ratio (a lower bound of μ) before the first slip; nothing without the tilt or before the
    travel."""
    from types import SimpleNamespace

    from kinestat.control import follow

    cfg = SimpleNamespace(base=SimpleNamespace(force_target=5.857))
    n = np.array([0.0, 0.0, 1.0])
    lean = math.radians(25.9)
    s6 = np.array([math.sin(lean), 0.0, -math.cos(lean)])
    st = SimpleNamespace(tilting=True, phase="travel", normal=n, friction_samples=0,
                         friction_ratio=0.0, ratio_max=0.44)
    hint = follow._tilt_hint(cfg, st, s6)
    assert "25.9°" in hint and "at least" in hint and "0.44" in hint and "5.86 N" in hint
    measured = follow._tilt_hint(cfg, _replace_ns(st, friction_samples=3, friction_ratio=0.48),
                                 s6)
    assert "0.48" in measured and "at least" not in measured
    assert follow._tilt_hint(cfg, _replace_ns(st, tilting=False), s6) == ""
    assert follow._tilt_hint(cfg, _replace_ns(st, phase="settle"), s6) == ""


def _replace_ns(ns, **kw):
    """A copy of the namespace ``ns`` with ``kw`` set."""
    from types import SimpleNamespace

    return SimpleNamespace(**{**vars(ns), **kw})


def test_the_stuck_lead_is_capped_so_a_long_breakaway_leans_the_tool_no_further(tmp_path):
    """A μ = 0.5 plane tilted 4.4° at 4.39 N, thesis sensor (campaign seed 2, run 26). While
    the tip sticks and S6 turns θ from the normal by δ a cycle, the stuck force turns with it
    and its normal part falls by |F| sin θ δ; pressed back along the normal, the force turns
    back by sin²θ δ, so its lead behind S6 drifts up (0.04° a cycle at 25°). Over ~160 stuck
    cycles the true lead reached 4.6° and the tool 31° from the normal, and the top reached its
    4° range before the tip slid. With the measured lead's mean past ``LEAD_CAP`` the force
    control presses along the force's own line (its direction kept): the true lead stays below
    4°, and the run completes inside the envelope."""
    from kinestat.control import follow

    cell = replace(SimulatedCell(), friction=0.5,
                   plane_point=np.array([-398.38415999884, 800.0, -100.39510141076444]),
                   plane_normal=np.array([-0.9706777526633575, 0.07548187761857303,
                                          0.22822617429994457]))
    prep, rep, out = _follow(tmp_path, cell=cell, force=4.390278272598966, travel=10.0,
                             travel_dir=[0.08853906837897454, 0.07624878010849882,
                                         1.0048141763475942])
    assert out["completed"] and rep.converged, rep.stop_reason
    trav, first = _first_slip(rep)
    assert first > 100  # the premise: a long stuck breakaway

    def lead(c):  # degrees S6 leads the true force, about the true normal
        n, f = np.asarray(c["true_normal"]), np.asarray(c["true_force"])
        fn = -float(f @ n)
        tilt = math.degrees(math.acos(min(1.0, -float(np.asarray(c["s6"]) @ n))))
        return tilt - math.degrees(math.atan2(float(np.linalg.norm(f + fn * n)), fn))

    assert max(lead(c) for c in trav[first - 20:first]) <= follow.LEAD_CAP + 1.5
    assert out["true_normal_force_max_error"] <= 0.3
