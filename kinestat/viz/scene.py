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
- ``q`` (the configuration shown first, radians for rotating joints, the length unit for
  prismatic ones), ``limits`` (``[lower, upper]`` per joint, same units, ``null`` where
  unbounded) and ``q_units`` when the scene has a robot;
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
    "opening_q",
    "check_within_limits",
    "platform_scene",
    "screw_scene",
    "guidance_scene",
    "force_color",
    "wrench_axis",
    "run_length",
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


def _limit(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _configuration(s: dict, model: ChainModel, q) -> None:
    """The scene's ``q``, ``limits`` and ``q_units`` keys (docs/viewer.md)."""
    s["q"] = [float(x) for x in q]
    s["limits"] = [[_limit(lo), _limit(hi)] for lo, hi in zip(model.lower, model.upper,
                                                               strict=True)]
    s["q_units"] = [model.length_unit if p else "rad" for p in model.prismatic]


def opening_q(model: ChainModel) -> np.ndarray:
    """The configuration a model opens at: its home when within the joint limits, else the
    point within the limits nearest to zero (each joint clipped into its interval).

    >>> import kinestat
    >>> [round(float(x), 4) for x in np.degrees(opening_q(kinestat.load("puma762")))][:2]
    [20.0, 0.0]
    """
    home = np.asarray(model.q_home, dtype=float)
    if bool(model.within_limits(home)):
        return home
    return np.clip(np.zeros(model.n), model.lower, model.upper)


def check_within_limits(model: ChainModel, q, what: str = "q") -> np.ndarray:
    """``q`` when every joint is within its limits; else an InputError naming the joint."""
    q = model.check_q(q)
    for i, (x, lo, hi) in enumerate(zip(q, model.lower, model.upper, strict=True)):
        if not lo <= x <= hi:
            k = 1.0 if model.prismatic[i] else 180.0 / math.pi
            u = model.length_unit if model.prismatic[i] else "deg"
            name = model.joints[i].name
            named = "" if name in ("", str(i + 1)) else f" ({name})"
            raise InputError(f"{what}: joint {i + 1}{named} = {x * k:.6g} "
                             f"{u} is outside its limits [{lo * k:.6g}, {hi * k:.6g}] {u}")
    return q


def _base(kind: str, title: str, unit: str, scale: float) -> dict:
    return {"schema": SCHEMA, "kind": kind, "title": title, "length_unit": unit,
            "scale": float(scale), "info": [], "frames": [], "robot": None, "items": [],
            "steps": []}


def model_scene(model: ChainModel, q=None, *, show_frames: bool = False,
                meshes: tuple[list[dict], list[str]] | None = None) -> dict:
    """A serial model at ``q`` (default :func:`opening_q`; a given ``q`` must lie within the
    joint limits, as the sliders do) with live joint sliders."""
    q = opening_q(model) if q is None else check_within_limits(model, q)
    scale = _span(model, q)
    s = _base("model", f"{model.name} ({model.n} joints)", model.length_unit, scale)
    s["frames"] = chain_frames(model, q)
    s["robot"] = robot_record(model, q, live=True)
    _configuration(s, model, q)
    s["show_frames"] = bool(show_frames)
    if meshes is not None:  # a URDF's visual meshes (kinestat.viz.meshes.urdf_meshes)
        s["meshes"], s["mesh_messages"] = list(meshes[0]), list(meshes[1])
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


def run_length(states) -> str:
    """A sequence of states in run-length form, runs joined by arrows.

    >>> run_length("aaab" + "p" * 3 + "tt")
    'a×3 → b → p×3 → t×2'
    """
    runs: list[list] = []
    for x in states:
        if runs and runs[-1][0] == x:
            runs[-1][1] += 1
        else:
            runs.append([x, 1])
    return " → ".join(f"{x}×{n}" if n > 1 else f"{x}" for x, n in runs)


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
    """Every assembly mode (``poses``) in the platform's base frame, one at a time in the page
    (``modes``: the physical one first, the others ghosted on demand); ``physical`` marks the
    assembled one. Every item carries its ``mode`` (0-based index into ``poses``) and its
    legend ``group``.

    Leg forces are the springs' tensions at each pose (Vibhute eq. 2-9), or those balancing
    ``wrench`` (eq. 2-8) when given; the wrench drawn is ``j f`` (eqs. 2-3 to 2-5).
    """
    poses = [np.asarray(T, dtype=float) for T in poses]
    if not poses:
        raise InputError("no platform pose to show")
    physical = physical if 0 <= physical < len(poses) else 0
    s = _base("platform", f"{platform.name}: {len(poses)} assembly mode(s)",
              platform.length_unit, platform.scale)
    s["force_unit"] = platform.force_unit
    items, frames = [], []
    order = [physical] + [k for k in range(len(poses)) if k != physical]
    s["modes"] = [{"index": k, "label": f"mode {k + 1}" + (" (physical)" if k == physical
                                                            else "")} for k in order]
    zero = np.zeros(3)
    for k, T in enumerate(poses):
        tag = f"mode {k + 1}" + (" (physical)" if k == physical else "")
        f = (spring_forces(platform, leg_lengths(platform, T)) if wrench is None
             else forces_from_wrench(platform, T, wrench))
        w = wrench_from_forces(platform, T, f)
        fmax = float(np.max(np.abs(w[:3]))) or 1.0
        mine = _platform_items(platform, T, zero, f, "")
        mine += _wrench_items(platform, T, zero, w, "", platform.scale / fmax)
        mine.append({"type": "frame", "pose": _pose(T), "size": platform.scale * 0.3})
        for it in mine:
            it["mode"], it["group"] = k, tag
            if "label" in it:
                it["label"] = it["label"].strip()
        items += mine
        frames.append({"name": f"top{k + 1}", "pose": _pose(T)})
        s["info"].append(f"{tag}: z = {T[2, 3]:.4g} {platform.length_unit}, leg forces "
                         + ", ".join(f"{x:+.3g}" for x in f))
    frames.insert(0, {"name": "base", "pose": _pose(np.eye(4))})
    frames.append({"name": "end", "pose": _pose(poses[physical])})
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
    _configuration(s, m, Q[0])
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
