"""The two plants of ``kinestat control`` side by side: the built-in simulator and MuJoCo.

Measured in one run, on the thesis's default cell (PUMA 762, the 2011 platform with the thesis's
legs and encoders, the default plane 2.5 mm ahead, 4 N along the thesis's direction):

* ``rtf``: MuJoCo's real-time factor (simulated seconds per wall second) of ``mj_step`` alone
  and of the plant's step (the legs' law and the servos applied each step), the tip pressed at
  4 N; the built-in simulator has no time: the wall time of one contact equilibrium instead.
* ``press``: the default press on each plant — the built-in through the simulated devices as
  ``kinestat control`` runs it (the Galil's profiles in real time, so its elapsed time is its
  time to goal), MuJoCo in process (simulated seconds to goal: the Galil's profiles followed by
  the servos, then settling); cycles, true |F| and wall time.
* ``follow`` (not with ``--quick``): the follow task, 50 mm on the default plane: travel speed
  (mm per second of the plant's time) and the true normal force's errors.

    .venv/bin/python benchmarks/plants.py [--quick] [--json]
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from kinestat.app.control_run import (  # noqa: E402
    ControlRequest,
    SimulatedCell,
    prepare_control,
    report_dict,
    run_control,
)
from kinestat.control.controller import THESIS_FORCE_DIRECTION  # noqa: E402

START = np.array([-400.0, 800.0, -100.0])


def _request(plant: str, task: str = "press") -> ControlRequest:
    kw = {"travel_dir": np.array([0.0, 1.0, 0.0])} if task == "follow" else {}
    return ControlRequest(force=4.0 * np.asarray(THESIS_FORCE_DIRECTION), start_tool_point=START,
                          cell=SimulatedCell(plant=plant), task=task, **kw)


def rtf(steps: int = 4000) -> dict:
    """MuJoCo's real-time factor at 4 N of contact; the built-in's equilibrium time."""
    import mujoco

    from kinestat.app.sim_cell import CellState

    prep = prepare_control(_request("mujoco"))
    plant = prep.plant
    model = prep.config.model
    T = plant.flange_pose()
    tp = T[:3, :3] @ model.tool_point_6 + T[:3, 3] + 3.5 * np.asarray(THESIS_FORCE_DIRECTION)
    axis = model.arm.solve_axis(tp, T[:3, 2], T[:3, 0], model.tool_point_6, plant.joints(),
                                model.limits_deg)
    q, q0 = model.arm.q_from_axis(axis), plant.joints()
    plant.track(lambda t: q0 + t * (q - q0), 1.0)  # 1 s, as a Galil move would
    plant.settle()
    f = float(np.linalg.norm(plant.truth()["true_force"]))
    dt = plant.model.opt.timestep
    data = copy.copy(plant.data)  # the forces held constant: timing only
    t0 = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(plant.model, data)
    raw = steps * dt / (time.perf_counter() - t0)
    t0 = time.perf_counter()
    plant.step(steps)
    full = steps * dt / (time.perf_counter() - t0)
    state = CellState(prep.cell, prep.sensor)
    reps = 50
    t0 = time.perf_counter()
    for k in range(reps):  # a fresh pose each time (no cache)
        state.solve(q + 1e-7 * k)
    eq_ms = (time.perf_counter() - t0) / reps * 1e3
    return {"mujoco_contact_force_N": f, "mujoco_timestep_s": dt, "mujoco_rtf_mj_step": raw,
            "mujoco_rtf_plant": full, "kinestat_equilibrium_ms": eq_ms}


def _run(plant: str, task: str) -> dict:
    prep = prepare_control(_request(plant, task))
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        rep = run_control(prep, Path(tmp) / "log.jsonl")
    out = report_dict(prep, rep)
    out["wall_s"] = time.perf_counter() - t0
    plant_time = out.get("sim_time_s", out["elapsed_s"])  # the built-in runs in real time
    keep = {"plant": plant, "converged": out["converged"], "cycles": out["iterations"],
            "plant_time_s": plant_time, "wall_s": out["wall_s"],
            "true_force_N": out.get("true_force_magnitude")}
    if task == "follow":
        keep.update(travel_mm=out.get("travel"),
                    travel_speed_mm_s=(out.get("travel") or 0.0) / plant_time,
                    true_rms_N=out.get("true_normal_force_rms_error"),
                    true_max_N=out.get("true_normal_force_max_error"))
    return keep


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the real-time factor and the press")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    res = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "rtf": rtf(),
           "press": [_run(p, "press") for p in ("kinestat", "mujoco")]}
    if not a.quick:
        res["follow"] = [_run(p, "follow") for p in ("kinestat", "mujoco")]
    if a.json:
        print(json.dumps(res, indent=2))
        return
    r = res["rtf"]
    print(f"{res['date']}\nMuJoCo at {r['mujoco_contact_force_N']:.2f} N of contact, step "
          f"{r['mujoco_timestep_s'] * 1e3:g} ms: real-time factor {r['mujoco_rtf_mj_step']:.1f} "
          f"(mj_step), {r['mujoco_rtf_plant']:.1f} (the plant's step); built-in: one contact "
          f"equilibrium {r['kinestat_equilibrium_ms']:.2f} ms")
    for task in ("press", "follow"):
        for row in res.get(task, []):
            print(f"{task:6s} " + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else
                                             f"{k} {v}" for k, v in row.items()))


if __name__ == "__main__":
    main()
