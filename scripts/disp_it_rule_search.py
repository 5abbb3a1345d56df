"""Search for DISP's IT = 0 step-count rule (Nadkarni 1977, App. I) among two-constant rules.

The published counts: Illustration 4 "Total 22 steps" (MS 0), 5: 27 path steps (MS 4, Table
A2-9), 6: 9 and 4 (MS 5), 7: 35 (MS 6). For every stage the features DISP knew at its start are
computed from the embedded decks (the screw angle θ, translations of the displacement, the
hand's size), then every rule form ``R(f(θ/c1, T/c2))`` with R = round, ceil or floor and
f = max, sum, root-sum-square (and the one-constant forms) is checked on a fine grid of the two
constants. Prints, per form and feature, whether the five counts can all be met and, when they
can, the range of each constant; then the same without Illustration 4, and with Illustration 4
at each path-step count from 16 to 22.

    PYTHONPATH=$PWD python scripts/disp_it_rule_search.py

docs/disp-decks.md, "IT = 0", states the outcome.
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.disp import deck_model, deck_stages
from kinestat.disp.deck import deck_initial_hand
from kinestat.io.disp_deck import embedded_deck
from kinestat.serial.fk import fk
from kinestat.serial.guidance.planners import GeneralPath, resolve_stage
from kinestat.spatial.displacement import frame_from_triple, screw_from_poses

#: (deck, published count per stage)
PUBLISHED = (("illustration4", (22,)), ("illustration5-published", (27,)),
             ("illustration6-corrected", (9, 4)), ("illustration7-corrected", (35,)))

#: Illustration 4's text prints b2 = (-20.65, -9.29, -5.85) where Table A2-5 has -8.29
#: (seed-errata D1); tried as the card DISP may have read.
ILL4_TEXT_B2 = np.array([[-20.30, -7.83, -6.66], [-20.65, -9.29, -5.85],
                         [-21.06, -7.18, -6.62]])


def _points(H) -> np.ndarray:
    return np.array([H[:3, 3], H[:3, 3] + H[:3, 2], H[:3, 3] + H[:3, 0]])


def stage_features(H0, H1, kind: str, hand: float = 1.0) -> dict[str, float]:
    """θ (deg) and candidate translations (deck units) of one stage; ``hand`` the hand's size
    on the cards (the largest distance of the +z point from the origin, start or target)."""
    sc = screw_from_poses(H0, H1)
    th = abs(float(sc.theta))
    d = abs(float(sc.d))
    u, p = np.asarray(sc.axis, dtype=float), np.asarray(sc.point, dtype=float)
    o0, o1 = H0[:3, 3], H1[:3, 3]
    r = float(np.linalg.norm(np.cross(o0 - p, u)))
    rho_n = float(np.linalg.norm(p - (p @ u) * u))
    chord = float(np.linalg.norm(o1 - o0))
    helix = math.hypot(d, r * th)
    origin_path = {"screw": helix, "command": d, "line": chord, "general": chord}[kind]
    return {
        "theta": math.degrees(th),
        "d (along the screw axis)": d,
        "origin chord D": chord,
        "origin helix": helix,
        "origin arc r*theta": r * th,
        "chord across the axis": math.sqrt(max(0.0, chord * chord - d * d)),
        "global-origin point |v|": math.hypot(d, rho_n * th),
        "largest hand-point chord": float(np.max(np.linalg.norm(
            _points(H1) - _points(H0), axis=1))),
        "origin path of the type": origin_path,
        "type's delta-r (d; D for type I)": chord if kind == "general" else d,
        "origin path / card hand size": origin_path / hand,
        "type's delta-r / card hand size": (chord if kind == "general" else d) / hand,
    }


def all_features(ill4_points=None) -> tuple[list[dict[str, float]], list[int]]:
    feats, counts = [], []
    for name, published in PUBLISHED:
        deck = embedded_deck(name)
        model, P0, _ = deck_initial_hand(deck, deck_model(deck))
        H = fk(model, model.q_home)
        kind = {0: "screw", 4: "line", 5: "command", 6: "general"}[deck.ms]
        for spec, k in zip(deck_stages(deck, P0), published, strict=True):
            path = resolve_stage(spec, H)
            end = np.asarray(path.end, dtype=float)
            cards = None if deck.positions is None else np.asarray(deck.positions[-1])
            if ill4_points is not None and deck.ms == 0:
                end, cards = frame_from_triple(ill4_points), ill4_points
            hand = 1.0 if cards is None else max(1.0, float(np.linalg.norm(cards[1] - cards[0])))
            assert kind != "general" or isinstance(path, GeneralPath)
            feats.append(stage_features(H, end, kind, hand))
            counts.append(k)
            H = end
    return feats, counts


ROUNDINGS = {"round": lambda x: np.floor(x + 0.5), "ceil": lambda x: np.ceil(x - 1e-12),
             "floor": np.floor}
FORMS = {"max": np.maximum, "sum": np.add, "rss": np.hypot}


def _ranges(ok, c1, c2) -> str:
    if not ok.any():
        return "none"
    i, j = np.nonzero(ok)
    return (f"c1 {c1[i].min():.3f}..{c1[i].max():.3f} deg, "
            f"c2 {c2[j].min():.4f}..{c2[j].max():.4f}")


def search(feats, counts, n: int = 1500) -> list[tuple[str, str, str, str]]:
    c1 = np.geomspace(0.5, 30.0, n)  # degrees per step
    c2 = np.geomspace(0.02, 20.0, n)  # hand sizes per step
    target = np.array(counts)
    th = np.array([f["theta"] for f in feats])
    out = []
    for tname in [k for k in feats[0] if k != "theta"]:
        T = np.array([f[tname] for f in feats])
        for rname, R in ROUNDINGS.items():
            for fname, F in FORMS.items():
                ok = np.ones((n, n), dtype=bool)
                for a, t, k in zip(th, T, target, strict=True):
                    ok &= R(F((a / c1)[:, None], (t / c2)[None, :])) == k
                out.append((tname, rname, fname, _ranges(ok, c1, c2)))
            one = np.ones(n, dtype=bool)
            for t, k in zip(T, target, strict=True):
                one &= R(t / c2) == k
            out.append((tname, rname, "T/c2 alone", _ranges(one[None, :], c1[:1], c2)))
    c0 = np.linspace(-10.0, 10.0, n)  # an offset (steps) as the second constant
    for rname, R in ROUNDINGS.items():
        ok = np.ones((n, n), dtype=bool)
        for a, k in zip(th, target, strict=True):
            ok &= R((a / c1)[:, None] + c0[None, :]) == k
        out.append(("-", rname, "theta/c1 + c0", "none" if not ok.any() else "fits"))
    return out


def main() -> None:
    for label, pts in (("Table A2-5's b2 (-8.29)", None), ("the text's b2 (-9.29)",
                                                          ILL4_TEXT_B2)):
        feats, counts = all_features(pts)
        print(f"== Illustration 4 with {label}")
        for f, k in zip(feats, counts, strict=True):
            print(f"  count {k:3d}: " + ", ".join(f"{n} {v:.3f}" for n, v in f.items()))
        rows = search(feats, counts)
        fits = [r for r in rows if r[3] != "none"]
        print(f"  rules fitting all five counts: {len(fits)} of {len(rows)}")
        for r in fits:
            print("   ", " | ".join(r))
        rest = search(feats[1:], counts[1:])
        print("  without Illustration 4:")
        for r in rest:
            if r[3] != "none":
                print("   ", " | ".join(r))
        # Illustration 5's caption counts every solve ("Total 38" = 27 + 10 sub-steps + 1
        # correction): Illustration 4's 22 then bounds its path steps to 16..21
        # (scripts/disp_ill4_total_checks.py); which of those can the others' rules give?
        print("  Illustration 4 at k path steps (the other four counts as published):")
        for k4 in range(16, 23):
            fits = [r for r in search(feats, [k4, *counts[1:]], n=600) if r[3] != "none"]
            print(f"    k = {k4}: {len(fits)} of {len(rows)} rules fit: "
                  + ("; ".join(" ".join(r[:3]) for r in fits) or "-"))


if __name__ == "__main__":
    main()
