"""Plain records (the JSON contracts) of guidance runs and DISP deck runs."""

from __future__ import annotations

import math

from kinestat.disp.deck import TYPE_NAMES, DeckRun
from kinestat.disp.steps import total_steps
from kinestat.mechanism.nadkarni import hand_points
from kinestat.serial.guidance.run import GuidanceResult, joint_display

__all__ = ["result_record", "deck_json"]


def result_record(result: GuidanceResult, *, hand_points_every_row: bool = False) -> dict:
    """A plain record of a run (arrays stay numpy; ``to_jsonable`` them for JSON).

    Keys: ``columns``, ``units``, ``table`` (joint values per row, initial first, degrees for
    revolute joints), ``hand_origins``, ``final_hand_points`` (origin, unit point on +z, unit
    point on +x), ``target_hand_points``, ``events``, ``steps``, ``substeps``,
    ``total_steps`` (every solve, as Nadkarni's captions count them:
    :func:`~kinestat.disp.steps.total_steps`), ``final_pose_error`` and
    ``max_path_deviation`` (``position``, ``angle_deg``), ``stopped``,
    ``stop_reason`` (``stop_message``), ``stage_hand_origins`` (the hand origin at the end of
    each stage), ``length_scale`` and, when asked, ``hand_points`` of every row.
    """
    m = result.model
    rec: dict = {
        "columns": [(f"r{i + 1}" if m.prismatic[i] else f"theta{i + 1}") for i in range(m.n)],
        "units": [m.length_unit if p else "deg" for p in m.prismatic],
        "table": joint_display(m, result.q),
        "hand_origins": result.poses[:, :3, 3],
    }
    if hand_points_every_row:
        rec["hand_points"] = hand_points(result.poses)
    rec["final_hand_points"] = hand_points(result.final_pose)
    rec["target_hand_points"] = [hand_points(T) for T in result.stage_targets]
    rec["stage_hand_origins"] = [result.poses[i, :3, 3] for i in result.stage_end_rows()]
    rec["events"] = [e.as_dict() for e in result.events]
    rec["steps"] = list(result.steps)
    rec["substeps"] = result.substeps
    rec["total_steps"] = total_steps(result)
    dp, da = result.final_pose_error()
    rec["final_pose_error"] = {"position": dp, "angle_deg": math.degrees(da)}
    mp, ma = result.max_path_deviation()
    rec["max_path_deviation"] = {"position": mp, "angle_deg": math.degrees(ma)}
    rec["stopped"] = result.stopped
    rec["stop_reason"] = result.stop_kind
    if result.stop_message:
        rec["stop_message"] = result.stop_message
    rec["length_scale"] = result.length
    return rec


def deck_json(run: DeckRun) -> dict:
    """The machine-readable record of a deck run (the ``kinestat disp --json`` contract).

    MS 1: ``screws``; MS 2: ``joints``; MS 3: both; MS 0/4/5/6: the keys of
    :func:`result_record` (``table``, ``final_hand_points``, ``events``, ...; ``hand_points``
    of every row when IO = 0), with ``stage_hand_origins`` (the hand origin at the end of each
    command) for MS = 5. Always ``ms``, ``analysis``, ``source`` and ``notes``.
    """
    deck = run.deck
    out: dict = {"ms": deck.ms, "analysis": deck.analysis, "source": deck.source}
    if run.screws is not None:
        out["screws"] = run.screws
    if run.joints is not None:
        out["joints"] = run.joints
    if run.result is not None:
        out["type"] = TYPE_NAMES[deck.ms]
        rec = result_record(run.result, hand_points_every_row=deck.io == 0)
        if deck.ms != 5:
            rec.pop("stage_hand_origins")
        out.update(rec)
    out["notes"] = list(run.notes)
    return out
