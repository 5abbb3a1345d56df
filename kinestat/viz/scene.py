"""Viewer scenes as plain data: pure functions ``(model, configuration) -> dict``.

A scene is the JSON document the 3D viewer (:mod:`kinestat.viz.html`) draws; it is documented in
docs/viewer.md. Every pose is a 4x4 row-major nested list in the model's length unit, every
point a 3-list. The keys:

- ``schema`` (``"kinestat-scene/1"``), ``kind`` (``model``, ``platform``, ``screw``, ``disp``,
  ``log``), ``title``, ``length_unit``, ``scale`` (a characteristic length for sizing marks),
  ``info`` (lines of text shown beside the view);
- ``frames``: ``[{"name", "pose"}]`` of the configuration shown first; for a chain every joint
  frame ``joint1 … jointn`` (``F_{i-1}``, whose z axis is joint i's axis) and the end frame
  ``end`` (``kinestat.fk``);
- ``robot``: ``null`` or the chain for forward kinematics in the page: ``constants`` C0..Cn,
  ``kinds``, ``pitches``, ``lower``/``upper`` (radians or length), ``q`` (shown first) and
  ``live`` (sliders shown);
- ``items``: static drawables (below); ``steps``: ``[{"label", "q", "frames", "items",
  "info"}]`` for animations, per step the same frames plus items drawn at that step only;
- optional: ``show_frames`` (joint frames drawn at first), ``focus`` (``{"point", "radius"}``,
  where the camera looks first), ``force_unit``, ``ik_url`` (served pages).

Drawables (``type``): ``segment`` (``a``, ``b``, ``radius``), ``polyline`` (``points``),
``polygon`` (``points``, ``opacity``), ``arrow`` (``origin``, ``vector``), ``line`` (an axis
through ``point`` along unit ``direction``, drawn ``length`` long, dashed), ``marker`` (``at``,
``radius``), ``frame`` (``pose``, ``size``); all take ``color`` (``#rrggbb``) and an optional
``label`` listed in the legend.
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel
from kinestat.parallel.legs import leg_lengths, top_points_in_base
from kinestat.parallel.statics import forces_from_wrench, spring_forces, wrench_from_forces
from kinestat.serial.fk import fk, fk_frames
from kinestat.spatial.displacement import interpolate_screw, screw_from_poses

__all__ = [
    "SCHEMA",
    "chain_frames",
    "robot_record",
    "model_scene",
    "platform_scene",
    "screw_scene",
    "guidance_scene",
    "force_color",
    "wrench_axis",
]

SCHEMA = "kinestat-scene/1"
TENSION = "#d62728"
COMPRESSION = "#1f77b4"
NEUTRAL = "#7f7f7f"


def _pose(T) -> list[list[float]]:
    return np.asarray(T, dtype=float).tolist()


def _pt(p) -> list[float]:
    return [float(x) for x in np.asarray(p, dtype=float).ravel()[:3]]


def chain_frames(model: ChainModel, q) -> list[dict]:
    """Joint frames ``joint1..jointn`` (``F_{i-1}``) and ``end`` (``kinestat.fk``) at ``q``.

    >>> import kinestat
    >>> m = kinestat.load("puma762")
    >>> [f["name"] for f in chain_frames(m, m.q_home)][-2:]
    ['joint6', 'end']
    """
    q = model.check_q(q)
    F = fk_frames(model, q)
    frames = [{"name": f"joint{i + 1}", "pose": _pose(F[i])} for i in range(model.n)]
    frames.append({"name": "end", "pose": _pose(fk(model, q))})
    return frames


def _span(model: ChainModel, q) -> float:
    P = fk_frames(model, q)[:, :3, 3]
    ext = float(np.max(np.ptp(P, axis=0))) if len(P) > 1 else 0.0
    return ext if ext > 0 else 1.0


def robot_record(model: ChainModel, q, *, live: bool = False) -> dict:
    """The chain as the page's forward kinematics needs it: ``C0..Cn`` and the joint kinds."""
    q = model.check_q(q)
    return {
        "name": model.name,
        "constants": [_pose(C) for C in model.constants],
        "kinds": [j.kind for j in model.joints],
        "pitches": [float(x) for x in model.pitches],
        "lower": [float(x) if math.isfinite(x) else None for x in model.lower],
        "upper": [float(x) if math.isfinite(x) else None for x in model.upper],
        "joint_names": [j.name for j in model.joints],
        "q": [float(x) for x in q],
        "live": live,
    }


def _base(kind: str, title: str, unit: str, scale: float) -> dict:
    return {"schema": SCHEMA, "kind": kind, "title": title, "length_unit": unit,
            "scale": float(scale), "info": [], "frames": [], "robot": None, "items": [],
            "steps": []}


def model_scene(model: ChainModel, q=None, *, show_frames: bool = False) -> dict:
    """A serial model at ``q`` (default ``q_home``) with live joint sliders."""
    q = model.q_home if q is None else model.check_q(q)
    scale = _span(model, q)
    s = _base("model", f"{model.name} ({model.n} joints)", model.length_unit, scale)
    s["frames"] = chain_frames(model, q)
    s["robot"] = robot_record(model, q, live=True)
    s["show_frames"] = bool(show_frames)
    s["info"] = [f"notation {model.notation}, lengths in {model.length_unit}",
                 "joints: " + ", ".join(f"{j.name} {j.kind}" for j in model.joints)]
    return s


# -- the platform -----------------------------------------------------------------------------
def _unloaded(f: float, fmax: float) -> bool:
    return fmax <= 0 or abs(f) <= 1e-9 * fmax


def force_color(f: float, fmax: float) -> str:
    """Leg colour: red for tension (f > 0), blue for compression, grey when unloaded."""
    if _unloaded(f, fmax):
        return NEUTRAL
    t = min(abs(f) / fmax, 1.0)
    base = (214, 39, 40) if f > 0 else (31, 119, 180)
    rgb = [round(127 + (c - 127) * (0.35 + 0.65 * t)) for c in base]
    return "#" + "".join(f"{c:02x}" for c in rgb)


def wrench_axis(w) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The line of a wrench ``[f; m_O]``: unit direction, the point nearest O, the pitch.

    ``r = f × m_O / |f|²`` (Plücker: the point of the axis nearest the origin), ``h = f·m/|f|²``.
    None for a pure couple or no wrench.

    >>> u, r, h = wrench_axis([0, 0, 2, 2, 0, 0])
    >>> [round(float(x), 6) for x in r]
    [0.0, 1.0, 0.0]
    """
    w = np.asarray(w, dtype=float)
    f, m = w[:3], w[3:]
    ff = float(f @ f)
    if ff <= 1e-24:
        return None
    return f / math.sqrt(ff), np.cross(f, m) / ff, float(f @ m) / ff


def _platform_items(platform, T, offset: np.ndarray, forces, tag: str) -> list[dict]:
    B = np.asarray(platform.base_points, dtype=float) + offset
    P = top_points_in_base(platform, T) + offset
    fmax = float(np.max(np.abs(forces))) if len(forces) else 0.0
    r = platform.scale * 0.025
    items: list[dict] = [
        {"type": "polygon", "points": [_pt(b) for b in B], "color": "#8c8c8c",
         "opacity": 0.55, "label": f"{tag} base plate"},
        {"type": "polygon", "points": [_pt(p) for p in P], "color": "#c7a34a",
         "opacity": 0.75, "label": f"{tag} top plate"},
    ]
    for name, b, p, f in zip(platform.leg_names, B, P, forces, strict=True):
        kind = "unloaded" if _unloaded(f, fmax) else ("tension" if f > 0 else "compression")
        items.append({"type": "segment", "a": _pt(b), "b": _pt(p), "radius": r,
                      "color": force_color(float(f), fmax),
                      "label": f"{tag} leg {name}: {float(f):+.4g} ({kind})"})
    return items


def _wrench_items(platform, T, offset, w, tag: str, force_scale: float) -> list[dict]:
    ax = wrench_axis(w)
    if ax is None:
        return []
    u, r0, h = ax
    centre = (T[:3, 3] + np.mean(platform.base_points, axis=0)) / 2.0
    foot = r0 + u * float(u @ (centre - r0))  # the axis point nearest the platform
    f = np.asarray(w[:3], dtype=float)
    return [
        {"type": "line", "point": _pt(foot + offset), "direction": _pt(u),
         "length": 3.0 * platform.scale, "color": "#2ca02c",
         "label": f"{tag} wrench axis (pitch {h:.4g} {platform.length_unit})"},
        {"type": "arrow", "origin": _pt(foot + offset), "vector": _pt(f * force_scale),
         "color": "#2ca02c", "label": f"{tag} force |f| = {float(np.linalg.norm(f)):.4g} "
                                       f"{platform.force_unit}"},
    ]


def platform_scene(platform, poses, *, legs=None, physical: int = 0,
                   wrench=None) -> dict:
    """Every assembly mode (``poses``) side by side; ``physical`` marks the assembled one.

    Leg forces are the springs' tensions at each pose (Vibhute eq. 2-9), or those balancing
    ``wrench`` (eq. 2-8) when given; the wrench drawn is ``j f`` (eqs. 2-3 to 2-5).
    """
    poses = [np.asarray(T, dtype=float) for T in poses]
    if not poses:
        raise InputError("no platform pose to show")
    gap = 3.0 * platform.scale
    s = _base("platform", f"{platform.name}: {len(poses)} assembly mode(s)",
              platform.length_unit, platform.scale)
    s["force_unit"] = platform.force_unit
    items, frames = [], []
    for k, T in enumerate(poses):
        off = np.array([k * gap, 0.0, 0.0])
        tag = f"mode {k + 1}" + (" (physical)" if k == physical else "")
        f = (spring_forces(platform, leg_lengths(platform, T)) if wrench is None
             else forces_from_wrench(platform, T, wrench))
        w = wrench_from_forces(platform, T, f)
        fmax = float(np.max(np.abs(w[:3]))) or 1.0
        items += _platform_items(platform, T, off, f, tag)
        items += _wrench_items(platform, T, off, w, tag, platform.scale / fmax)
        Tw = T.copy()
        Tw[:3, 3] += off
        items.append({"type": "frame", "pose": _pose(Tw), "size": platform.scale * 0.3})
        if k == physical:
            items.append({"type": "marker", "at": _pt(off + [0, 0, -0.15 * platform.scale]),
                          "radius": platform.scale * 0.12, "color": "#ff7f0e",
                          "label": f"mode {k + 1} is the physical assembly"})
        base = np.eye(4)
        base[:3, 3] = off
        frames += [{"name": f"base{k + 1}", "pose": _pose(base)},
                   {"name": f"top{k + 1}", "pose": _pose(Tw)}]
        s["info"].append(f"{tag}: z = {T[2, 3]:.4g} {platform.length_unit}, leg forces "
                         + ", ".join(f"{x:+.3g}" for x in f))
    Tp = poses[physical].copy()
    Tp[:3, 3] += [physical * gap, 0.0, 0.0]
    frames.append({"name": "end", "pose": _pose(Tp)})
    s["frames"], s["items"] = frames, items
    if legs is not None:
        s["info"].insert(0, "leg lengths " + ", ".join(f"{x:.4g}" for x in legs))
    return s


# -- screws -----------------------------------------------------------------------------------
def screw_scene(T1, T2, *, points1=None, points2=None, n_path: int = 48) -> dict:
    """Two positions of a body, the screw axis of the displacement (Nadkarni ch. III), and the
    helical path of the body origin: rotation ``theta`` about and translation ``d`` along it."""
    T1, T2 = np.asarray(T1, dtype=float), np.asarray(T2, dtype=float)
    sc = screw_from_poses(T1, T2)
    span = float(np.linalg.norm(T2[:3, 3] - T1[:3, 3]))
    scale = max(span, float(np.linalg.norm(T1[:3, 3])), float(np.linalg.norm(T2[:3, 3])), 1.0)
    s = _base("screw", "screw displacement between two positions", "", scale)
    u, p = np.asarray(sc.axis, dtype=float), np.asarray(sc.point, dtype=float)
    mid = (T1[:3, 3] + T2[:3, 3]) / 2.0
    foot = p + u * float(u @ (mid - p))
    path = [interpolate_screw(T1, T2, t)[:3, 3] for t in np.linspace(0.0, 1.0, n_path)]
    s["frames"] = [{"name": "position1", "pose": _pose(T1)}, {"name": "end", "pose": _pose(T2)}]
    size = 0.25 * scale
    items = [
        {"type": "frame", "pose": _pose(T1), "size": size, "label": "position 1"},
        {"type": "frame", "pose": _pose(T2), "size": size, "label": "position 2"},
        {"type": "line", "point": _pt(foot), "direction": _pt(u), "length": 3.0 * scale,
         "color": "#9467bd", "label": "screw axis"},
        {"type": "polyline", "points": [_pt(x) for x in path], "color": "#ff7f0e",
         "label": "path of the body origin (rotation + translation along the axis)"},
        {"type": "arrow", "origin": _pt(foot), "vector": _pt(u * float(sc.d)),
         "color": "#17becf", "label": f"translation d = {float(sc.d):.6g}"},
    ]
    for k, pts in ((1, points1), (2, points2)):
        if pts is not None:
            P = np.asarray(pts, dtype=float).reshape(3, 3)
            items.append({"type": "polygon", "points": [_pt(x) for x in P],
                          "color": "#bcbd22" if k == 1 else "#e377c2", "opacity": 0.6,
                          "label": f"body points, position {k}"})
    s["items"] = items
    pitch = "inf" if bool(sc.is_translation) else f"{float(sc.pitch):.6g}"
    s["info"] = [f"axis u = ({', '.join(f'{x:.4f}' for x in u)})",
                 f"point (foot from origin) = ({', '.join(f'{x:.4g}' for x in p)})",
                 f"rotation {float(sc.angle_deg):.4f} deg, translation {float(sc.d):.6g}, "
                 f"pitch {pitch}"]
    return s


# -- guidance runs ----------------------------------------------------------------------------
def guidance_scene(result, *, title: str = "guidance run") -> dict:
    """A guidance run (DISP deck or ``kinestat guide``) as an animation: one step per row of
    ``result.q``, the hand path, the ideal path, and every singular or limit event marked."""
    m = result.model
    Q = np.asarray(result.q, dtype=float)
    if Q.ndim != 2 or Q.shape[0] == 0:
        raise InputError("the guidance run has no configurations to show")
    F = fk_frames(m, Q)
    E = fk(m, Q)
    scale = max(_span(m, Q[0]), float(np.max(np.ptp(E[:, :3, 3], axis=0))))
    s = _base("disp", title, m.length_unit, scale)
    s["robot"] = robot_record(m, Q[0], live=False)
    s["frames"] = chain_frames(m, Q[0])
    names = [f"joint{i + 1}" for i in range(m.n)] + ["end"]
    stage = np.asarray(result.stage)
    steps = []
    for r in range(Q.shape[0]):
        fr = [{"name": names[i], "pose": _pose(F[r, i])} for i in range(m.n)]
        fr.append({"name": "end", "pose": _pose(E[r])})
        st = int(stage[r]) if r < len(stage) else 0
        steps.append({"label": f"step {r}" + (f" (stage {st})" if st > 0 else ""),
                      "q": [float(x) for x in Q[r]], "frames": fr, "items": []})
    colors = {"singular": "#d62728", "joint_limit": "#ff7f0e", "least_squares": "#9467bd"}
    for ev in result.events:
        r = int(ev.get("step", 0))
        if ev["kind"] in colors and 0 <= r < len(steps):
            at = E[min(r, len(E) - 1), :3, 3]
            steps[r]["items"].append({"type": "marker", "at": _pt(at), "radius": 0.03 * scale,
                                      "color": colors[ev["kind"]], "label": ev["kind"]})
    s["steps"] = steps
    s["items"] = [
        {"type": "polyline", "points": [_pt(T[:3, 3]) for T in E], "color": "#ff7f0e",
         "label": "hand path"},
        {"type": "polyline", "points": [_pt(T[:3, 3]) for T in np.asarray(result.ideal)],
         "color": "#2ca02c", "label": "ideal path"},
    ]
    for ev in result.events:
        r = int(ev.get("step", 0))
        if ev["kind"] in colors:
            s["items"].append({"type": "marker", "at": _pt(E[min(r, len(E) - 1), :3, 3]),
                               "radius": 0.02 * scale, "color": colors[ev["kind"]],
                               "label": f"{ev['kind']} at step {r}"})
    s["info"] = [f"{m.name}: {Q.shape[0]} configurations, stages "
                 + ", ".join(str(k) for k in result.steps),
                 f"events: {len(result.events)}"
                 + (f"; STOPPED: {result.stop_message}" if result.stopped else "")]
    return s
