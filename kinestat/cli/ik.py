"""``kinestat ik``: inverse kinematics — the PUMA 762 in closed form, any model numerically."""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np
import typer

from kinestat.cli._compile import compiling_notice
from kinestat.cli._model import (
    base_option,
    length_unit_option,
    load_model,
    scale_option,
    tip_option,
)
from kinestat.cli._options import (
    POSE_FILE_METAVAR,
    Q_METAVAR,
    XYZ_METAVAR,
    check_seed,
    command_help,
    flag,
    json_option,
    name_value,
    units,
)
from kinestat.cli._output import console, literal, parse_floats, parse_pose, print_json, table
from kinestat.errors import InputError, KinestatError

#: ``--limits``: the PUMA 762 axis-limit sets (puma_rev_analysis.m, or Table 2-1)
AxisLimitSet = Literal["matlab", "table"]


def register(app: typer.Typer) -> None:
    app.command("ik", help=command_help(ik_command))(ik_command)


def _read_poses(text: str) -> np.ndarray:
    """``--pose``: 16 comma-separated numbers (row-major 4x4) or a pose file (JSON — a 4x4
    matrix, 16 numbers, a list of 4x4 matrices, or an object with a "pose" key as written by
    ``kinestat fk --json`` — TOML, or plain numbers)."""
    return parse_pose(text, "pose", allow_batch=True)


def _deg(x) -> list[float]:
    return [float(v) for v in np.degrees(np.asarray(x, dtype=float))]


def ik_command(
    model: str = typer.Argument(
        ..., parser=name_value,
        help="puma762 (closed form with --tool-point/--s6/--a67) or any model name, TOML "
        "or URDF file (numerical, or every analytic solution with --all, with --pose)."
    ),
    tool_point: str = typer.Option(
        None, "--tool-point", help="PUMA 762: P_tool_F, the tool point in the fixed frame, x,y,z "
        "(mm).", metavar=XYZ_METAVAR
    ),
    s6: str = typer.Option(
        None, "--s6", help="PUMA 762: S6_F, the sixth joint axis (unit), x,y,z.",
        metavar=XYZ_METAVAR
    ),
    a67: str = typer.Option(None, "--a67", help="PUMA 762: a67_F (unit, perpendicular to S6_F).",
                            metavar=XYZ_METAVAR),
    tool_point_6: str = typer.Option(
        "0,0,0", "--tool-point-6", metavar=XYZ_METAVAR,
        help="PUMA 762: P_tool_6, the tool point in frame 6, x,y,z (mm)."
    ),
    current_deg: str = typer.Option(
        None, "--current-deg", help="PUMA 762: current joint angles φ1,θ2..θ6 (degrees); selects "
        "the nearest solution within the axis limits.", metavar=Q_METAVAR
    ),
    current_axis_deg: str = typer.Option(
        None, "--current-axis-deg", help="PUMA 762: the current configuration as robot axis "
        "angles (degrees; axis 1 = φ1 + 180).", metavar=Q_METAVAR
    ),
    limits: str = typer.Option(  # an AxisLimitSet
        "matlab", "--limits", help="PUMA 762 axis limits: 'matlab' (puma_rev_analysis.m, joint 5 "
        "±100°) or 'table' (Table 2-1, joint 5 ±110°)."
    ),
    normalize: bool = flag(
        False, "--normalize", help="PUMA 762: unitise S6_F and a67_F first (as Crane's program "
        "does); they must still be perpendicular."
    ),
    pose: str = typer.Option(
        None, "--pose", help="Numerical IK target: 16 comma-separated numbers (row-major 4x4) or "
        "a JSON file (4x4, list of 4x4, or {\"pose\": ...}).", metavar=POSE_FILE_METAVAR
    ),
    q0_deg: str = typer.Option(
        None, "--q0-deg", help="Numerical IK start: joint values, rotating joints in degrees.",
        metavar=Q_METAVAR
    ),
    restarts: int = typer.Option(100, "--restarts", help="Numerical IK: random restarts."),
    max_iter: int = typer.Option(100, "--max-iter", help="Numerical IK: iterations per attempt."),
    seed: int = typer.Option(0, "--seed", help="Numerical IK: seed of the random restarts."),
    ignore_limits: bool = flag(
        False, "--ignore-limits", help="Numerical IK: ignore the model's joint limits."
    ),
    all_solutions: bool = flag(
        False, "--all", help="With --pose: every analytic solution of a 6R arm, or of an arm "
        "with prismatic joints before a spherical wrist (kinestat.ik_all), and the one nearest "
        "--current-deg (or --q0-deg; default the model's home) within the limits."
    ),
    lock: list[str] = typer.Option(
        None, "--lock", help="With --all, a 7-joint arm: hold joint J (number from 1, or name) at "
        "VALUE (degrees; prismatic: length) and solve the other six; repeatable. With "
        "--self-motion: J alone.", metavar="J=VALUE"
    ),
    self_motion: int = typer.Option(
        None, "--self-motion", help="With --all --lock J: sample joint J at N values over its "
        "limits and give every solution at each (the self-motion).", metavar="N"
    ),
    tip: str = tip_option(),
    base: str = base_option(),
    scale: float = scale_option(),
    length_unit: str = length_unit_option(),
    as_json: bool = json_option(),
) -> None:
    """Joint angles that reach a pose.

    PUMA 762, closed form (Vibhute 2011 §2.2): every solution (up to 8) and every wrist-singular
    family; JSON {"solutions": [{"q_deg", "axis_deg", "branch", "within_limits", ...}],
    "singular_families": [...], "selected" (with --current-deg)}.

    Any model, numerically (--pose): JSON {"q", "q_deg", "success", "position_error",
    "rotation_error", "iterations", "attempts", "joint_names"}.

    Any 6R arm, or R/P arm with a spherical wrist, every solution (--pose --all): JSON
    {"solutions": [{"q", "q_deg", "residual", "within_limits", "singular"}],
    "singular_families", "selected", "reason", "method", "units"}; an unreachable pose gives no
    solution, the reason, and exit status 0. A 7-joint arm with --lock J=VALUE: the same, with
    "locked"; with --lock J --self-motion N: {"self_motion": {"joint", "samples": [{"value",
    "value_deg", "solutions", ...}]}}.
    """
    closed = any(v is not None for v in (tool_point, s6, a67))
    check_seed(seed)
    if limits not in get_args(AxisLimitSet):
        raise InputError(f"--limits must be 'matlab' or 'table', got {limits!r}")
    if (lock or self_motion is not None) and not all_solutions:
        raise InputError("--lock and --self-motion go with --all")
    if self_motion is not None and self_motion < 1:
        raise InputError(f"--self-motion must be a number of samples >= 1, got {self_motion}")
    if all_solutions:
        _all_command(model, closed, pose, current_deg, current_axis_deg, q0_deg,
                     (tip, base, scale, length_unit), as_json, lock or [], self_motion)
        return
    if closed and pose is not None:
        raise InputError("give either --pose (numerical IK) or --tool-point/--s6/--a67 "
                         "(PUMA 762 closed form), not both")
    if closed and q0_deg is not None:
        raise InputError("--q0-deg: a start of numerical IK (--pose); the PUMA 762 closed form "
                         "picks among its solutions by --current-deg or --current-axis-deg")
    if closed:
        _closed_form(model, tool_point, s6, a67, tool_point_6, current_deg, current_axis_deg,
                     limits, normalize, as_json)
        return
    if pose is None:
        raise InputError("give the target: --pose for any model, or --tool-point, --s6 and "
                         "--a67 for the PUMA 762 closed form")
    closed_only = [name for name, given in (("--current-deg", current_deg is not None),
                                            ("--current-axis-deg", current_axis_deg is not None),
                                            ("--normalize", normalize)) if given]
    if closed_only:
        raise InputError(f"{', '.join(closed_only)}: options of the PUMA 762 closed form "
                         "(--tool-point/--s6/--a67) or of --all; numerical IK starts from "
                         "--q0-deg")
    m = load_model(model, tip, base, scale, length_unit)
    _numerical(m, pose, q0_deg, restarts, max_iter, seed, ignore_limits, as_json)


def _closed_form(model, tool_point, s6, a67, tool_point_6, current_deg, current_axis_deg,
                 limits, normalize, as_json) -> None:
    from kinestat.robots.puma762 import (
        closed_form as P,  # lazy: numba kernels; keeps `kinestat --help` fast
    )
    from kinestat.spatial.validate import as_unit_vector  # lazy: kinestat.spatial loads scipy

    if model != "puma762":
        raise InputError(
            f"the closed-form reverse analysis (--tool-point/--s6/--a67) exists only for "
            f"puma762, not {model!r}; use --pose for numerical IK"
        )
    missing = [n for n, v in (("--tool-point", tool_point), ("--s6", s6), ("--a67", a67))
               if v is None]
    if missing:
        raise InputError(f"the PUMA 762 closed form needs {', '.join(missing)} as well")
    if limits not in get_args(AxisLimitSet):
        raise InputError(f"--limits must be 'matlab' or 'table', got {limits!r}")
    lim = {"matlab": P.AXIS_LIMITS_MATLAB_DEG, "table": P.AXIS_LIMITS_TABLE_2_1_DEG}[limits]
    p = parse_floats(tool_point, 3, "tool-point")
    z = parse_floats(s6, 3, "s6")
    x = parse_floats(a67, 3, "a67")
    p6 = parse_floats(tool_point_6, 3, "tool-point-6")
    if normalize:
        z = as_unit_vector(z, "--s6", normalize=True)
        x = as_unit_vector(x, "--a67", normalize=True)
    if current_deg is not None and current_axis_deg is not None:
        raise InputError("give the current configuration once: --current-deg or "
                         "--current-axis-deg")
    current = current_axis = None
    if current_deg is not None:
        current = np.radians(parse_floats(current_deg, 6, "current-deg"))
    elif current_axis_deg is not None:
        current_axis = np.radians(parse_floats(current_axis_deg, 6, "current-axis-deg"))
        current = P.from_axis_angles(current_axis)

    with compiling_notice("puma762"):
        res = P.reverse(p, z, x, p6)
    b = res.batch
    if current_axis is not None:
        cand = P.select_batch(b, None, lim, current_axis=current_axis)
    else:
        cand = P.select_batch(b, current, lim)
    out: dict = {
        "model": "puma762",
        "method": "closed-form",
        "tool_point": p,
        "s6": z,
        "a67": x,
        "tool_point_6": p6,
        "solutions": [],
        "singular_families": [],
        "axis_limits_deg": lim,
    }
    for qk, k in zip(res.solutions, res.branches, strict=True):
        out["solutions"].append({
            "branch": int(k),
            "q_deg": _deg(qk),
            "axis_deg": _deg(P.to_axis_angles(qk)),
            "within_limits": bool(cand.candidates_ok[k]),
            "position_error": float(b.position_error[k]),
            "rotation_error": float(b.rotation_error[k]),
        })
    for f in res.families:
        rel = "theta6 - theta4" if f.kind == "difference" else "theta4 + theta6"
        out["singular_families"].append({
            "branch": f.branch,
            "kind": f.kind,
            "relation": f"{rel} = value_deg (theta4 free)",
            "value_deg": float(np.degrees(f.value)),
            "phi1_deg": float(np.degrees(f.phi1)),
            "theta2_deg": float(np.degrees(f.theta2)),
            "theta3_deg": float(np.degrees(f.theta3)),
            "theta5_deg": float(np.degrees(f.theta5)),
            "representative_q_deg": _deg(f.representative),
            "within_limits": bool(cand.candidates_ok[f.branch]),
        })
    if res.reason:
        out["reason"] = res.reason
    if current is not None:
        out["current_q_deg"] = _deg(current)
        if current_axis is not None:
            out["current_axis_deg"] = _deg(current_axis)
        if bool(cand.ok):
            k = int(cand.branch)
            out["selected"] = {
                "branch": k,
                "q_deg": _deg(cand.q),
                "axis_deg": _deg(cand.axis),
                "singular": bool(b.singular[k]),
                "motion_deg": float(np.degrees(cand.motion)),
            }
        else:
            out["selected"] = None
            out["selection_error"] = "no solution lies within the axis limits"
    if as_json:
        print_json({**out, "units": units(out.get("length_unit", "mm"))})
        return
    _print_closed_form(out, res, current is not None)


def _print_closed_form(out: dict, res, has_current: bool) -> None:
    """The tables of the PUMA 762 closed form (without --json)."""
    console.print(f"[bold]PUMA 762 reverse analysis[/]: {len(res.solutions)} isolated "
                  f"solution(s), {len(res.families)} wrist-singular family(ies)")
    cols = ["branch", "φ1", "θ2", "θ3", "θ4", "θ5", "θ6", "limits ok"]
    rows = [[s["branch"], *s["q_deg"], "yes" if s["within_limits"] else "no"]
            for s in out["solutions"]]
    if rows:
        console.print(table("Solutions (degrees)", cols, rows, fmt="{:.3f}"))
    for f in out["singular_families"]:
        console.print(
            f"family (branch {f['branch']}): φ1={f['phi1_deg']:.4f} θ2={f['theta2_deg']:.4f} "
            f"θ3={f['theta3_deg']:.4f} θ5={f['theta5_deg']:.4f}, {f['relation']} with value "
            f"{f['value_deg']:.4f}°" + ("" if f["within_limits"] else "  \\[outside limits]")
        )
    if res.reason:
        console.print(f"[yellow]note:[/] {literal(res.reason)}")
    if has_current:
        sel = out["selected"]
        if sel is None:
            console.print("[red]no solution lies within the axis limits[/]")
        else:
            console.print(
                f"selected branch {sel['branch']}: q (deg) = "
                + ", ".join(f"{v:.4f}" for v in sel["q_deg"])
                + "; axis (deg) = " + ", ".join(f"{v:.4f}" for v in sel["axis_deg"])
                + f"; total motion {sel['motion_deg']:.4f}°"
            )


def _numerical(model_name, pose, q0_deg, restarts, max_iter, seed, ignore_limits,
               as_json) -> None:
    import kinestat  # lazy: pulls in numba and scipy; keeps `kinestat --help` fast
    from kinestat.serial.ik import MAX_ITER, MAX_RESTARTS, ik  # lazy: as above

    if not 0 <= restarts <= MAX_RESTARTS:
        raise InputError(f"--restarts must be 0 or more and at most {MAX_RESTARTS}, got {restarts}")
    if not 1 <= max_iter <= MAX_ITER:
        shown = max_iter if len(str(max_iter)) <= 40 else f"{len(str(max_iter))} digits"
        raise InputError(f"--max-iter must be at least 1 and at most {MAX_ITER}, got {shown}")
    m = kinestat.load(model_name)
    T = _read_poses(pose)
    q0 = None
    if q0_deg is not None:
        v = parse_floats(q0_deg, m.n, "q0-deg")
        q0 = np.where(m.prismatic, v, np.radians(v))
    with compiling_notice("serial", "ik"):
        r = ik(m, T, q0, restarts=restarts, max_iter=max_iter, seed=seed,
               respect_limits=not ignore_limits)
    q_deg = np.where(m.prismatic, r.q, np.degrees(r.q))
    out = {
        "model": m.name,
        "method": "numerical",
        "length_unit": m.length_unit,
        "joint_names": [j.name for j in m.joints],
        "q": r.q,
        "q_deg": q_deg,
        "success": r.success,
        "position_error": r.position_error,
        "rotation_error": r.rotation_error,
        "iterations": r.iterations,
        "attempts": r.attempts,
    }
    if as_json:
        print_json({**out, "units": units(m.length_unit)})
    else:
        qs = np.atleast_2d(q_deg)
        ok = np.atleast_1d(r.success)
        pe = np.atleast_1d(r.position_error)
        re = np.atleast_1d(r.rotation_error)
        names = [j.name if j.name and j.name != str(i + 1) else f"q{i + 1}"
                 for i, j in enumerate(m.joints)]
        cols = ["#", *names, "ok", "pos err", "rot err"]
        rows = [[i, *qs[i], "yes" if ok[i] else "NO", f"{pe[i]:.1e}", f"{re[i]:.1e}"]
                for i in range(qs.shape[0])]
        console.print(table(f"{m.name}: numerical IK (rotating joints in degrees, lengths in "
                            f"{m.length_unit})", cols, rows, fmt="{:.3f}"))
    if not np.all(r.success):
        n_bad = int(np.sum(~np.atleast_1d(r.success)))
        raise KinestatError(
            f"numerical IK did not reach {n_bad} target(s) within tolerance (best configuration "
            "reported above); try another --q0-deg, more --restarts, or check that the pose "
            "is reachable within the joint limits"
        )


def _lock_joint(m, text: str) -> int:
    """The 0-based index of joint ``text`` (a number from 1, or a joint name) of model m."""
    names = [j.name for j in m.joints]
    if text in names and not text.isdigit():
        return names.index(text)
    if text.isdigit() and 1 <= int(text) <= m.n:
        return int(text) - 1
    raise InputError(f"--lock: joint {text!r} is neither a joint number (1 to {m.n}) nor a "
                     f"joint name of model {m.name!r} ({', '.join(names)})")


def _parse_locks(m, lock: list[str], self_motion: int | None) -> dict[int, float]:
    """``--lock J=VALUE`` options as ``{joint index: value}`` (radians or length); with
    ``--self-motion`` one ``--lock J`` whose value is NaN (sampled)."""
    out: dict[int, float] = {}
    for item in lock:
        j_text, sep, v_text = item.partition("=")
        j = _lock_joint(m, j_text.strip())
        if j in out:
            raise InputError(f"--lock: joint {j_text.strip()!r} is given twice")
        if self_motion is not None:
            if sep or len(lock) != 1:
                raise InputError("--self-motion samples one joint: give it as --lock J "
                                 "(no value)")
            out[j] = float("nan")
            continue
        if not sep:
            raise InputError(f"--lock: expected J=VALUE, got {item!r}")
        v = float(parse_floats(v_text, 1, f"lock {j_text.strip()}")[0])
        out[j] = v if m.prismatic[j] else float(np.radians(v))
    if self_motion is not None and not out:
        raise InputError("--self-motion needs the joint to sample: --lock J")
    return out


def _all_command(model, closed, pose, current_deg, current_axis_deg, q0_deg, urdf,
                 as_json, lock: list[str], self_motion: int | None) -> None:
    """``kinestat ik MODEL --pose ... --all``: every analytic solution (docs/ik-all.md)."""
    from kinestat.serial.analytic import ik_all, method_for, select_nearest  # lazy: numba
    from kinestat.serial.analytic.locked import check_locked, fold  # lazy: numba

    if closed or current_axis_deg is not None:
        raise InputError("--all goes with --pose (--tool-point/--s6/--a67 and "
                         "--current-axis-deg are the PUMA 762 closed form's options)")
    if pose is None:
        raise InputError("--all needs the target pose: --pose")
    if current_deg is not None and q0_deg is not None:
        raise InputError("give the reference configuration once: --current-deg or --q0-deg")
    m = load_model(model, *urdf)
    T = _read_poses(pose)
    ref_text, ref_name = (current_deg, "current-deg") if current_deg is not None else \
        (q0_deg, "q0-deg")
    ref = m.q_home
    if ref_text is not None:
        v = parse_floats(ref_text, m.n, ref_name)
        ref = np.where(m.prismatic, v, np.radians(v))
    locked = _parse_locks(m, lock, self_motion)
    m6 = fold(m, check_locked(m, {j: 0.0 for j in locked})) if locked else m
    groups = {"raghavan-roth": ("ik_all_closed", "ik_all_general"),
              "decoupled": ("ik_all_decoupled",),
              "middle-wrist": ("ik_all_middle",)}.get(method_for(m6), ("ik_all_closed",))
    groups += ("ik_all_locked",) if locked else ()  # the single call's steps around a kernel
    if self_motion is not None:
        _self_motion(m, T, next(iter(locked)), self_motion, ref, groups, as_json)
        return
    with compiling_notice(*groups):
        res = ik_all(m, T, locked=locked or None)
    sel = select_nearest(m, res, ref)
    records = [_all_record(m, res, sel, i, ref) for i in np.ndindex(res.shape)]
    head = {"model": m.name, "method": res.method, "length_unit": m.length_unit,
            "joint_names": [j.name for j in m.joints]}
    if locked:
        head["locked"] = [{"joint": m.joints[j].name, "index": j + 1, "value": v,
                           "value_deg": None if m.prismatic[j] else float(np.degrees(v))}
                          for j, v in locked.items()]
    if as_json:
        body = records[0] if T.ndim == 2 else {"targets": records}
        print_json({**head, **body, "units": units(m.length_unit)})
        return
    for k, rec in enumerate(records):
        _print_all(m, rec, res.method, None if T.ndim == 2 else k)


def _self_motion(m, T, j: int, n: int, ref, groups, as_json) -> None:
    """``--all --lock J --self-motion N``: every solution at N values of joint J."""
    from kinestat.serial.analytic import ik_self_motion, select_nearest  # lazy: numba

    if T.ndim != 2:
        raise InputError("--self-motion takes one target pose (--pose with one 4x4)")
    with compiling_notice(*groups):
        sm = ik_self_motion(m, T, j, n)
    samples = []
    for v, res in zip(sm.values, sm.results, strict=True):
        rec = _all_record(m, res, select_nearest(m, res, ref), (), ref)
        samples.append({"value": float(v), "value_deg": None if m.prismatic[j] else
                        float(np.degrees(v)), "method": res.method, **rec})
    out = {"model": m.name, "length_unit": m.length_unit,
           "joint_names": [jt.name for jt in m.joints],
           "self_motion": {"joint": m.joints[j].name, "index": j + 1, "samples": samples},
           "n_solutions": int(sum(s["n_solutions"] for s in samples))}
    if as_json:
        print_json({**out, "units": units(m.length_unit)})
        return
    for k, (s, res) in enumerate(zip(samples, sm.results, strict=True)):
        console.print(f"[bold]joint {literal(m.joints[j].name)} = "
                      f"{s['value'] if s['value_deg'] is None else s['value_deg']:.4f}"
                      f"{'' if s['value_deg'] is None else '°'}[/] (sample {k + 1} of {n})")
        _print_all(m, s, res.method, None)


def _all_record(m, res, sel, i: tuple, ref: np.ndarray) -> dict:
    """The JSON record of one pose's solutions (``i`` indexes the batch)."""
    from kinestat.serial.analytic import wrap_to_limits  # lazy: numba kernels

    rot = ~m.prismatic
    names = [f"joint {j.name}" if j.name.isdigit() else j.name for j in m.joints]
    out: dict = {"solutions": [], "singular_families": [], "n_solutions": int(res.n_solutions[i]),
                 "reference_q_deg": _q_deg(m, ref)}
    for k in np.flatnonzero(res.valid[i]):
        q = res.q[i][k]
        _, ok = wrap_to_limits(q, ref, m.lower, m.upper, rot)
        out["solutions"].append({
            "q": q, "q_deg": _q_deg(m, q),
            "residual": {"position": float(res.position_error[i][k]),
                         "rotation": float(res.rotation_error[i][k])},
            "within_limits": bool(np.all(ok)), "singular": bool(res.singular[i][k]),
        })
        if res.singular[i][k] and res.family_joints is None:  # a curve: four joints move
            curve = res.family_curve
            out["singular_families"].append({
                "solution": len(out["solutions"]) - 1,
                "joints": [names[j] for j in curve.joints],
                "free_joint": names[curve.free_joint], "sign": None, "value": None,
                "value_deg": None, "relation": f"{curve.description} (one free parameter; q "
                                               "holds one member)"})
        elif res.singular[i][k]:
            a, b = res.family_joints
            sign = int(res.family_sign[i][k])
            value = float(res.family_value[i][k])
            out["singular_families"].append({
                "solution": len(out["solutions"]) - 1, "joints": [names[a], names[b]],
                "sign": sign, "value": value, "value_deg": float(np.degrees(value)),
                "relation": f"{names[a]} {'+' if sign > 0 else '-'} {names[b]} = value "
                            "(one free parameter; q holds the member with "
                            f"{names[a]} = 0)",
            })
    out["reason"] = str(res.reason[i])  # "" when some solution exists
    if bool(sel.ok[i]):
        out["selected"] = {"index": int(np.flatnonzero(res.valid[i]).tolist().index(
            int(sel.index[i]))), "q": sel.q[i], "q_deg": _q_deg(m, sel.q[i]),
            "motion": float(sel.motion[i])}
    else:
        out["selected"] = None
        out["selection_error"] = ("no solution" if not out["solutions"] else
                                  "no solution lies within the joint limits")
    return out


def _q_deg(m, q) -> list[float]:
    """Joint values with rotating joints in degrees (prismatic: length)."""
    return [float(v) for v in np.where(m.prismatic, q, np.degrees(np.asarray(q, dtype=float)))]


def _print_all(m, rec: dict, method: str, k: int | None) -> None:
    """The table of ``ik --all`` for one pose (without --json)."""
    names = [j.name or f"q{i + 1}" for i, j in enumerate(m.joints)]
    title = (f"{m.name}: every IK solution ({method}; degrees, lengths in {m.length_unit})"
             + ("" if k is None else f", target {k}"))
    rows = [[n, *s["q_deg"], f"{s['residual']['position']:.1e}",
             f"{s['residual']['rotation']:.1e}", "yes" if s["within_limits"] else "no",
             "family" if s["singular"] else ""] for n, s in enumerate(rec["solutions"])]
    if rows:
        console.print(table(title, ["#", *names, "pos err", "rot err", "limits ok", "family"], rows,
                            fmt="{:.3f}"))
    else:
        console.print(f"[bold]{literal(title)}[/]: no solution")
    for f in rec["singular_families"]:
        value = "" if f["value_deg"] is None else f", value {f['value_deg']:.4f}°"
        console.print(f"solution {f['solution']} is a family: {literal(f['relation'])}{value}")
    if rec["reason"]:
        console.print(f"[yellow]unreachable:[/] {literal(rec['reason'])}")
    sel = rec["selected"]
    if sel is not None:
        console.print(f"selected #{sel['index']} (nearest the reference, within limits): "
                      + ", ".join(f"{v:.4f}" for v in sel["q_deg"]))
    elif rec["solutions"]:
        console.print("[red]no solution lies within the joint limits[/]")
