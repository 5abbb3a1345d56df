"""The press task's move in contact off the default plane: a frictionless curved workpiece (the
turn that overshoots is damped), a workpiece met far off the tool axis (the turn is made in
steps), a stuck tip (the force is shed across S6), and an approach that meets nothing (it
stops at ``max_approach``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinestat.app.control_run import ControlRequest, CylinderSpec, SimulatedCell, prepare_control
from kinestat.app.sim_cell import InProcessIO, start_counts
from kinestat.control.align import align_gain, align_stalled
from kinestat.control.controller import ControllerConfig
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import run
from kinestat.control.tuning import TUNING
from kinestat.errors import InputError
from kinestat.sim.surface import approach_distance

from .conftest import F_HAT, START, run_in_process, scenario


def _press(tmp_path, cell: SimulatedCell, **kw):
    """The press task as ``kinestat control`` runs it (the thesis's calibrated cell), in
    process."""
    kw.setdefault("force", 4.0 * F_HAT)
    prep = prepare_control(ControlRequest(start_tool_point=START, cell=cell, **kw))
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with CycleLog(tmp_path / "log.jsonl") as log:
        rep = run(prep.config, io, log)
    return rep, read_log(tmp_path / "log.jsonl"), io


@pytest.mark.parametrize("radius", [150.0, 200.0])
def test_the_press_settles_on_a_frictionless_cylinder(tmp_path, radius):
    # on f793e55 R = 200 mm alternated ±2.35° for all 60 cycles (the whole turn onto the force
    # lands past the new normal: the free tip slides round the cylinder) and R = 150 mm pushed
    # the simulated tip off its equilibrium; the damped turn settled them in 8-9 cycles, and
    # since the first, 13.5° turn is made before pushing they settle in 6
    cyl = CylinderSpec(radius=radius, axis=np.array([0.0, 0.0, 1.0]))
    rep, recs, _ = _press(tmp_path, SimulatedCell(cylinder=cyl))
    assert rep.converged, rep.stop_reason
    assert abs(rep.true_force_magnitude - 4.0) <= 0.5
    assert rep.axis_error_deg <= 1.0
    assert rep.iterations <= 15


@pytest.mark.parametrize("radius, axis, force", [
    (297.4, (0.7849, -0.1143, 0.6090), 3.05),
    (419.7, (0.7954, -0.4450, 0.4116), 4.25),
])
def test_a_large_turn_is_made_before_pushing(tmp_path, radius, axis, force):
    # frictionless cylinders met 30-45° off the tool axis (two draws of the random press
    # study): an 18-20° turn made together with the Newton step's push drove the force from
    # about 1 N to 6-7 N in one cycle and the top past its 4° range
    cyl = CylinderSpec(radius=radius, axis=np.array(axis))
    rep, recs, _ = _press(tmp_path, SimulatedCell(cylinder=cyl), force=force * F_HAT)
    assert rep.converged, rep.stop_reason
    assert abs(rep.true_force_magnitude - force) <= 0.5 and rep.axis_error_deg <= 1.0
    for r in recs:
        if r.get("type") == "cycle" and r["action"] == "align":
            if r["commanded"]["rotation_deg"] > TUNING.push_turn_deg:
                assert r["commanded"]["step"] <= 0.0


@pytest.mark.parametrize("radius, axis, force, converges", [
    (344.3, (0.4888, -0.3247, -0.8097), 4.76, True),
    (200.5, (-0.6164, 0.6671, 0.4185), 5.8, False),
])
def test_the_force_a_turn_raises_is_not_pushed_on_top_of(tmp_path, radius, axis, force,
                                                         converges):
    # frictionless cylinders met 41-42° off the tool axis (the random press study's two
    # failures on 1cb8fd6): two 20° turns raised the force from 1 N to 4.7-6.4 N with no push
    # at all (the top's soft deflection across the tool, undone by the turn, loads the stiff
    # axis), and the next Newton step, computed without the turn, pushed the top 0.5-2.2° past
    # its 4° range. With the turn's rise predicted (predict_sliding) R = 344 mm settles; R =
    # 200 mm ends its 60 cycles within the force tolerance but 1.2° off the force (its tip
    # flips between two sides), inside the envelope throughout
    cyl = CylinderSpec(radius=radius, axis=np.array(axis))
    rep, recs, _ = _press(tmp_path, SimulatedCell(cylinder=cyl), force=force * F_HAT)
    cycles = [r for r in recs if r.get("type") == "cycle"]
    assert all(not r["violations"] for r in cycles)  # every measurement inside the envelope
    assert "outside the envelope" not in rep.stop_reason
    assert "refused" not in rep.stop_reason
    forces = [r["measured"]["force_magnitude"] for r in cycles]
    assert max(forces) <= 1.25 * force
    if converges:
        assert rep.converged, rep.stop_reason
        assert abs(rep.true_force_magnitude - force) <= 0.5 and rep.axis_error_deg <= 1.0


@pytest.mark.parametrize("radius, axis, force", [
    (430.4, (-0.7496, -0.5976, -0.2846), 2.95),
    (419.8, (0.8368, 0.1842, 0.5156), 4.54),
])
def test_a_turn_the_wrist_cannot_make_at_once_is_halved(tmp_path, radius, axis, force):
    # two draws of a fresh random press study (seeds 3 and 4, 2026-12-04): the second 20°
    # turn would have swung axis 4 by 30-42° in one command, and the envelope's refusal
    # stopped the run; the turn is now halved within the cycle until the wrist can make it
    cyl = CylinderSpec(radius=radius, axis=np.array(axis))
    rep, recs, _ = _press(tmp_path, SimulatedCell(cylinder=cyl), force=force * F_HAT)
    assert rep.converged, rep.stop_reason
    assert abs(rep.true_force_magnitude - force) <= 0.5 + 0.1 and rep.axis_error_deg <= 1.0
    turns = [r["commanded"]["rotation_deg"] for r in recs
             if r.get("type") == "cycle" and r["action"] == "align" and r["commanded"]]
    assert any(t == pytest.approx(TUNING.max_align_turn_deg / 2) for t in turns)


@pytest.mark.parametrize("cylinder", [None, CylinderSpec(radius=200.0,
                                                          axis=np.array([0.0, 0.0, 1.0]))])
def test_a_stuck_tip_is_aligned_by_shedding_the_force_across_s6(tmp_path, cylinder):
    # with μ = 0.3 the tip sticks where it touched, every turn of S6 about the tool point
    # turned the platform rigidly about it and the force turned along (0.74° before a 0.74°
    # turn, 0.72° after): 26 cycles on the plane, 38 on the cylinder, until a slip
    rep, recs, _ = _press(tmp_path, SimulatedCell(friction=0.3, cylinder=cylinder))
    assert rep.converged, rep.stop_reason
    assert rep.iterations <= 10
    assert abs(rep.true_force_magnitude - 4.0) <= 0.5 and rep.axis_error_deg <= 0.5
    actions = [r["action"] for r in recs if r.get("type") == "cycle"]
    assert "shed" in actions
    shed = next(r for r in recs if r.get("type") == "cycle" and r["action"] == "shed")
    assert shed["true"]["sticking"]  # it was stuck when the shed was chosen


@pytest.mark.parametrize("tilt", [35.0, 45.0])
def test_a_plane_met_far_off_the_tool_axis_is_turned_onto_in_steps(tmp_path, tilt):
    # a 35-45° turn at once moved the wrist more than the envelope's 30° per command
    scn = scenario(tilt_deg=tilt)
    rep, recs, _ = run_in_process(scn, scn.config(), tmp_path / "log.jsonl")
    assert rep.converged, rep.stop_reason
    assert abs(rep.true_force_magnitude - 4.0) <= 0.5 and rep.axis_error_deg <= 1.0
    turns = [r["commanded"]["rotation_deg"] for r in recs
             if r.get("type") == "cycle" and r["action"] == "align"]
    assert turns and max(turns) <= TUNING.max_align_turn_deg + 1e-9
    assert sum(turns) >= tilt - 5.0  # it did turn onto the plane, in several turns


@settings(max_examples=200, deadline=None)
@given(kb=st.floats(0.0, 20.0), e0=st.floats(0.01, 0.3), sign=st.sampled_from([-1.0, 1.0]))
def test_the_damped_turn_converges_where_the_whole_turn_alternates(kb, e0, sign):
    # the misalignment after a turn g e is e (1 − g (1 + κB)) (the free tip's slide moves the
    # normal by κB times the turn); the sign rule must bring it below 0.01 rad for any κB up to
    # 20 (the whole turn alone diverges past κB = 1; a frictionless R = 172 mm cylinder at
    # 5.5 N measured κB ≈ 16, beyond the floor of 1/8 the gain had until 2026-12-04)
    gain, last, e = 1.0, None, sign * e0
    for _ in range(40):
        gain = align_gain(gain, last, np.array([0.0, 0.0, e]))
        assert TUNING.min_align_gain <= gain <= 1.0
        if abs(e) < 1e-2:
            break
        last = np.array([0.0, 0.0, gain * e])
        e = e * (1.0 - gain * (1.0 + kb))
    assert abs(e) < 1e-2, (kb, gain, e)


def test_the_whole_turn_is_kept_on_a_plane():
    # a turn short of the force (or a noisy reading back against it by less than half the
    # turn) keeps the whole turn: the default plane's runs are unchanged
    assert align_gain(1.0, [0.0, 0.0, 0.2], [0.0, 0.0, 0.01]) == 1.0
    assert align_gain(1.0, [0.0, 0.0, 0.2], [0.0, 0.0, -0.09]) == 1.0
    assert align_gain(1.0, [0.0, 0.0, 0.2], [0.0, 0.0, -0.11]) == 0.5
    floor = TUNING.min_align_gain
    assert align_gain(2 * floor, [0.0, 0.0, 0.2], [0.0, 0.0, -0.3]) == floor
    assert align_gain(floor, [0.0, 0.0, 0.2], [0.0, 0.0, -0.3]) == floor


def test_a_turn_of_a_sixteenth_lands_on_a_steep_frictionless_cylinder(tmp_path):
    # a random draw (seed 5, run 3): a frictionless R = 172.5 mm cylinder at 5.52 N lands a
    # turn about 16 times its size past the normal; with the gain's floor at 1/8 the turns went
    # to and fro for 60 cycles, 0.96° off the force
    cyl = CylinderSpec(radius=172.5, axis=np.array([0.2172, 0.4401, -0.8713]))
    rep, _, _ = _press(tmp_path, SimulatedCell(cylinder=cyl), force=5.52 * F_HAT)
    assert rep.converged, rep.stop_reason
    assert abs(rep.true_force_magnitude - 5.52) <= 0.5
    assert rep.axis_error_deg <= 1.0
    assert rep.iterations <= 30


def test_a_contact_that_snaps_across_the_axis_stops_with_its_reason(tmp_path):
    # a random draw (seed 1, run 0): on a frictionless R = 200.5 mm cylinder at 5.8 N the tip
    # has no equilibrium with the force along S6: a 0.078° turn leaves it 1.18° off on one
    # side, a 0.104° turn 2.75° off on the other. It used to turn to and fro for all 60
    # cycles; it now stops once the turns cut to their floor make no progress, and says why
    cyl = CylinderSpec(radius=200.5, axis=np.array([-0.6164, 0.6671, 0.4185]))
    rep, recs, io = _press(tmp_path, SimulatedCell(cylinder=cyl), force=5.8 * F_HAT)
    assert not rep.converged
    assert "does not settle on the tool axis" in rep.stop_reason
    assert "--align-tol-deg" in rep.stop_reason and "--force" in rep.stop_reason
    assert rep.iterations < ControllerConfig.__dataclass_fields__["max_iterations"].default
    assert io.stopped
    assert recs[-1]["type"] == "end"


def test_the_fixed_step_is_not_taken_for_a_snapping_contact(tmp_path):
    # a CLI fuzz draw: --method fixed with friction 0.1 on the default plane kept its turns
    # from settling (the 1 mm step's force jumps), and the snap's stop named a frictionless
    # convex workpiece; the stop is the stiffness method's only
    d = np.array([0.9710, 0.0298, -0.2374])
    rep, _, io = _press(tmp_path, SimulatedCell(friction=0.1), method="fixed",
                        force=4.0 * d / np.linalg.norm(d))
    assert not rep.converged and io.stopped
    assert "does not settle on the tool axis" not in rep.stop_reason


def test_align_stalled_needs_both_no_progress_and_turns_at_their_floor():
    n, floor = TUNING.align_stall_cycles, TUNING.min_align_gain
    assert align_stalled(n, floor)
    assert align_stalled(n, 2 * floor)
    assert not align_stalled(n - 1, floor)
    assert not align_stalled(10 * n, 4 * floor)  # turns not cut


def test_an_approach_that_meets_nothing_stops_at_max_approach(tmp_path):
    scn = scenario(distance=30.0)
    cfg = scn.config(max_approach=10.0)
    rep, recs, io = run_in_process(scn, cfg, tmp_path / "log.jsonl")
    assert not rep.converged and "max_approach = 10 mm" in rep.stop_reason
    assert io.stopped
    far = max(float(np.linalg.norm(np.asarray(r["commanded"]["tool_point"]) - START))
              for r in recs if r.get("type") == "cycle" and r["commanded"])
    assert 9.0 <= far <= 10.0


def test_max_approach_must_be_positive():
    with pytest.raises(InputError, match="max_approach"):
        ControllerConfig(model=None, force=4.0 * F_HAT, start_tool_point=START,
                         max_approach=0.0)


@pytest.mark.parametrize("spec, why", [
    (CylinderSpec(radius=200.0, axis=np.array([0.0, 0.0, 1.0]),
                  point=START + np.array([500.0, 0.0, 0.0])), "meets it only"),
    (CylinderSpec(radius=200.0, axis=np.array([0.0, 1.0, 0.0]),
                  point=START + np.array([0.0, 0.0, 500.0])), "never meets it"),
])
def test_a_simulated_workpiece_out_of_the_approach_is_refused_before_any_motion(spec, why):
    req = ControlRequest(force=4.0 * F_HAT, start_tool_point=START,
                         cell=SimulatedCell(cylinder=spec))
    with pytest.raises(InputError, match=why):
        prepare_control(req)


@settings(max_examples=100, deadline=None)
@given(radius=st.floats(50.0, 1000.0), ax=st.tuples(*[st.floats(-1, 1)] * 3),
       d=st.tuples(*[st.floats(-1, 1)] * 3), off=st.tuples(*[st.floats(-500, 500)] * 3))
def test_approach_distance_lands_on_the_surface(radius, ax, d, off):
    from kinestat.sim.surface import Cylinder

    a, u = np.asarray(ax), np.asarray(d)
    if np.linalg.norm(a) < 0.1 or np.linalg.norm(u) < 0.1:
        return
    cyl = Cylinder(point=np.zeros(3), axis=a, radius=radius)
    p = np.asarray(off)
    u = u / np.linalg.norm(u)
    t = approach_distance(cyl, p, u)
    ts = np.linspace(0.0, min(t, 3000.0), 400)
    gaps = cyl.gap(p + ts[:, None] * u)
    if math.isinf(t):  # never meets it: the sampled line stays outside (or starts inside: 0)
        assert np.all(gaps > -1e-9)
    elif t == 0.0:
        assert float(cyl.gap(p)) <= 0.0
    else:
        assert abs(float(cyl.gap(p + t * u))) < 1e-6 * max(1.0, t)
        assert np.all(gaps[:-1] > -1e-9)  # nothing met before it
