"""The closed-loop correction (``--closed-loop``): a tolerance relative to the mechanism's size,
and a stop that says what happened (issue 42)."""

from __future__ import annotations

import dataclasses
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from kinestat.disp import disp_options, run_deck
from kinestat.io.disp_deck import embedded_deck
from kinestat.serial.guidance.events import NotConverged
from kinestat.serial.guidance.planners import pose_error


def _family_script():
    path = Path(__file__).resolve().parents[3] / "scripts" / "disp_closed_loop_family.py"
    spec = importlib.util.spec_from_file_location("disp_closed_loop_family", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _deck(ms: int, target) -> object:
    base = embedded_deck("illustration5")
    return dataclasses.replace(base, ms=ms, positions=np.stack([np.zeros((3, 3)), target]))


def test_straight_line_deck_of_the_issue_lands_with_131_steps():
    """Illustration 5's mechanism to (12, -8, 18) along a straight line: every step converges
    (the fixed 1e-12 tolerance stopped it at step 125 with an error of 1.9e-11 in)."""
    deck = _deck(4, [[12.0, -8, 18], [12, -8, 19], [13, -8, 18]])
    opts = disp_options(closed_loop=True)
    r = run_deck(deck, steps=131, options=opts).result
    assert not r.stopped, r.stop_message
    dp, da = pose_error(r.poses, r.ideal)  # every row on its path pose
    assert np.max(dp) <= opts.tol * r.length and np.max(da) <= opts.tol
    assert r.final_pose_error()[0] <= opts.tol * r.length


def test_tolerance_scales_with_the_mechanism():
    """The same motion in millimetres instead of inches: the same rows, to the tolerance."""
    deck = _deck(4, [[12.0, -8, 18], [12, -8, 19], [13, -8, 18]])
    k = 25.4
    mm = dataclasses.replace(
        deck, positions=np.array(deck.positions) * k, frame_points=np.array(deck.frame_points) * k,
        joints=[dataclasses.replace(j, r=j.r * k, a=j.a * k) for j in deck.joints])
    opts = disp_options(closed_loop=True)
    r_in = run_deck(deck, steps=60, options=opts).result
    r_mm = run_deck(mm, steps=60, options=opts).result
    assert not r_in.stopped and not r_mm.stopped
    assert r_mm.length == pytest.approx(k * r_in.length)
    np.testing.assert_allclose(r_mm.poses[:, :3, 3], k * r_in.poses[:, :3, 3],
                               atol=10 * opts.tol * r_mm.length)


def test_random_family_lands_or_stops_for_a_true_reason():
    """A seeded random family of straight-line and screw decks (the script runs 20; 6 here):
    each lands within 1e-9 L or stops where the wrist is singular (checked from sin θ5)."""
    fam = _family_script()
    for k, (deck, steps) in enumerate(fam.family(6, seed=42)):
        assert deck.ms == (4 if k % 2 == 0 else 0) and 50 <= steps <= 300
        res = fam.check(deck, steps)
        assert res["true"], (k, res)


def test_a_failed_correction_says_what_happened():
    """A step too large for Newton from a near-singular start (Illustration 4's mechanism, a
    target far out, 5 steps): the stop names its reason and the numbers behind it."""
    base = embedded_deck("illustration4")
    P = np.array(base.positions)
    far = P[1] + np.array([30.0, 0, 0])
    r = run_deck(dataclasses.replace(base, ms=4, positions=np.stack([P[0], far])), steps=5,
                 options=disp_options(closed_loop=True)).result
    assert r.stopped and isinstance(r.stop_event, NotConverged)
    ev = r.stop_event
    assert ev.reason in ("singular", "out_of_reach", "diverged")
    assert (ev.reason == "singular") == (ev.cond > 1e3)
    assert f"{ev.cond:.3g}" in r.stop_message and "tolerance" in r.stop_message
    assert ev.position_error > disp_options(closed_loop=True).tol * r.length
