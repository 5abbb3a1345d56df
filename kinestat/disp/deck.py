"""Running a DISP deck (Nadkarni 1977, Appendix I) for every analysis type MS = 0..6:
deck -> model -> run (the DISP program; layer 3, an application of io + serial guidance).

============  ==========================================================================
MS            what runs (DISP subroutine)
============  ==========================================================================
1             screw axis between consecutive SET TWO positions (SCREWM)
2             every SET FOUR joint in the global frame: X*(i), X(i), U(i), ρn(i) (TRANSM)
3             1 and 2
0             type II screw path from the hand to each next position (DISPM)
4             type III straight lines of the hand points (SPLITM → DISPM)
5             type IV operator commands, each from where the last ended (GUIDM)
6             type I Example 4 (GENM)
============  ==========================================================================

The hand (MS = 0, 4, 5, 6): when SET TWO's first three cards are zero (and always for
MS = 5) it is the seventh joint's frame x*(7), i.e. the chain's forward kinematics at the
deck's initial configuration. A non-zero first position is the thesis's "inferior" option:
kinestat then takes the hand to be the body located by those three points, rigidly attached to
link 6 — the two agree when the points lie on x*(7) (origin, +z, +x side); when they do not,
the hand is a different body and a note says by how much.

The thesis asks for a7 > 0 because DISP builds the hand from three points, the third being the
x(7) origin a7 along the seventh normal. kinestat takes the frame x*(7) itself, so a7 only
matters for that check: a deck with a7 = 0 runs, with a note.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from kinestat.disp.steps import DISP_STEP_DEG, disp_step_count
from kinestat.errors import InputError
from kinestat.io.disp_deck import DispDeck, deck_warnings
from kinestat.mechanism.chain import ChainModel, from_nadkarni
from kinestat.mechanism.nadkarni import hand_points, mechanism_frames
from kinestat.serial.fk import fk
from kinestat.serial.guidance.planners import StageSpec, pose_error
from kinestat.serial.guidance.rules import GuidanceOptions, SingularMode
from kinestat.serial.guidance.run import GuidanceResult, run_guidance
from kinestat.serial.guidance.stages import command_stages, target_stages
from kinestat.serial.guidance.step import DEFAULT_COND_LIMIT
from kinestat.serial.lengths import characteristic_length
from kinestat.spatial.displacement import frame_from_triple, screws_between
from kinestat.spatial.transforms import inv

__all__ = [
    "DeckRun",
    "disp_options",
    "disp_cond_limit",
    "deck_model",
    "deck_initial_hand",
    "deck_screws",
    "deck_joints",
    "deck_stages",
    "run_deck",
    "TYPE_NAMES",
]

TYPE_NAMES = {0: "II (screw path)", 4: "III (hand point on a straight line)",
         5: "IV (operator commands)", 6: "I (general, Example 4)"}


@dataclass(frozen=True, eq=False)
class DeckRun:
    """Everything a deck produced: ``screws`` (MS 1, 3), ``joints`` (MS 2, 3), ``result``
    (MS 0, 4, 5, 6) and ``notes`` (deck warnings, hand choice, corrections)."""

    deck: DispDeck
    screws: list[dict] | None = None
    joints: list[dict] | None = None
    model: ChainModel | None = None
    result: GuidanceResult | None = None
    notes: tuple[str, ...] = ()


def deck_screws(deck: DispDeck) -> list[dict]:
    """MS = 1: the screw axis between every pair of consecutive SET TWO positions (SCREWM)."""
    if deck.positions is None:
        raise InputError(f"MS = {deck.ms} deck has no SET TWO positions")
    P = np.asarray(deck.positions, dtype=float)
    if deck.ms in (0, 4, 6) and deck.hand_from_seventh_joint:
        raise InputError("the first position is all zero (hand from the seventh joint)")
    sc = screws_between(frame_from_triple(P))
    out = []
    for i in range(P.shape[0] - 1):
        s = sc[i]
        out.append({
            "from_position": i + 1, "to_position": i + 2,
            "axis": np.asarray(s.axis), "point": np.asarray(s.point),
            "translation": float(s.d), "angle_deg": float(s.angle_deg),
            "pitch": float(s.pitch), "pure_translation": bool(s.is_translation),
        })
    return out


def deck_joints(deck: DispDeck) -> list[dict]:
    """MS = 2: every SET FOUR joint in the global frame (TRANSM, eqs. 2-10 to 2-18)."""
    if deck.joints is None or deck.frame_points is None:
        raise InputError(f"MS = {deck.ms} deck has no SET FOUR / SET FIVE")
    fr = mechanism_frames(deck.joint_table, deck.frame_points)
    return [
        {"joint": i + 1, "origin_star": fr.origin_star[i], "origin": fr.origin[i],
         "axis": fr.axis[i], "normal": fr.normal[i]}
        for i in range(len(deck.joints))
    ]


def deck_model(deck: DispDeck) -> ChainModel:
    """The six-joint chain of a guidance deck (SET FOUR, SET FIVE); its end frame is the
    seventh joint's x*(7) when N ≥ 7 (later joints are part of the hand, App. I), else x(6)."""
    if deck.joints is None or deck.frame_points is None:
        raise InputError(f"MS = {deck.ms} deck has no SET FOUR / SET FIVE")
    n = len(deck.joints)
    if n < 6:
        raise InputError(f"a guidance deck needs at least 6 joints, SET FOUR has {n}")
    rows = deck.joint_table[: min(n, 7)]
    name = deck.source.rsplit("/", 1)[-1].removesuffix(".dat") or "deck"
    return from_nadkarni(rows, deck.frame_points, n_active=6, name=name, length_unit="in",
                         description=f"DISP deck {deck.source}")


def deck_initial_hand(deck: DispDeck, model: ChainModel) -> tuple[ChainModel, np.ndarray,
                                                                  list[str]]:
    """The hand: ``(model, initial hand points (3, 3), notes)``.

    Seventh-joint option: the model as is and the unit points of x*(7). Inferior option (a
    non-zero first SET TWO position): the model's end frame re-attached to link 6 so that the
    hand at the initial configuration is the frame of those points.
    """
    notes: list[str] = []
    H7 = fk(model, model.q_home)
    if deck.ms == 5 or deck.hand_from_seventh_joint:
        if len(deck.joints or ()) < 7:
            raise InputError("the hand is defined by the seventh joint, but SET FOUR has "
                             f"{len(deck.joints or ())} joints: give N ≥ 7")
        a7 = deck.joints[6].a
        if a7 <= 0.0:
            notes.append(
                f"a7 = {a7:g}: DISP needs a7 > 0 to build the hand from three points; kinestat "
                "takes the seventh joint's frame x*(7) directly, so the run does not depend on "
                "a7 (Table A2-7 prints a7 = 1.00)")
        return model, hand_points(H7), notes
    P0 = np.asarray(deck.positions[0], dtype=float)
    Hg = frame_from_triple(P0)
    dp, da = pose_error(Hg, H7)
    if len(deck.joints) < 7:
        notes.append("SET FOUR has no seventh joint: the hand is the body located by the first "
                     "SET TWO position, rigidly attached to link 6")
    elif dp > 1e-6 * max(1.0, float(np.max(np.abs(P0)))) or da > 1e-6:
        notes.append(
            f"the first SET TWO position (the thesis's 'inferior' option) is not the seventh "
            f"joint's frame: it is {dp:.6g} {model.length_unit} and {math.degrees(da):.6g} deg "
            "away; kinestat guides the body located by those points, rigidly attached to link 6")
    else:
        notes.append("the first SET TWO position agrees with the seventh joint's frame")
    C = np.array(model.constants)
    C[-1] = C[-1] @ (inv(H7) @ Hg)
    return dataclasses.replace(model, constants=C), P0, notes


def deck_stages(deck: DispDeck, start_points) -> list[StageSpec]:
    """One stage per target position (MS 0, 4, 6) or command (MS 5), each a function of the
    hand pose at its start (:mod:`kinestat.serial.guidance.stages`)."""
    ms = deck.ms
    if ms == 5:
        return command_stages(deck.commands)
    kind = {0: "screw", 4: "line", 6: "general"}.get(ms)
    if kind is None:
        raise InputError(f"MS = {ms} is not a guidance analysis (0, 4, 5, 6)")
    # type II steps from the actual hand to the next screw position (App. I: DISP uses "the
    # actual position of the manipulator hand ... for any intermediate stage")
    return target_stages(kind, start_points, list(deck.positions[1:]), from_actual=ms == 0)


#: DISP's tables print joint values and hand points to 2-3 decimals, and Illustration 5's
#: summary says the computed final hand "coincide[s] with the desired final position ... with
#: three decimal accuracy": the final correction goes on until every hand point (origin, unit
#: +z and +x points) is within half the third decimal of the target's, in the deck's length
#: unit (and so the hand's orientation within 0.0005 rad).
PRINTED_PRECISION = 5e-4

#: The analyses whose run DISP ended on the target by a correction (Illustration 4, MS 0;
#: Illustration 5, MS 4, Table A2-9's last row).
CORRECTED_MS = (0, 4)

Correction = Literal["printed", "settle", "none"]

#: Half a unit of the last decimal DISP's cards give the hand in: SET TWO's points are F10.2
#: (0.005 in the deck's length unit), SET THREE's distances F10.3 (0.0005).
HAND_CARD_PRECISION = {"TWO": 0.005, "THREE": 0.0005}


def disp_cond_limit(deck: DispDeck) -> float:
    """DISP's singularity criterion for a guidance deck (an inferred, stated criterion: the
    thesis says only that [A] "does not have an inverse"): a configuration is singular when
    its dimensionless condition number κ exceeds L / p, with L the mechanism's characteristic
    length at the deck's initial configuration and p half a unit of the last decimal of the
    cards that give the hand (:data:`HAND_CARD_PRECISION`). Beyond it κ · p / L ≥ 1: the
    relative uncertainty the cards leave, amplified by κ, is as large as the step itself, so
    the cards no longer fix the joint increments. Other decks: the library's 1000.

    >>> from kinestat.io.disp_deck import embedded_deck
    >>> round(disp_cond_limit(embedded_deck("illustration4")))   # L = 19.59 in, p = 0.005 in
    3919
    """
    if deck.ms not in (0, 4, 5, 6):
        return DEFAULT_COND_LIMIT
    model, _, _ = deck_initial_hand(deck, deck_model(deck))
    p = HAND_CARD_PRECISION["THREE" if deck.ms == 5 else "TWO"]
    return characteristic_length(model, model.q_home) / p


def disp_options(*, settle: bool = False, closed_loop: bool = False,
                 second_order: bool = False, singular: SingularMode = "perturb_all",
                 cond_limit: float | None = None, disp_1977: bool = False,
                 correction: Correction | None = None, ms: int | None = None,
                 deck: DispDeck | None = None) -> GuidanceOptions:
    """Guidance options of DISP (Nadkarni 1977, ch. IV, App. I) by default: first-order
    steps (eq. 4-11), DISP's perturbation of every joint at a singularity (``perturb_all``)
    with the singularity criterion of ``deck`` (:func:`disp_cond_limit`; without a deck or
    with ``cond_limit`` given, that limit or 1000), a step of an automatically counted stage
    whose joint increments exceed the count's rotation bound done as sub-steps
    (``counted_substep_deg``), and, for the type II and III analyses (``ms`` 0 and 4),
    DISP's final correction: rows straight at each target until the hand is on it to the
    printed precision (``correction="printed"``, :data:`PRINTED_PRECISION`); ``"settle"`` (or
    ``settle=True``) corrects to 1e-9 (kinestat's), ``"none"`` not at all. kinestat's
    refinements are opt-in. ``disp_1977`` selects the inferred type III step rule of Table
    A2-9, which includes its final correction step.

    >>> o = disp_options()
    >>> o.step_rule, o.settle, o.closed_loop, o.singular, o.cond_limit
    ('first_order', False, False, 'perturb_all', 1000.0)
    >>> o = disp_options(ms=0)
    >>> o.settle, o.settle_tol, o.settle_length
    (True, 0.0005, 1.0)
    """
    if deck is not None and ms is None:
        ms = deck.ms
    if cond_limit is None:
        cond_limit = DEFAULT_COND_LIMIT if deck is None else disp_cond_limit(deck)
    if correction is None:
        correction = "settle" if settle else ("printed" if ms in CORRECTED_MS else "none")
    if correction not in ("printed", "settle", "none"):
        raise InputError(f"correction must be printed, settle or none, got {correction!r}")
    if disp_1977:
        return GuidanceOptions.disp_1977(closed_loop=closed_loop, second_order=second_order,
                                         singular=singular, cond_limit=cond_limit)
    extra: dict = {}
    if correction == "printed":
        extra = {"settle_tol": PRINTED_PRECISION, "settle_length": 1.0}
    return GuidanceOptions(step_rule="second_order" if second_order else "first_order",
                           closed_loop=closed_loop, singular=singular,
                           settle=correction != "none", cond_limit=cond_limit,
                           counted_substep_deg=DISP_STEP_DEG, **extra)


def run_deck(deck: DispDeck, *, steps: Sequence[int] | int | None = None,
             options: GuidanceOptions | None = None,
             progress: Callable[[int, int], None] | None = None,
             auto_steps: Literal["disp", "kinestat"] = "disp") -> DeckRun:
    """Run a deck for its MS as DISP does. ``steps`` overrides the deck's IT (0/None: IT, or
    automatic when IT = 0: DISP's inferred rule, :func:`~kinestat.disp.steps.disp_step_count`,
    or with ``auto_steps="kinestat"`` kinestat's own, as ``kinestat guide`` uses);
    ``options`` default to :func:`disp_options` (DISP's behaviour).
    The inferred 1977 step rule (``step_rule="disp_1977"``) belongs to the type III analysis
    (MS = 4) it was fitted to and is refused for other MS."""
    if not isinstance(deck, DispDeck):
        raise InputError(f"run_deck takes a DispDeck, got {type(deck).__name__}")
    options = disp_options(deck=deck) if options is None else options
    notes = list(deck_warnings(deck))
    ms = deck.ms
    if options.step_rule == "disp_1977" and ms != 4:
        raise InputError(
            f"the DISP 1977 step rule (--disp-1977) is inferred from Table A2-9, a type III "
            f"analysis (MS = 4); it does not apply to MS = {ms}")
    if ms in (1, 2, 3):
        screws = deck_screws(deck) if ms in (1, 3) else None
        joints = deck_joints(deck) if ms in (2, 3) else None
        return DeckRun(deck, screws=screws, joints=joints, notes=tuple(notes))
    model = deck_model(deck)
    model, P0, hand_notes = deck_initial_hand(deck, model)
    notes = [n for n in notes if not n.startswith("a7 =")] + hand_notes
    stages = deck_stages(deck, P0)
    if steps is None or steps == 0:
        steps = deck.it if deck.it > 0 else None
    step_count = None if auto_steps == "kinestat" else disp_step_count
    result = run_guidance(model, model.q_home, stages, steps=steps, options=options,
                          progress=progress, step_count=step_count)
    if not result.stopped and (not options.settle or options.settle_length is not None):
        dp, da = result.final_pose_error()
        if dp > 1e-9 * max(1.0, result.length) or da > 1e-9:
            what = ("after DISP's correction to the printed precision" if options.settle else
                    "after the last step (the first-order residual; --settle adds correction "
                    "steps)")
            notes.append(f"the hand ended {dp:.4g} {model.length_unit} and "
                         f"{math.degrees(da):.3g} deg from the target {what}")
    return DeckRun(deck, model=model, result=result, notes=tuple(notes) + result.notes)
