"""DISP decks for every MS, checked against the thesis's published results (Illustration 2's
TRANSM summary, Table A2-9 of Illustration 5) and geometric properties."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from kinestat.cli._guidance import parse_steps
from kinestat.disp import (
    deck_json,
    deck_model,
    disp_options,
    run_deck,
)
from kinestat.errors import InputError
from kinestat.io.disp_deck import embedded_deck
from kinestat.mechanism.nadkarni import hand_points
from kinestat.serial.fk import fk
from kinestat.serial.guidance.run import GuidanceOptions
from kinestat.spatial.displacement import frame_from_triple, pose_from_screw


def test_illustration2_joints_match_the_published_summary():
    """MS = 2: X*(i), U(i), ρn(i) as printed in Appendix II (two or three decimals)."""
    run = run_deck(embedded_deck("illustration2"))
    j = {d["joint"]: d for d in run.joints}
    assert len(j) == 7
    np.testing.assert_allclose(j[3]["origin_star"], [-11.95, 0.00, 2.488], atol=6e-3)
    np.testing.assert_allclose(j[6]["origin"], [-24.315, 5.273, 4.059], atol=6e-4)
    np.testing.assert_allclose(j[7]["origin"], [-24.833, 6.126, 3.998], atol=6e-4)
    np.testing.assert_allclose(j[4]["axis"], [0.112, -0.766, 0.633], atol=6e-4)
    np.testing.assert_allclose(j[7]["axis"], [0.171, 0.174, 0.970], atol=6e-4)
    np.testing.assert_allclose(j[6]["normal"], [-21.374, 0.121, 3.747], atol=6e-4)


def test_ms1_screws_carry_each_position_to_the_next():
    run = run_deck(embedded_deck("illustration1"))
    P = np.array(embedded_deck("illustration1").positions)
    assert len(run.screws) == 2
    for i, s in enumerate(run.screws):
        T1, T2 = frame_from_triple(P[i]), frame_from_triple(P[i + 1])
        D = pose_from_screw(s["axis"], s["point"], math.radians(s["angle_deg"]),
                            s["translation"])
        np.testing.assert_allclose(D @ T1, T2, atol=1e-9)
        assert abs(float(np.dot(s["axis"], s["point"]))) < 1e-9


def test_ms3_gives_both():
    rec = deck_json(run_deck(embedded_deck("illustration3")))
    assert rec["ms"] == 3 and len(rec["screws"]) == 2 and len(rec["joints"]) == 7
    assert "table" not in rec


@pytest.mark.parametrize("name", ["illustration4", "illustration6", "illustration7"])
def test_guidance_decks_reach_their_targets(name):
    # run_deck is DISP by default — one row per step; MS 0 (and 4) end with DISP's correction
    # rows to the printed precision, the others keep the first-order residual (noted);
    # settle=True corrects every stage to 1e-9
    deck = embedded_deck(name)
    bare = run_deck(deck).result
    n_settle = len(bare.settle_rows())
    assert not bare.stopped and (n_settle > 0) == (deck.ms == 0)
    assert not [e for e in bare.events if e.kind not in ("singular", "settle")]
    assert len(bare.q) == 1 + sum(bare.steps) + n_settle
    assert bare.final_pose_error()[0] < (5e-4 if deck.ms == 0 else 0.1)
    run = run_deck(embedded_deck(name), options=disp_options(settle=True))
    r = run.result
    assert not r.stopped
    dp, da = r.final_pose_error()
    assert dp < 1e-8 and da < 1e-9
    rec = deck_json(run)
    for key in ("table", "final_hand_points", "events", "steps", "final_pose_error",
                "max_path_deviation", "notes"):
        assert key in rec
    np.testing.assert_allclose(rec["final_hand_points"], hand_points(r.stage_targets[-1]),
                               atol=1e-8)
    assert len(rec["table"]) == len(r.q) and len(rec["table"][0]) == 6
    assert ("stage_hand_origins" in rec) == (name == "illustration6")


def test_illustration7_general_path_keeps_the_origin_on_a_line_when_closed():
    run = run_deck(embedded_deck("illustration7"), options=GuidanceOptions(closed_loop=True))
    o = run.result.poses[:, :3, 3]
    a1, a2 = np.array([15.0, -25, 12]), np.array([10.0, -10, 20])
    d = (a2 - a1) / np.linalg.norm(a2 - a1)
    rel = o - a1
    assert np.max(np.linalg.norm(rel - np.outer(rel @ d, d), axis=1)) < 1e-9


def test_seventh_joint_hand_and_the_inferior_option():
    deck = embedded_deck("illustration4")
    m = deck_model(deck)
    np.testing.assert_allclose(
        hand_points(fk(m, m.q_home)),
        [[-24.315, 5.273, 4.059], [-24.144, 5.447, 5.029], [-24.833, 6.126, 3.998]], atol=6e-4)
    # first position given = the printed a1, b1, c1 (to 3 decimals): agrees with x*(7)
    P = np.array(deck.positions)
    P[0] = [[-24.315, 5.273, 4.059], [-24.144, 5.447, 5.029], [-24.833, 6.126, 3.998]]
    run = run_deck(dataclasses.replace(deck, positions=P), steps=5,
                   options=disp_options(settle=True, singular="perturb"))
    assert any("inferior" in n for n in run.notes)  # 3-decimal points are 1e-3 off x*(7)
    np.testing.assert_allclose(run.result.poses[0], frame_from_triple(P[0]), atol=1e-12)
    assert run.result.final_pose_error()[0] < 1e-8


def test_a7_zero_runs_with_a_note():
    run = run_deck(embedded_deck("illustration6"))
    assert any(n.startswith("a7 = 0") for n in run.notes)
    ref = run_deck(embedded_deck("illustration6-corrected"))
    np.testing.assert_allclose(run.result.q, ref.result.q, atol=1e-12)


def test_parse_steps():
    assert parse_steps(None) is None and parse_steps("") is None
    assert parse_steps("40") == 40
    assert parse_steps("30, 12") == [30, 12]
    for bad in ("x", "1,,2", "-3"):
        with pytest.raises(InputError):
            parse_steps(bad)


def test_step_override_per_stage():
    run = run_deck(embedded_deck("illustration6"), steps=[10, 5],
                   options=GuidanceOptions(settle=False))
    assert run.result.steps == (10, 5) and len(run.result.q) == 16
    with pytest.raises(InputError):
        run_deck(embedded_deck("illustration6"), steps=[10, 5, 2])
