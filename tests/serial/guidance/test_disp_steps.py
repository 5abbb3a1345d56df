"""DISP's inferred IT = 0 step count (kinestat.disp.steps): its property, its inputs checked
against the deck cards, and that ``kinestat guide`` keeps kinestat's own count."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinestat.disp import deck_model, deck_stages, run_deck
from kinestat.disp.deck import deck_initial_hand
from kinestat.disp.steps import DISP_STEP_DEG, DISP_STEP_HAND, disp_step_count, stage_motion
from kinestat.io.disp_deck import embedded_deck
from kinestat.serial.fk import fk
from kinestat.serial.guidance.planners import (
    auto_steps,
    command_path,
    general_path,
    line_path,
    resolve_stage,
    screw_path,
)
from kinestat.serial.guidance.step import characteristic_length


def _pose(rv, p):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rv).as_matrix()
    T[:3, 3] = p
    return T


def _points(T):
    return np.array([T[:3, 3], T[:3, 3] + T[:3, 2], T[:3, 3] + T[:3, 0]])


def _independent_motion(T0, T1, kind):
    """θ (deg) and T from scipy: the relative rotation's angle, and the translation along its
    axis (screw types) or the origin's straight line (type I)."""
    R = Rotation.from_matrix(T1[:3, :3] @ T0[:3, :3].T)
    rv = R.as_rotvec()
    th = float(np.linalg.norm(rv))
    dp = T1[:3, 3] - T0[:3, 3]
    if kind == "general":
        return math.degrees(th), float(np.linalg.norm(dp))
    if th < 1e-9:
        return 0.0, float(np.linalg.norm(dp))
    u = rv / th
    return math.degrees(th), abs(float(dp @ u))


vec = st.lists(st.floats(-1.2, 1.2), min_size=3, max_size=3)
pos = st.lists(st.floats(-30.0, 30.0), min_size=3, max_size=3)


@settings(max_examples=40, deadline=None)
@given(vec, pos, vec, pos, st.sampled_from(["screw", "line", "general"]))
def test_count_keeps_both_step_parameters_at_the_bounds(rv0, p0, rv1, p1, kind):
    T0, T1 = _pose(rv0, p0), _pose(rv1, p1)
    th_ref, t_ref = _independent_motion(T0, T1, kind)
    if th_ref < 1e-3:
        return
    path = {"screw": lambda: screw_path(T0, T1),
            "line": lambda: line_path(_points(T0), _points(T1)),
            "general": lambda: general_path(T0, T1)}[kind]()
    th, t = stage_motion(path)
    assert th == pytest.approx(th_ref, abs=1e-7) and t == pytest.approx(t_ref, abs=1e-7)
    k = disp_step_count(path)
    x = max(th / DISP_STEP_DEG, t / DISP_STEP_HAND)
    assert k >= 1 and (abs(k - x) <= 0.5 or (k == 1 and x < 1.5))
    # rounding to the nearest: per step, neither parameter exceeds its bound by more than
    # k / (k − ½), and one fewer step would exceed a bound by more than (k − ½) / (k − 1)
    assert th / k <= DISP_STEP_DEG * k / (k - 0.5) + 1e-12
    assert t / k <= DISP_STEP_HAND * k / (k - 0.5) + 1e-12


def test_count_is_in_hand_sizes():
    """The same motion in a unit 25.4 times smaller, with the hand size in that unit: the same
    count (the rule has no length of its own)."""
    T0, T1 = _pose([0.1, 0.2, 0.3], [15.0, -25, 12]), _pose([0.3, -0.2, 1.0], [10.0, -10, 20])
    k_in = disp_step_count(general_path(T0, T1))
    M0, M1 = T0.copy(), T1.copy()
    M0[:3, 3] *= 25.4
    M1[:3, 3] *= 25.4
    k_mm = disp_step_count(general_path(M0, M1), hand_size=25.4)
    assert k_in == k_mm and k_in > disp_step_count(general_path(T0, T1), hand_size=2.0)


def test_commands_take_theta_and_d_from_the_set_three_cards():
    """Type IV: θ and T are the cards' THA and DD (Table A2-10), whatever the hand's pose."""
    deck = embedded_deck("illustration6")
    H = fk(*(lambda m: (m, m.q_home))(deck_model(deck)))
    for c in deck.commands:
        path = command_path(H, c.direction, c.distance, c.angle, c.frame)
        th, t = stage_motion(path)
        assert th == pytest.approx(abs(c.angle_deg), abs=1e-9)
        assert t == pytest.approx(abs(c.distance), abs=1e-9)
        H = path.end


@pytest.mark.parametrize("name", ["illustration4", "illustration5", "illustration6",
                                  "illustration7"])
def test_disp_uses_the_rule_and_guide_keeps_kinestats(name):
    deck = embedded_deck(name)
    assert deck.it == 0
    model, P0, _ = deck_initial_hand(deck, deck_model(deck))
    H = fk(model, model.q_home)
    path = resolve_stage(deck_stages(deck, P0)[0], H)
    run = run_deck(deck).result
    assert run.steps[0] == disp_step_count(path)
    if deck.ms != 0:  # Illustration 4 starts singular and re-plans after the perturbation
        kin = run_deck(deck, auto_steps="kinestat").result
        L = characteristic_length(model, model.q_home)
        assert kin.steps[0] == auto_steps(path, L) != run.steps[0]


def test_type_ii_steps_aim_from_the_actual_hand():
    """DISP's type II (App. I: the actual hand "for any intermediate stage"): a step's twist
    carries the actual hand onto the screw's next pose, and the errors of a run do not add up
    as with eq. 4-19's constant twist."""
    from kinestat.serial.guidance.planners import twist_between
    from kinestat.serial.guidance.run import run_guidance
    from kinestat.spatial.se3 import twist_exp

    T0, T1 = _pose([0.1, 0.2, 0.3], [15.0, -25, 12]), _pose([0.3, -0.2, 1.0], [10.0, -10, 20])
    p = screw_path(T0, T1, from_actual=True)
    off = _pose([0.01, -0.02, 0.0], [15.1, -25.0, 12.05])
    np.testing.assert_allclose(twist_exp(p.step_twist(0.2, 0.3, off)) @ off, p.pose_at(0.3),
                               atol=1e-9)
    np.testing.assert_allclose(p.step_twist(0.2, 0.3, off), twist_between(off, p.pose_at(0.3)))
    deck = embedded_deck("illustration5-corrected")
    m = deck_model(deck)
    H = fk(m, m.q_home)
    target = H @ _pose([0.0, 0.4, 0.2], [2.0, -1.0, 1.5])
    errs = []
    for fa in (False, True):
        r = run_guidance(m, m.q_home, [screw_path(H, target, from_actual=fa)], steps=12)
        errs.append(r.max_path_deviation()[0])
    assert errs[1] < 0.5 * errs[0]


def test_the_published_counts_fix_the_constants_and_rule_out_illustration_4s_22():
    """Round-max (the rule's form): 27, 9 and 4 bound c1, 35 bounds c2 (both non-empty), and
    no (c1, c2) in those bounds gives Illustration 4's "Total 22" (docs/disp-decks.md)."""
    motions = {}
    for name in ("illustration4", "illustration5", "illustration6", "illustration7"):
        deck = embedded_deck(name)
        model, P0, _ = deck_initial_hand(deck, deck_model(deck))
        H = fk(model, model.q_home)
        for i, spec in enumerate(deck_stages(deck, P0)):
            path = resolve_stage(spec, H)
            motions[(name, i)] = stage_motion(path)
            H = path.end
    lo1, hi1 = 0.0, math.inf
    for key, k in ((("illustration5", 0), 27), (("illustration6", 0), 9),
                   (("illustration6", 1), 4)):
        th = motions[key][0]  # rotation-limited: θ/c1 rounds to k
        lo1, hi1 = max(lo1, th / (k + 0.5)), min(hi1, th / (k - 0.5))
    d7 = motions[("illustration7", 0)][1]
    lo2, hi2 = d7 / 35.5, d7 / 34.5
    assert lo1 < DISP_STEP_DEG <= hi1 and lo2 < DISP_STEP_HAND <= hi2
    th4, t4 = motions[("illustration4", 0)]
    assert max(th4 / lo1, t4 / lo2) < 21.5  # the largest count the bounds allow: 16


def test_total_steps_counts_every_solve_as_table_a2_9s_caption():
    """Table A2-9's caption "Total 38 steps" (Illustration 5, published): 27 path steps, the
    sub-steps and the correction row of the inferred 1977 step (erratum G1); JSON and result
    agree."""
    from kinestat.disp import deck_json, disp_options
    from kinestat.disp.steps import total_steps

    deck = embedded_deck("illustration5-published")
    run = run_deck(deck, options=disp_options(deck=deck, disp_1977=True))
    r = run.result
    assert r.steps == (27,) and len(r.settle_rows()) == 1 and r.substeps > 0
    assert total_steps(r) == 38 == deck_json(run)["total_steps"]


def _frame_ok(P, card=0.005):
    """Three F10.2 cards fix a frame: unit +z and +x points at right angles to the cards'
    rounding (each coordinate ±card)."""
    z, x = P[1] - P[0], P[2] - P[0]
    t_len = 2 * card * math.sqrt(3.0)
    t_dot = 2 * card * (np.abs(z).sum() + np.abs(x).sum()) + 3 * (2 * card) ** 2
    return (abs(np.linalg.norm(z) - 1) <= t_len and abs(np.linalg.norm(x) - 1) <= t_len
            and abs(z @ x) <= t_dot)


def _frame(P):
    z = (P[1] - P[0]) / np.linalg.norm(P[1] - P[0])
    y = np.cross(z, P[2] - P[0])
    y /= np.linalg.norm(y)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([np.cross(y, z), y, z])
    T[:3, 3] = P[0]
    return T


def test_illustration4s_target_cards_and_their_misreadings_do_not_give_22():
    """Erratum G7, the deck: Table A2-5's target cards are a frame to their precision (the
    text's −9.29 is not), and no one-character misreading (a digit, a sign) that still is one
    moves the count near 22."""
    deck = embedded_deck("illustration4")
    model, P0, _ = deck_initial_hand(deck, deck_model(deck))
    H = fk(model, model.q_home)
    cards = np.array(deck.positions[-1], dtype=float)
    assert _frame_ok(cards)
    text = cards.copy()
    text[1, 1] = -9.29
    assert not _frame_ok(text)
    counts = set()
    for i in range(3):
        for j in range(3):
            s = f"{abs(cards[i, j]):.2f}"
            values = [-cards[i, j]] + [math.copysign(float(s[:n] + d + s[n + 1:]), cards[i, j])
                                       for n in range(len(s)) if s[n] != "."
                                       for d in "0123456789" if d != s[n]]
            for v in values:
                P = cards.copy()
                P[i, j] = v
                if _frame_ok(P):
                    counts.add(disp_step_count(screw_path(H, _frame(P))))
    assert counts and max(counts) <= 17


def test_illustration4s_count_at_a_new_configuration_is_not_22():
    """Erratum G7: the count taken where DISP's small increments left the arm (every joint by
    ±δ, δ ≤ 5°, 64 sign patterns) stays at 13..21: the screw's θ and d change too little."""
    deck = embedded_deck("illustration4")
    model, P0, _ = deck_initial_hand(deck, deck_model(deck))
    q0 = np.asarray(model.q_home, dtype=float)
    target = resolve_stage(deck_stages(deck, P0)[0], fk(model, q0)).end
    signs = np.array(np.meshgrid(*[[1.0, -1.0]] * 6)).reshape(6, -1).T
    counts = {disp_step_count(screw_path(fk(model, q0 + math.radians(d) * s), target))
              for d in (1.0, 3.0, 5.0) for s in signs}
    assert max(counts) < 22 and min(counts) >= 13


def test_an_illustration4_run_of_eq_4_11_needs_a_correction_row_to_land():
    """Erratum G7: DISP's run ended on the target; k first-order steps of the screw from a new
    configuration (every joint ±1.5°, clearing the criterion) end ≥ 0.005 in off, so one
    correction row at least follows: with the caption counting every solve, "Total 22" leaves
    at most 21 path steps."""
    from kinestat.disp.deck import PRINTED_PRECISION, disp_cond_limit
    from kinestat.serial.guidance.rules import GuidanceOptions
    from kinestat.serial.guidance.run import run_guidance

    deck = embedded_deck("illustration4")
    model, P0, _ = deck_initial_hand(deck, deck_model(deck))
    q0 = np.asarray(model.q_home, dtype=float)
    target = resolve_stage(deck_stages(deck, P0)[0], fk(model, q0)).end
    opts = GuidanceOptions(singular="stop", cond_limit=disp_cond_limit(deck), settle=False)
    ends = []
    for s in ([1, -1, -1, 1, -1, 1], [1, 1, 1, 1, 1, 1], [-1, 1, -1, 1, 1, -1]):
        q = q0 + math.radians(1.5) * np.array(s, dtype=float)
        for k in (16, 22):
            r = run_guidance(model, q, [lambda H: screw_path(H, target, from_actual=True)],
                             steps=k, options=opts)
            if not r.stopped:
                ends.append(r.final_pose_error()[0])
    assert ends and min(ends) > 10 * PRINTED_PRECISION
