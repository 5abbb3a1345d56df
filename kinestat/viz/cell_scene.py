"""The kinestatic cell replayed from a control run's cycle log (``kinestat control --log``).

Per cycle (one scene step): the PUMA 762 (or the run's ``--arm``, from the chain its log header
records) at its measured joints, the compliant platform mounted
on the flange (base = ``F_6T · 6_BT``, top = base · measured top pose), the tool from the top to
its measured tip, the workpiece plane of a simulated run, and the measured and true force arrows.
The state a–e and the controller's decision are the step's label.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import kinestat
from kinestat.control.log import read_log
from kinestat.errors import InputError
from kinestat.io.library import prototype
from kinestat.mechanism.chain import ChainModel
from kinestat.mechanism.joints import Joint
from kinestat.viz.scene import (
    _base,
    _configuration,
    _pt,
    chain_frames,
    force_color,
    robot_record,
    run_length,
)

__all__ = ["read_cycle_log", "cell_scene", "force_series", "run_arm"]


def force_series(cycles: list[dict], target: float, unit: str) -> dict:
    """The measured force per cycle for the page's plot (the Fig. 5-2 panels): ``cycle``,
    ``force`` (x, y, z per cycle, the estimate the controller acted on), ``magnitude``,
    ``target`` and ``unit``."""
    F = [[float(x) for x in (c["measured"].get("estimate") or c["measured"]["force"])]
         for c in cycles]
    return {"cycle": [int(c.get("cycle", k + 1)) for k, c in enumerate(cycles)], "force": F,
            "magnitude": [float(np.linalg.norm(f)) for f in F], "target": float(target),
            "unit": unit}

_CYCLE_KEYS = ("joints_deg", "top_pose", "tip", "force", "leg_lengths")


def read_cycle_log(path) -> tuple[dict, list[dict], dict | None]:
    """The ``start`` record, the ``cycle`` records and the ``end`` record (or None) of a log
    (``path``: the ``log.jsonl`` file, or the run's folder that holds it).

    Raises:
        InputError: the file is missing, not JSON lines, or not a cycle log of this version.
    """
    p = Path(path)
    if p.is_dir():  # a run's folder (kinestat-runs/<time>/): its log
        if not (p / "log.jsonl").is_file():
            raise InputError(f"cycle log {str(p)!r} is a directory without a log.jsonl")
        p = p / "log.jsonl"
    if not p.is_file():
        raise InputError(f"cycle log {str(p)!r} not found")
    records = read_log(p)
    if not records or records[0].get("type") != "start" or "config" not in records[0]:
        raise InputError(f"{p}: not a kinestat control cycle log of this version (the first "
                         "record must be a 'start' record with 'config')")
    cycles = [r for r in records if r.get("type") == "cycle"]
    if not cycles:
        raise InputError(f"{p}: the cycle log holds no 'cycle' record to replay")
    for r in cycles:
        meas = r.get("measured")
        missing = [k for k in _CYCLE_KEYS if not isinstance(meas, dict) or k not in meas]
        if missing:
            raise InputError(f"{p}: cycle {r.get('cycle')} lacks measured {', '.join(missing)}: "
                             "not a kinestat control cycle log of this version")
    end = next((r for r in records if r.get("type") == "end"), None)
    return records[0], cycles, end


def _workpiece(start: dict, scale: float) -> list[dict]:
    c, n = start.get("plane_point"), start.get("plane_normal")
    if c is None or n is None:
        return []
    c, n = np.asarray(c, dtype=float), np.asarray(n, dtype=float)
    n = n / np.linalg.norm(n)
    a = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    h = 0.6 * scale
    corners = [c + h * (sa * a + sb * b) for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return [{"type": "polygon", "points": [_pt(x) for x in corners], "color": "#8c564b",
             "opacity": 0.45, "label": "workpiece plane (simulated)"}]


def _cycle_items(platform, mount, F6, meas: dict, true: dict | None,
                 force_scale: float) -> list[dict]:
    base = F6 @ mount
    top = base @ np.asarray(meas["top_pose"], dtype=float)
    L = np.asarray(meas["leg_lengths"], dtype=float)
    forces = platform.stiffness * (L - platform.free_lengths)
    Bw = (base[:3, :3] @ np.asarray(platform.base_points, dtype=float).T).T + base[:3, 3]
    Pw = (top[:3, :3] @ np.asarray(platform.top_points, dtype=float).T).T + top[:3, 3]
    fmax = float(np.max(np.abs(forces))) or 1.0
    items = [
        {"type": "polygon", "points": [_pt(x) for x in Bw], "color": "#8c8c8c",
         "opacity": 0.55, "label": "platform base plate"},
        {"type": "polygon", "points": [_pt(x) for x in Pw], "color": "#c7a34a",
         "opacity": 0.75, "label": "platform top plate"},
    ]
    for name, b, p, f in zip(platform.leg_names, Bw, Pw, forces, strict=True):
        items.append({"type": "segment", "a": _pt(b), "b": _pt(p), "radius": platform.scale * 0.03,
                      "color": force_color(float(f), fmax),
                      "label": f"leg {name}: {float(f):+.3g} {platform.force_unit}",
                      "group": "platform legs"})
    tip = np.asarray(meas["tip"], dtype=float)
    items.append({"type": "segment", "a": _pt(top[:3, 3]), "b": _pt(tip),
                  "radius": platform.scale * 0.05, "color": "#444444", "label": "tool"})
    F = np.asarray(meas.get("estimate") or meas["force"], dtype=float)
    items.append({"type": "arrow", "origin": _pt(tip), "vector": _pt(F * force_scale),
                  "color": "#d62728",
                  "label": f"measured force {np.linalg.norm(F):.3g} {platform.force_unit}"})
    if true and true.get("tool_force") is not None:
        Ft = np.asarray(true["tool_force"], dtype=float)
        items.append({"type": "arrow", "origin": _pt(tip), "vector": _pt(Ft * force_scale),
                      "color": "#2ca02c",
                      "label": f"true force {np.linalg.norm(Ft):.3g} {platform.force_unit}"})
    return items


def _logged_arm(arm: dict) -> ChainModel:
    """The ``--arm`` of a run as its log header records it (placed chain, mm, limits)."""
    try:
        lim = np.radians(np.asarray(arm["limits_deg"], dtype=float))
        joints = tuple(Joint(name=str(n), lower=float(lo), upper=float(hi))
                       for n, (lo, hi) in zip(arm["joints"], lim, strict=True))
        return ChainModel(name=str(arm["name"]), joints=joints,
                          constants=np.asarray(arm["constants"], dtype=float), length_unit="mm")
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"the log's arm record is incomplete ({exc}): it cannot be drawn"
                         ) from exc


def run_arm(start: dict) -> ChainModel:
    """The arm of a run: the PUMA 762, or the ``--arm`` its log header records."""
    return kinestat.load("puma762") if "arm" not in start else _logged_arm(start["arm"])


def cell_scene(start: dict, cycles: list[dict], end: dict | None = None, *, platform=None,
               title: str = "kinestatic control run", model: ChainModel | None = None) -> dict:
    """The scene of a control run: one step per cycle record (see the module docstring);
    ``model`` is the run's arm when already loaded (:func:`run_arm`)."""
    platform = prototype() if platform is None else platform
    model = run_arm(start) if model is None else model
    cfg = start["config"]
    mount = np.asarray(cfg.get("mount", np.eye(4)), dtype=float)
    Q = np.radians(np.array([c["measured"]["joints_deg"] for c in cycles], dtype=float))
    Fall = kinestat.fk(model, Q)
    scale = 1000.0 if model.length_unit == "mm" else 1.0
    target = float(cfg.get("force_target") or 1.0)
    force_scale = 0.08 * scale / max(target, 1e-9)
    s = _base("log", title, model.length_unit, scale)
    s["robot"] = robot_record(model, Q[0], live=False)
    _configuration(s, model, Q[0])
    s["frames"] = chain_frames(model, Q[0])
    s["items"] = _workpiece(start, 0.1 * scale)
    s["items"].append({"type": "polyline", "points": [_pt(c["measured"]["tip"]) for c in cycles],
                       "color": "#ff7f0e", "label": "tool tip path"})
    states = cfg.get("states", {})
    steps = []
    for k, c in enumerate(cycles):
        meas = c["measured"]
        st = c.get("state", "?")
        fr = chain_frames(model, Q[k])
        label = (f"cycle {c.get('cycle', k + 1)}: state {st}, {c.get('decision', '')}"
                 f" {c.get('action', '')}").rstrip()
        info = [f"state {st}: {states.get(st, '')}",
                f"|F| measured {float(meas.get('force_magnitude', math.nan)):.4g}, target "
                f"{target:.4g}"]
        if c.get("reason"):
            info.append(f"reason: {c['reason']}")
        steps.append({"label": label, "state": st, "q": [float(x) for x in Q[k]],
                      "frames": fr, "info": info,
                      "items": _cycle_items(platform, mount, Fall[k], meas, c.get("true"),
                                            force_scale)})
    s["steps"] = steps
    # the view opens on the whole cell; "frame tool" looks at the wrist, platform and tool
    s["tool_focus"] = {"point": _pt(cycles[0]["measured"]["tip"]), "radius": 0.35 * scale}
    s["series"] = force_series(cycles, target, platform.force_unit)
    s["info"] = [f"{len(cycles)} cycles, states "
                 f"{run_length(c.get('state', '?') for c in cycles)}"]
    if end is not None and isinstance(end.get("report"), dict):
        rep = end["report"]
        s["info"].append(f"converged: {rep.get('converged')}, stop: {rep.get('stop_reason')}")
    return s
