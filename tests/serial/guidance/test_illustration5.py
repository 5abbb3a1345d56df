"""Illustration 5 (Nadkarni 1977, App. II): the embedded ``illustration5-published`` deck against
the published Table A2-9, and what the published table itself implies about the input
(docs/errata/guidance.md G1)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import kinestat
from kinestat.io.disp_deck import embedded_deck
from kinestat.serial.guidance.disp import deck_initial_hand, deck_model, run_deck
from kinestat.serial.guidance.planners import line_path, twist_between
from kinestat.serial.guidance.run import joint_display

# Table A2-9: r1, r2, r3 (in), θ4, θ5, θ6 (deg) — the initial position and the nine printed
# intermediate rows ("Total 38 steps"); then the final position.
TABLE_A2_9 = np.array([
    [0.000, 25.000, 8.000, 0.000, 90.000, 0.000],
    [-0.225, 26.496, 7.704, 10.000, 90.000, 0.000],
    [-0.948, 27.775, 7.407, 21.801, 90.000, 0.000],
    [-1.960, 28.790, 7.111, 32.005, 90.000, 0.000],
    [-3.108, 29.464, 6.815, 41.009, 90.000, 0.000],
    [-4.229, 29.864, 6.519, 48.652, 90.000, 0.000],
    [-5.317, 29.953, 6.222, 55.008, 90.000, 0.000],
    [-6.254, 29.919, 5.926, 60.255, 90.000, 0.000],
    [-7.138, 29.674, 5.630, 64.592, 90.000, 0.000],
    [-7.918, 29.343, 5.333, 68.199, 90.000, 0.000],
])
TABLE_A2_9_FINAL = np.array([-15.000, 20.000, 0.000, 90.000, 90.000, 0.000])
HALF_UNIT = 5e-4 + 1e-9  # half a unit of the printed third decimal
K = 27


def test_published_deck_is_table_a2_8_with_three_changes():
    printed = embedded_deck("illustration5")
    published = embedded_deck("illustration5-published")
    assert (printed.ms, printed.np_, printed.it) == (4, 2, 0)
    assert (published.ms, published.np_, published.it, published.io) == (4, 2, K, 0)
    P0, P1 = np.array(printed.positions), np.array(published.positions)
    changed = np.argwhere(P0 != P1)
    assert [tuple(c) for c in changed] == [(1, 1, 0)]  # the target's +z point, x only
    np.testing.assert_array_equal(P1[1, 1], [15.0, -10.0, 20.0])
    for i, (a, b) in enumerate(zip(printed.joints, published.joints, strict=True)):
        if i == 6:
            assert (a.a, b.a) == (0.0, 1.0)  # Table A2-7's a7 (erratum D3)
            b = dataclasses.replace(b, a=0.0)
        assert a == b
    np.testing.assert_array_equal(printed.frame_points, published.frame_points)


def test_table_a2_9_itself_implies_27_splits_and_a_5_to_1_turn_of_the_z_point():
    """From the published numbers alone: r3 falls by 8/27 per row (38 equal splits would give
    8/38), and θ4 of rows 2-9 is the direction of (1 - s)(0, 1, 0) + s(5, 0, 0), s = j/27."""
    dr3 = np.diff(TABLE_A2_9[:, 2])
    np.testing.assert_allclose(dr3, -8 / K, atol=1.1e-3)
    assert np.all(np.abs(dr3 + 8 / 38) > 0.08)
    j = np.arange(2, 10)
    np.testing.assert_allclose(TABLE_A2_9[2:, 3], np.degrees(np.arctan2(5 * j, K - j)),
                               atol=HALF_UNIT)
    # a unit +z point at the target (the printed deck) turns far too slowly
    assert abs(math.degrees(math.atan2(9, K - 9)) - TABLE_A2_9[9, 3]) > 40
    # row 1 is the one row off that rule: atan(5/26) = 10.886 deg, printed 10.000
    assert math.degrees(math.atan2(5, 26)) - TABLE_A2_9[1, 3] == pytest.approx(0.886, abs=1e-3)


def test_published_deck_reproduces_table_a2_9():
    run = run_deck(embedded_deck("illustration5-published"))
    assert run.result.steps == (K,) and not run.result.stopped
    table = joint_display(run.result.model, run.result.q)
    for col in (2, 4, 5):  # r3, θ5, θ6 in every printed row
        np.testing.assert_allclose(table[:10, col], TABLE_A2_9[:, col], atol=HALF_UNIT)
    rows = [0, *range(2, 10)]  # θ4 in every row but the first
    np.testing.assert_allclose(table[rows, 3], TABLE_A2_9[rows, 3], atol=HALF_UNIT)
    # "coincides with the desired final position with three decimal accuracy"
    np.testing.assert_allclose(table[-1], TABLE_A2_9_FINAL, atol=5e-4)
    # the departures G1 leaves unexplained, bounded: θ4 of row 1, r1 and r2
    assert table[1, 3] - TABLE_A2_9[1, 3] == pytest.approx(0.886, abs=1e-3)
    dev = np.abs(table[:10, :2] - TABLE_A2_9[:, :2]).max(axis=0)
    assert dev[0] < 0.09 and dev[1] < 0.135


def test_printed_rows_are_farther_from_the_split_positions_than_one_first_order_step():
    """Every printed row's hand origin lies farther from the split position it aimed at than a
    single first-order type III step from the printed previous row leaves it — so no
    refinement of the step (sub-steps, second-order terms) can turn kinestat's rows into the
    printed ones; what DISP did differently makes the step *less* accurate (G1)."""
    deck = embedded_deck("illustration5-published")
    model, P0, _ = deck_initial_hand(deck, deck_model(deck))
    path = line_path(P0, np.array(deck.positions)[1])
    q_rows = np.where(model.prismatic, TABLE_A2_9, np.radians(TABLE_A2_9))
    for j in range(1, 10):
        q = q_rows[j - 1]
        target = path.pose_at(j / K)
        V = twist_between(kinestat.fk(model, q), target)
        q_step = q + np.linalg.solve(kinestat.jacobian(model, q), V)
        gap_step = np.linalg.norm(kinestat.fk(model, q_step)[:3, 3] - target[:3, 3])
        gap_printed = np.linalg.norm(kinestat.fk(model, q_rows[j])[:3, 3] - target[:3, 3])
        assert gap_printed > gap_step + 0.02, j
        # and the printed height is the split position's (r3 is exact)
        assert kinestat.fk(model, q_rows[j])[2, 3] == pytest.approx(target[2, 3], abs=1e-3)
