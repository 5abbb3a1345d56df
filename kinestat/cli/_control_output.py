"""What ``kinestat control`` prints (:mod:`kinestat.cli.control`): a line per cycle, the final
report, and the live view's server around the run (``--view --serve``)."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from kinestat.cli._output import console as out_console
from kinestat.cli._output import err_console, literal, table


def print_progress(rec: dict) -> None:
    """One line per cycle on stderr."""
    m = rec["measured"]
    c = rec["commanded"]
    what = rec["decision"] if c is None else c["action"]
    extra = ""
    if c is not None and c["step"]:
        extra += f" step {c['step']:+.4f} mm"
    if c is not None and c["rotation_deg"]:
        extra += f" turn {c['rotation_deg']:.3f}°"
    fmag = float(np.linalg.norm(m["estimate"]))
    task = rec.get("task")
    if task:
        extra += f"  F_n {task['normal_force']:7.4f} N  travel {task['travel']:7.3f} mm"
    err_console.print(f"cycle {rec['cycle']:3d}  state {rec['state']}  |F| {fmag:7.4f} N"
                      f"  -> {what}{extra}")


def start_live(log_path: Path, platform: str | None):
    """The live view of the run (``--view --serve``), opened in the browser."""
    import webbrowser  # lazy: the browser only with --serve

    from kinestat.viz.live import start_live  # lazy: the server only with --serve

    p = None
    if platform is not None:
        from kinestat.io.platform_toml import read_platform  # lazy: only with --platform

        p = read_platform(platform)
    live = start_live(log_path, platform=p)
    err_console.print(f"kinestat control: live view at {live.url}")
    err_console.file.flush()
    webbrowser.open(live.url)
    return live


def serve_until_interrupted(live) -> None:
    err_console.print(f"kinestat control: the run has ended; the live view stays at {live.url} "
                      "until Ctrl-C")
    err_console.file.flush()
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        live.close()


def arm_words(placed) -> str:
    """The banner's words on another arm: its name and where its base was put."""
    b = ", ".join(f"{v:g}" for v in placed.base)
    how = "placed automatically" if placed.placement == "auto" else "--arm-base"
    return f", arm {placed.source_name} (base at {b} mm, {how})"


def print_report(out: dict) -> None:
    ok = "[green]converged[/]" if out["converged"] else "[red]not converged[/]"
    out_console.print(f"Kinestatic control {ok} after {out['iterations']} cycles "
                      f"({out['moves']} moves, {out['elapsed_s']:.1f} s); states "
                      + (" → ".join(out["states"]) if out["states"]
                         else "none (stopped before the first cycle)"))
    if out["converged"]:  # a failed run's reason is the one error line on stderr
        out_console.print(f"  {literal(out['stop_reason'])}")
    if out.get("task") == "follow":
        rms, mx = out.get("normal_force_rms_error"), out.get("normal_force_max_error")
        out_console.print(f"  travel {out['travel']:.3f} mm along the surface; normal force error "
                          + ("n/a" if rms is None else f"RMS {rms:.4f} N, max {mx:.4f} N")
                          + f"; contact lost {out['contact_lost']} cycles")
    rows = []
    # the equivalent wrench's force beside its torques: base − tool = tool_point × that force,
    # base − tip = tip × that force
    for key, label in (("force", f"force, {out.get('estimator', 'point')} estimate (N)"),
                       ("equivalent_force", "equivalent wrench: force (N)"),
                       ("torque_about_tip", "  torque about measured tip (N·mm)"),
                       ("torque_about_tool", "  torque about tool point P_tool_F (N·mm)"),
                       ("torque_about_base", "  torque about robot base (N·mm)"),
                       ("true_force", "true force (N)"), ("tool_axis", "tool axis S6"),
                       ("tip", "tip, measured (mm)"),
                       ("tool_point", "tool point (mm), commanded")):
        if out.get(key) is not None:
            rows.append([label, *out[key]])
    if rows:
        out_console.print(table("Final state (fixed frame)", ["", "x", "y", "z"], rows))
    if out.get("force_magnitude") is not None:
        line = f"|F| = {out['force_magnitude']:.4f} N (target {out['target_force']:g} N)"
        if out.get("true_force_magnitude") is not None:
            line += f", true |F| = {out['true_force_magnitude']:.4f} N"
        if out.get("axis_error_deg") is not None:
            line += f", true force vs tool axis {out['axis_error_deg']:.3f}°"
        out_console.print(line)
    if out.get("final_axis_deg") is not None:
        out_console.print("robot axes (deg): " + ", ".join(f"{v:.4f}"
                                                           for v in out["final_axis_deg"]))
    if out.get("tool_point_6") is not None:
        out_console.print("tool offset (" + ", ".join(f"{v:g}" for v in out["tool_point_6"])
                          + ") mm in the end frame, mount "
                          + literal(str(out.get("mount_source", "centred"))))
    if out.get("arm") is not None:
        arm = out["arm"]
        out_console.print(literal(f"arm {arm['name']}: base at ("
                                  + ", ".join(f"{v:g}" for v in arm["base"]) + ") mm, "
                                  + ("placed automatically" if arm["placement"] == "auto"
                                     else "--arm-base")))
    out_console.print(f"log: {literal(out['log'])}")
    for p in out.get("plots", []):
        out_console.print(f"plot: {literal(p)}")


def announce(prepared, o: dict) -> None:
    """The run's first line on stderr: the goal, the procedure and the cell."""
    spec = prepared.request
    d = spec.direction
    cell = (("simulated cell" + (" (MuJoCo)" if o["sim"] == "mujoco" else ""))
            if prepared.cell is not None
            else literal(f"Galil {o['galil']}, sensor {o['serial']}"))
    err_console.print(f"[bold]kinestat control[/]: |F_req| = {o['force']:g} N along "
                      f"({d[0]:.4f}, {d[1]:.4f}, {d[2]:.4f}), procedure {spec.procedure}, "
                      f"method {spec.method}, calibration {spec.calibration}, " + cell
                      + ("" if prepared.arm is None else literal(arm_words(prepared.arm)))
                      + ("" if prepared.follow is None else
                         "; follow {:g} mm, first along ({:.4f}, {:.4f}, {:.4f})".format(
                             prepared.follow.travel, *prepared.follow.travel_dir)))


def no_plot(exc: Exception) -> None:
    """A plot the run's log cannot give: said on stderr, the run's result stands."""
    err_console.print(f"[yellow]no plot:[/] {literal(exc)}")
