"""Illustration 4's "Total 22 steps" (Nadkarni 1977, App. II): the checks behind erratum G7.

The inferred IT = 0 rule (kinestat.disp.steps) gives 16 path steps for Illustration 4 and the
published 27, 9 + 4 and 35 for Illustrations 5-7; ``scripts/disp_it_rule_search.py`` finds no
two-constant rule that gives 22 with them. Our copy of the thesis withholds Illustration 4's
table (and with it the caption and DISP's new configuration), so these checks test the
remaining readings by computation:

1. the deck: Table A2-5's target cards form a frame to their F10.2 precision, and no
   single-character misreading of them that still does changes the count to 22;
2. the count taken at DISP's new (perturbed) configuration instead of the singular start:
   every joint by an equal increment of either sign, up to 5 deg;
3. Illustration 5's caption convention ("Total 38" = 27 path steps + 10 extra sub-steps + 1
   correction: every solve of eq. 4-11): Illustration 4's total under it, with the rule's 16
   path steps, from new configurations that clear the singularity criterion; it depends on the
   first step out of the near-singular start;
4. the translations of Illustration 4 DISP knew, against the band 22 would need;
5. which path-step count gives a total of 22 under that convention.

    PYTHONPATH=$PWD python scripts/disp_ill4_total_checks.py
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections import Counter

import numpy as np

from kinestat.disp import deck_model, deck_stages
from kinestat.disp.deck import PRINTED_PRECISION, deck_initial_hand, disp_cond_limit
from kinestat.disp.steps import DISP_STEP_DEG, DISP_STEP_HAND, disp_step_count, total_steps
from kinestat.io.disp_deck import embedded_deck
from kinestat.serial.fk import fk, fk_frames
from kinestat.serial.guidance.planners import resolve_stage, screw_path
from kinestat.serial.guidance.rules import GuidanceOptions
from kinestat.serial.guidance.run import run_guidance
from kinestat.serial.guidance.step import conditioning, scaled_jacobian
from kinestat.serial.jacobian import jacobian
from kinestat.serial.lengths import characteristic_length
from kinestat.spatial.displacement import frame_from_triple, screw_from_poses

DECK = embedded_deck("illustration4")
MODEL, P0, _ = deck_initial_hand(DECK, deck_model(DECK))
Q0 = np.asarray(MODEL.q_home, dtype=float)
H0 = fk(MODEL, Q0)
TARGET = np.asarray(resolve_stage(deck_stages(DECK, P0)[0], H0).end, dtype=float)
L = characteristic_length(MODEL, Q0)
LIMIT = disp_cond_limit(DECK)
CARD = 0.005  # half the last decimal of an F10.2 card


def cond(q) -> float:
    return float(conditioning(scaled_jacobian(jacobian(MODEL, q), MODEL.prismatic, L))[1])


def count_from(H, target) -> int:
    return disp_step_count(screw_path(H, target))


def frame_consistent(P) -> bool:
    """The three cards are an origin and unit +z, +x points at right angles, within what the
    cards' rounding allows (each coordinate ±0.005)."""
    z, x = P[1] - P[0], P[2] - P[0]
    t_len = 2 * CARD * math.sqrt(3.0)
    t_dot = 2 * CARD * (np.abs(z).sum() + np.abs(x).sum()) + 3 * (2 * CARD) ** 2
    return bool(abs(np.linalg.norm(z) - 1) <= t_len and abs(np.linalg.norm(x) - 1) <= t_len
                and abs(z @ x) <= t_dot)


def misreadings(v: float):
    """Every value one OCR character away from ``v`` as printed to two decimals: one digit
    replaced, or the sign dropped/added."""
    s = f"{abs(v):.2f}"
    sign = -1.0 if v < 0 else 1.0
    for i, ch in enumerate(s):
        if ch != ".":
            for dgt in "0123456789":
                if dgt != ch:
                    yield sign * float(s[:i] + dgt + s[i + 1:])
    yield -v


def check_deck() -> None:
    cards = np.asarray(DECK.positions[-1], dtype=float)
    print("1. Table A2-5's target cards:", cards.tolist())
    z, x = cards[1] - cards[0], cards[2] - cards[0]
    print(f"   |z| {np.linalg.norm(z):.4f}, |x| {np.linalg.norm(x):.4f}, z.x {z @ x:+.4f}: "
          f"a frame to the cards' precision: {frame_consistent(cards)}")
    text_b2 = cards.copy()
    text_b2[1, 1] = -9.29
    print(f"   the text's b2 y = -9.29 (erratum D1): a frame: {frame_consistent(text_b2)}")
    counts: Counter = Counter()
    for i, j in itertools.product(range(3), range(3)):
        for v in misreadings(cards[i, j]):
            P = cards.copy()
            P[i, j] = v
            if frame_consistent(P):
                counts[count_from(H0, frame_from_triple(P))] += 1
    print(f"   single-character misreadings that still form a frame: {sum(counts.values())}, "
          f"counts {sorted(counts.items())} (printed cards: {count_from(H0, TARGET)})")
    a = fk_frames(MODEL, Q0)[-1]
    print(f"   start from Table A2-2 by FK, hand origin {np.round(a[:3, 3], 3).tolist()} "
          "(the text's a1 = [-24.315, 5.273, 4.059])")


def perturbed(signs, deg: float) -> np.ndarray:
    return Q0 + math.radians(deg) * np.asarray(signs, dtype=float)


def check_new_configuration() -> None:
    print("2. The count taken at a new configuration (every joint ±deg, 64 sign patterns):")
    for deg in (0.5, 1.0, 2.0, 3.0, 4.0, 5.0):
        ks, clear = Counter(), 0
        for s in itertools.product((1, -1), repeat=6):
            q = perturbed(s, deg)
            ks[count_from(fk(MODEL, q), TARGET)] += 1
            clear += cond(q) < LIMIT
        print(f"   {deg:3.1f} deg: counts {min(ks)}..{max(ks)}, 22 in {ks[22]} of 64 "
              f"({clear} clear the criterion L/0.005 = {LIMIT:.0f})")


VARIANTS = {
    "eq. 4-11 as printed, no sub-steps": (GuidanceOptions(singular="stop"), False),
    "Illustration 5's step (disp_1977)": (GuidanceOptions.disp_1977(singular="stop"), False),
    "kinestat disp's sub-steps (3.36 deg)": (
        GuidanceOptions(singular="stop", counted_substep_deg=DISP_STEP_DEG), True),
}


def caption_total(q, options: GuidanceOptions, counted: bool, k: int,
                  settle: bool = True):
    """A run of ``k`` path steps of the screw from ``q`` to the target, with DISP's correction
    rows (``settle``): every solve it made (None when it stops or does not land to the
    printed precision) and its end error before any correction."""
    opts = dataclasses.replace(options, cond_limit=LIMIT, settle=settle,
                               settle_tol=PRINTED_PRECISION, settle_length=1.0)
    stage = [lambda H: screw_path(H, TARGET, from_actual=True)]
    if counted:
        r = run_guidance(MODEL, q, stage, options=opts, step_count=lambda _p: k)
    else:
        r = run_guidance(MODEL, q, stage, steps=k, options=opts)
    return (None if r.stopped else total_steps(r)), r.final_pose_error()[0]


def new_configurations() -> list[np.ndarray]:
    """Every joint by ±1, 1.5, 2 or 3 deg (64 sign patterns each), those that clear DISP's
    criterion."""
    starts = [perturbed(s, deg) for deg in (1.0, 1.5, 2.0, 3.0)
              for s in itertools.product((1, -1), repeat=6)]
    return [q for q in starts if cond(q) < LIMIT]


def check_caption_convention() -> None:
    k = count_from(H0, TARGET)
    starts = new_configurations()
    print(f"3. 'Total' as Illustration 5 counts it (path steps + extra sub-steps + corrections),"
          f" {k} path steps, from {len(starts)} new configurations that clear the criterion:")
    for name, (opts, counted) in VARIANTS.items():
        ok = sorted(t for t, _ in (caption_total(q, opts, counted, k) for q in starts)
                    if t is not None)
        print(f"   {name}: {len(ok)} land; totals {ok[0]}..{ok[-1]}, median "
              f"{ok[len(ok) // 2]}, 22 in {ok.count(22)}")
    plain = VARIANTS["eq. 4-11 as printed, no sub-steps"][0]
    print("   k path steps of eq. 4-11: end error before correcting, and totals with DISP's "
          "correction rows:")
    for kk in (16, 21, 22):
        bare = min(caption_total(q, plain, False, kk, settle=False)[1] for q in starts)
        tot = Counter(t for t, _ in (caption_total(q, plain, False, kk) for q in starts)
                      if t is not None)
        print(f"   k = {kk}: smallest end error {bare:.4f} in (> {PRINTED_PRECISION}: a "
              f"correction row is needed); totals {sorted(tot.items())}")


def check_which_k() -> None:
    starts = new_configurations()
    print("5. Which path-step count k gives a total of 22 (of the runs that land):")
    for name in ("eq. 4-11 as printed, no sub-steps", "Illustration 5's step (disp_1977)"):
        opts, counted = VARIANTS[name]
        row = []
        for k in range(16, 22):
            land = [t for t, _ in (caption_total(q, opts, counted, k) for q in starts)
                    if t is not None]
            row.append(f"k = {k}: {land.count(22)}/{len(land)}")
        print(f"   {name}: " + ", ".join(row))


def check_translations() -> None:
    # c1 from 27, 9 and 4 (90, 30 and 15 deg), c2 from 35 (17.72 in): rounding to the nearest
    th_lo = max(90.0 / 27.5, 30.0 / 9.5, 15.0 / 4.5)
    th_hi = min(90.0 / 26.5, 30.0 / 8.5, 15.0 / 3.5)
    t_lo, t_hi = 21.5 * 17.72 / 35.5, 22.5 * 17.72 / 34.5  # T for 22 with c2 from Ill. 7's 35
    sc = screw_from_poses(H0, TARGET)
    th, d = abs(float(sc.theta)), abs(float(sc.d))
    u, p = np.asarray(sc.axis, float), np.asarray(sc.point, float)
    print(f"4. Illustration 4: θ = {math.degrees(th):.3f} deg (22 would need c1 <= "
          f"{math.degrees(th) / 21.5:.2f} deg; Illustrations 5, 6 allow {th_lo:.3f}.."
          f"{th_hi:.3f}), d = {d:.3f}; 22 from T/c2 needs T in [{t_lo:.2f}, {t_hi:.2f})")
    rel = TARGET @ np.linalg.inv(H0)
    pts = {"hand origin": H0[:3, 3], "+z point": H0[:3, 3] + H0[:3, 2],
           "+x point": H0[:3, 3] + H0[:3, 0], "wrist point X(5)": fk_frames(MODEL, Q0)[5][:3, 3],
           "global origin, carried by the hand": np.zeros(3)}
    for name, x in pts.items():
        r = float(np.linalg.norm(np.cross(x - p, u)))
        chord = float(np.linalg.norm((rel @ np.append(x, 1.0))[:3] - x))
        print(f"   {name}: chord {chord:.3f}, helix {math.hypot(d, r * th):.3f}")
    print(f"   (rule's constants: {DISP_STEP_DEG} deg, {DISP_STEP_HAND} hand sizes)")


def main() -> None:
    check_deck()
    check_new_configuration()
    check_caption_convention()
    check_translations()
    check_which_k()


if __name__ == "__main__":
    main()
