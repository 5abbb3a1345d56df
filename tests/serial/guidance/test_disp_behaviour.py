"""Issue 14: ``kinestat disp`` behaves as DISP did — type I re-planned from the actual hand at
every step (GENM), first-order steps with the deck's counts and no correction rows, the 1977 rule
only for type III, DISP's all-joint perturbation at singularities."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.disp import disp_options, run_deck
from kinestat.errors import InputError, SingularityError
from kinestat.io.disp_deck import embedded_deck
from kinestat.serial.guidance.events import Singularity
from kinestat.serial.guidance.planners import general_path
from kinestat.serial.guidance.rules import FirstOrder, GuidanceOptions
from kinestat.serial.guidance.run import joint_display, run_guidance
from kinestat.serial.guidance.step import (
    DEFAULT_COND_LIMIT,
    characteristic_length,
    conditioning,
    perturb_all_joints,
    scaled_jacobian,
    sigma_min_gradient,
)
from kinestat.spatial.displacement import screw_from_poses

TARGET7 = np.array([10.0, -10.0, 20.0])  # Illustration 7's a2


def _commanded_twists(model, q_rows):
    """B of every step, recovered from the rows alone: a first-order step solves J δq = B."""
    return np.array([kinestat.jacobian(model, q_rows[j]) @ (q_rows[j + 1] - q_rows[j])
                     for j in range(len(q_rows) - 1)])


def test_type_i_replans_from_the_actual_hand_at_every_step():
    """GENM (MS = 6): at every step the commanded translation of the hand origin points from the
    actual hand origin to the target origin, with 1/(steps left) of the remaining length, and
    the rotation is 1/(steps left) of the remaining rotation."""
    k = 35
    r = run_deck(embedded_deck("illustration7"), steps=k).result
    assert len(r.q) == k + 1 and not r.events  # the steps only, no correction row
    B = _commanded_twists(r.model, r.q)
    for j in range(k):
        o = r.poses[j, :3, 3]
        v_origin = B[j, 3:] + np.cross(B[j, :3], o)  # velocity of the body point at O_H
        np.testing.assert_allclose(v_origin, (TARGET7 - o) / (k - j), atol=1e-9)
        sc = screw_from_poses(r.poses[j], r.stage_targets[0])
        rot_left = 0.0 if bool(sc.is_translation) else float(sc.theta)
        np.testing.assert_allclose(B[j, :3], rot_left / (k - j) * np.asarray(sc.axis),
                                   atol=1e-9)
    # re-planning keeps the first-order error from accumulating: the end is ~0.01 in off
    dp, da = r.final_pose_error()
    assert dp < 0.02 and da < 1e-9


def test_type_i_without_replanning_drifts_further():
    """The same 35 steps on the path planned once at the start (ρo updated, u_v, δr, δθ fixed)
    end ~0.3 in from the target: re-planning is what brings DISP's rows close."""
    deck = embedded_deck("illustration7")
    ref = run_deck(deck, steps=35).result
    fixed = general_path(ref.poses[0], ref.stage_targets[0])
    fixed = type(fixed)(fixed.start, fixed.u_w, fixed.theta, fixed.u_v, fixed.r)
    r = run_guidance(ref.model, ref.q[0], [fixed], steps=35, options=disp_options())
    assert r.final_pose_error()[0] > 0.2 > 10 * ref.final_pose_error()[0]
    assert np.abs(joint_display(r.model, r.q[-1] - ref.q[-1]))[:2].max() > 0.15


def test_disp_default_rows_are_the_steps_and_nothing_else(capsys):
    """``kinestat disp illustration6 --steps 9,4``: 14 rows, initial first, final last. Each
    command moves the hand origin d along R and turns it θ about R (eq. 4-21): the prismatic
    r3 carries the vertical motion and θ4 (axis −z) the turn, in equal steps."""
    assert main(["disp", "illustration6", "--steps", "9,4", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    t = np.array(out["table"])
    assert t.shape == (14, 6) and out["steps"] == [9, 4]
    assert not any(e["kind"] == "settle" for e in out["events"])
    np.testing.assert_allclose(t[0], [0, 25, 8, 0, 90, 0], atol=1e-12)
    np.testing.assert_allclose(t[:10, 2], 8 - 4 * np.arange(10) / 9, atol=1e-9)   # d = 4
    np.testing.assert_allclose(t[9:, 2], 4 - np.arange(5) / 4, atol=1e-9)         # d = -1
    np.testing.assert_allclose(t[:10, 3], 30 * np.arange(10) / 9, atol=1e-9)      # -30°
    np.testing.assert_allclose(t[9:, 3], 30 + 15 * np.arange(5) / 4, atol=1e-9)   # 15°
    np.testing.assert_allclose(t[:, 4:], np.tile([90.0, 0.0], (14, 1)), atol=1e-9)
    # the first-order residual stays: the hand origin ends near, not on, (15, -25, 17)
    assert 1e-3 < out["final_pose_error"]["position"] < 0.1


def test_disp_illustration7_cli_ends_close_without_a_correction_row(capsys):
    assert main(["disp", "illustration7", "--steps", "35", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["table"]) == 36 and out["events"] == []
    assert out["final_pose_error"]["position"] < 0.02
    np.testing.assert_allclose(out["table"][-1], [-15, 20, 0, 90, 90, 0], atol=0.02)


def test_settle_is_an_option_of_disp_and_the_default_of_guide():
    deck = embedded_deck("illustration7")
    settled = run_deck(deck, steps=35, options=disp_options(settle=True)).result
    assert settled.settle_rows() and settled.final_pose_error()[0] < 1e-8
    assert GuidanceOptions().settle and not disp_options().settle


def test_disp_1977_rule_only_for_type_iii(capsys):
    with pytest.raises(InputError, match="MS = 4"):
        run_deck(embedded_deck("illustration7"), options=GuidanceOptions.disp_1977())
    assert main(["disp", "illustration6", "--disp-1977"]) == 2
    assert "type III" in capsys.readouterr().err


def test_help_texts_say_who_emulates_disp(capsys):
    for cmd, words in (("disp", "By default this is DISP"), ("guide", "not an emulator")):
        assert main([cmd, "--help"]) == 0
        assert words in " ".join(capsys.readouterr().out.split())


# -- singularities: DISP's small increments on all joints ----------------------------------

def _wrist_singular():
    m = kinestat.load("puma762")
    q = np.radians([90.0, -30.0, 30.0, 0.0, 0.0, 0.0])  # θ5 = 0: axes 4 and 6 line up
    return m, q, characteristic_length(m, q)


def _exhaustive_best_cond(m, q, eps_rad, L):
    """The smallest condition number over all 2^n sign patterns of ±eps on every joint."""
    signs = np.array(list(itertools.product([-1.0, 1.0], repeat=m.n)))
    _, c = conditioning(scaled_jacobian(kinestat.jacobian(m, q + eps_rad * signs),
                                        m.prismatic, L))
    return float(np.min(c))


@pytest.mark.parametrize("case", ["puma-wrist", "illustration4"])
def test_perturb_all_gives_every_joint_the_smallest_equal_increment(case):
    """DISP's remedy (ch. IV, Singularities 1)): every joint by the same small increment, mixed
    signs, and no fewer increments would do — checked against every sign pattern of one
    increment less (an exhaustive search, not the function's own greedy one)."""
    if case == "puma-wrist":
        m, q, L = _wrist_singular()
        limit = DEFAULT_COND_LIMIT
    else:
        from kinestat.disp import deck_model
        from kinestat.disp.deck import disp_cond_limit
        deck = embedded_deck("illustration4")
        m = deck_model(deck)
        q, L, limit = m.q_home, characteristic_length(m, m.q_home), disp_cond_limit(deck)
    _, c0 = conditioning(scaled_jacobian(kinestat.jacobian(m, q), m.prismatic, L))
    assert c0 > limit
    q1, c1, t = perturb_all_joints(m, q, length=L, cond_limit=limit, increment_deg=0.1)
    d = np.degrees(q1 - q)
    np.testing.assert_allclose(np.abs(d), 0.1 * t, atol=1e-9)  # every joint, t × 0.1°
    assert np.any(d > 0) and np.any(d < 0)  # mixed signs
    _, c_check = conditioning(scaled_jacobian(kinestat.jacobian(m, q1), m.prismatic, L))
    assert c1 == pytest.approx(float(c_check)) and c1 < limit
    assert _exhaustive_best_cond(m, q, math.radians(0.1 * (t - 1)), L) >= limit
    q2, _, _ = perturb_all_joints(m, q, length=L, cond_limit=limit, increment_deg=0.1)
    np.testing.assert_array_equal(q1, q2)  # deterministic


def test_a_joint_that_cannot_change_sigma_min_gets_no_sign_from_rounding():
    """Turning the base joint about its own axis turns the whole arm: the Jacobian's singular
    values cannot change, so ∂σ_min/∂q1 is 0, not rounding noise of either sign (which made
    the perturbation's first sign, and Illustration 4's sub-step count, depend on the
    machine). Checked on Illustration 4's arm at random configurations and shifted by any
    base angle: the gradient's other components are unchanged, its first is exactly 0."""
    from kinestat.disp import deck_model
    m = deck_model(embedded_deck("illustration4"))
    L = characteristic_length(m, m.q_home)
    rng = np.random.default_rng(5)
    for q in rng.uniform(-np.pi, np.pi, (20, 6)):
        g = sigma_min_gradient(m, q, length=L)
        assert g[0] == 0.0
        shifted = sigma_min_gradient(m, q + np.array([rng.uniform(-3, 3), 0, 0, 0, 0, 0]),
                                     length=L)
        np.testing.assert_allclose(shifted[1:], g[1:], rtol=1e-5, atol=1e-7)
    q1, _, _ = perturb_all_joints(m, m.q_home, length=L, cond_limit=3919.0)
    assert np.degrees(q1 - m.q_home)[0] > 0.0  # a tie takes +, as documented


def test_perturb_all_gives_up_and_says_so():
    m, q, L = _wrist_singular()
    q1, c1, t = perturb_all_joints(m, q, length=L, increment_deg=0.1, max_tries=2)
    assert t == 2 and c1 >= DEFAULT_COND_LIMIT and np.array_equal(q1, q)


@pytest.mark.parametrize("mode", ["perturb", "perturb_all"])
def test_illustration4_singular_start_reports_the_new_configuration(mode):
    r = run_deck(embedded_deck("illustration4"),
                 options=disp_options(singular=mode, ms=0)).result
    ev = r.events[0]
    assert isinstance(ev, Singularity) and ev.action == "perturbed" and ev.method == mode
    moved = np.count_nonzero(np.abs(ev.joint_increments) > 1e-12)
    assert moved == (6 if mode == "perturb_all" else 1)
    np.testing.assert_allclose(ev.q, joint_display(r.model, r.q[0]) + ev.joint_increments,
                               atol=1e-9)
    assert ev.cond > DEFAULT_COND_LIMIT > ev.cond_after
    assert not r.stopped and r.final_pose_error()[0] < 5e-4  # DISP's final correction


def test_singular_modes_from_the_cli(capsys):
    assert main(["disp", "illustration4", "--singular", "perturb-all", "--json"]) == 0
    ev = json.loads(capsys.readouterr().out)["events"][0]
    inc = np.asarray(ev["joint_increments"])
    assert ev["method"] == "perturb_all" and np.all(np.abs(inc) <= 0.1 * ev["tries"] + 1e-9)
    assert np.all(inc != 0) and np.any(inc > 0) and np.any(inc < 0)  # all, mixed signs
    assert main(["disp", "illustration4", "--singular", "stop", "--json"]) == 2
    out = json.loads(capsys.readouterr().out)
    assert out["stop_reason"] == "singular" and len(out["table"]) == 1
    assert main(["disp", "illustration4", "--singular", "sideways"]) == 2
    assert "--singular" in capsys.readouterr().err


def test_stop_event_raises_its_own_error():
    r = run_deck(embedded_deck("illustration4"), options=disp_options(singular="stop")).result
    assert r.stop_event is r.events[-1] and r.stop_kind == r.stop_event.kind == "singular"
    with pytest.raises(SingularityError):
        r.raise_if_stopped()


def test_a_custom_step_rule_plugs_in():
    calls = []

    class Counting(FirstOrder):
        def increment(self, path, s0, s1, inp):
            calls.append((s0, s1))
            return super().increment(path, s0, s1, inp)

    deck = embedded_deck("illustration7")
    ref = run_deck(deck, steps=10).result
    r = run_guidance(ref.model, ref.q[0], [general_path(ref.poses[0], ref.stage_targets[0])],
                     steps=10, options=disp_options(), rule=Counting())
    assert len(calls) == 10 and calls[0] == (0.0, 0.1)
    np.testing.assert_allclose(r.q, ref.q, atol=1e-12)
    assert math.isclose(calls[-1][1], 1.0)


def _exact_path_joints(model, q_start, target, n_rows, per_row=40):
    """Joints along the screw from ``q_start``'s hand to ``target``, tracked by Newton on the
    forward kinematics in small steps (independent of the guidance step rules)."""
    from kinestat.serial.fk import fk
    from kinestat.serial.guidance.planners import screw_path, twist_between

    path = screw_path(fk(model, q_start), target)
    q = np.array(q_start, dtype=float)
    out = [q.copy()]
    for j in range(1, n_rows * per_row + 1):
        T = path.pose_at(j / (n_rows * per_row))
        for _ in range(30):
            e = twist_between(fk(model, q), T)
            if np.linalg.norm(e) < 1e-12:
                break
            q = q + np.linalg.solve(kinestat.jacobian(model, q), e)
        out.append(q.copy())
    return joint_display(model, np.array(out[::per_row]))


def test_illustration4_starts_as_disp_did_and_follows_the_screw():
    """MS 0 from Table A2-2's singular pose: DISP's small mixed-sign increments on every joint
    (by its criterion, well under the library's 1000), then rows that stay on the branch the
    screw path itself takes (no first-order swing of 100°+), and the target to the printed
    precision."""
    from kinestat.disp.deck import disp_cond_limit

    deck = embedded_deck("illustration4")
    r = run_deck(deck).result
    ev = r.events[0]
    inc = ev.joint_increments
    assert ev.method == "perturb_all" and ev.cond > disp_cond_limit(deck) > ev.cond_after
    np.testing.assert_allclose(np.abs(inc), np.abs(inc[0]), atol=1e-9)
    assert np.any(inc > 0) and np.any(inc < 0) and 0 < abs(inc[0]) < 7.0
    k = r.steps[0]
    exact = _exact_path_joints(r.model, np.radians(ev.q), r.stage_targets[0], k)
    rows = joint_display(r.model, r.q[1:k + 1])
    assert np.max(np.abs(rows - exact[1:])) < 1.0  # degrees: first-order error only
    assert not r.stopped and r.final_pose_error()[0] < 5e-4
    np.testing.assert_allclose(joint_display(r.model, r.final_q), exact[-1], atol=0.01)


def test_the_library_criterion_needs_larger_increments():
    deck = embedded_deck("illustration4")
    small = run_deck(deck).result.events[0].joint_increments
    strict = run_deck(deck, options=disp_options(deck=deck, cond_limit=DEFAULT_COND_LIMIT)
                      ).result.events[0]
    assert strict.cond_after < DEFAULT_COND_LIMIT
    assert np.max(np.abs(strict.joint_increments)) > np.max(np.abs(small))


def test_disp_singularity_criterion_follows_the_cards_and_the_size():
    """κ > L / p: the same arm in millimetres (cards still to 0.005) tolerates 25.4 times the
    condition number; a command deck (SET THREE, F10.3) ten times more than F10.2 points."""
    import dataclasses

    from kinestat.disp.deck import disp_cond_limit

    deck = embedded_deck("illustration4")
    mm = dataclasses.replace(
        deck, joints=[(25.4 * j.r, j.alpha_deg, 25.4 * j.a, j.theta_deg, j.pitch)
                      for j in deck.joints],
        positions=25.4 * np.asarray(deck.positions),
        frame_points=25.4 * np.asarray(deck.frame_points))
    assert disp_cond_limit(mm) == pytest.approx(25.4 * disp_cond_limit(deck), rel=1e-9)
    m = kinestat.disp.deck_model(deck)
    assert disp_cond_limit(deck) == pytest.approx(characteristic_length(m, m.q_home) / 0.005)
    six = embedded_deck("illustration6-corrected")
    seven = embedded_deck("illustration7-corrected")  # the same arm, hand on F10.2 cards
    assert disp_cond_limit(six) == pytest.approx(10 * disp_cond_limit(seven))
    assert disp_cond_limit(embedded_deck("illustration2")) == DEFAULT_COND_LIMIT


def test_sub_steps_only_for_counted_stages():
    """IT = 0 counts split a step whose joint increments exceed the count's bound; an explicit
    count is taken as given (and its first step from the perturbed start swings far)."""
    deck = embedded_deck("illustration4")
    counted = run_deck(deck).result
    given = run_deck(deck, steps=counted.steps[0]).result
    assert counted.substeps > 0 and given.substeps == 0
    first = np.abs(np.diff(joint_display(given.model, given.q[:2]), axis=0)).max()
    assert first > 90.0 > np.abs(np.diff(joint_display(counted.model, counted.q[:2]),
                                         axis=0)).max()
