"""Record the controller's decisions on twelve simulated runs, or compare two recordings.

A refactoring of ``kinestat/control/`` should not change what the controller decides. This
script runs twelve requests on the in-process simulated cell (press: plane, fixed step,
friction 0.3, R = 200 mm cylinder, leg noise, the thesis's procedure; follow: plane, plane with
friction, cylinders with the automatic tilt, a tilted start that the envelope stops, leg
noise) and writes, per run, its cycle count, stop reason and every command (kind, label,
action, axis counts, predicted force and leg deflections) to a JSON file. ``--compare A B``
reports, per run, whether the cycle counts, stop reasons and commands are the same and the
largest difference of the predicted figures. Each run's task (press, thesis or follow) is
recorded through the task protocol (:mod:`kinestat.control.task`).

    .venv/bin/python scripts/decision_replay.py record OUT.json
    .venv/bin/python scripts/decision_replay.py compare BEFORE.json AFTER.json
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from kinestat.app.control_run import prepare_control  # noqa: E402
from kinestat.app.sim_cell import InProcessIO, start_counts  # noqa: E402
from kinestat.control.controller import THESIS_FORCE_DIRECTION  # noqa: E402
from kinestat.control.log import CycleLog  # noqa: E402
from kinestat.control.loop import run  # noqa: E402
from kinestat.control.runspec import CylinderSpec, RunSpec, SimulatedCell  # noqa: E402

START = np.array([-400.0, 800.0, -100.0])


def _cylinder(radius: float, mu: float = 0.0) -> SimulatedCell:
    return SimulatedCell(friction=mu, cylinder=CylinderSpec(radius, np.array([0.0, 0.0, 1.0])))


RUNS = {
    "press": dict(task="press"),
    "press-fixed": dict(task="press", method="fixed"),
    "press-friction": dict(task="press", cell=SimulatedCell(friction=0.3)),
    "press-cyl200": dict(task="press", cell=_cylinder(200.0)),
    "press-noise": dict(task="press", cell=SimulatedCell(noise=0.002, seed=3)),
    "press-thesis": dict(task="press", procedure="thesis"),
    "follow-plane": dict(task="follow", travel=20.0),
    "follow-plane-friction": dict(task="follow", travel=20.0, cell=SimulatedCell(friction=0.3)),
    "follow-cyl-friction": dict(task="follow", travel=20.0, auto_tilt=True,
                                cell=_cylinder(200.0, 0.3)),
    "follow-cyl100": dict(task="follow", travel=20.0, auto_tilt=True, cell=_cylinder(100.0)),
    "follow-tilt": dict(task="follow", travel=15.0, tilt_deg=10.0),
    "follow-noise": dict(task="follow", travel=15.0, cell=SimulatedCell(noise=0.002, seed=5)),
}


def _listed(a) -> list | None:
    return None if a is None else np.asarray(a).tolist()


class _Recording:
    """The run's task (:mod:`kinestat.control.task`), recording every command it decides."""

    def __init__(self, task) -> None:
        self.name, self.config, self._task, self.cmds = task.name, task.config, task, []

    def start(self, q_now, counts_now):
        return self._task.start(q_now, counts_now)

    def decide(self, state, meas):
        cmd, new = self._task.decide(state, meas)
        pred = getattr(cmd, "prediction", None)
        self.cmds.append([cmd.kind, cmd.label, cmd.action, _listed(cmd.axis_counts),
                          None if pred is None else _listed(pred.force),
                          None if pred is None else _listed(pred.deflections)])
        return cmd, new

    def report(self, cycles):
        return self._task.report(cycles)


def record_one(kw: dict) -> dict:
    """One run's cycle count, stop reason and commands."""
    kw = dict(kw)
    kw.setdefault("cell", SimulatedCell())
    if kw["task"] == "follow":
        kw.setdefault("travel_dir", np.array([0.0, 1.0, 0.0]))
    req = RunSpec(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START, **kw)
    prep = prepare_control(req)
    task = _Recording(prep.task)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with tempfile.TemporaryDirectory() as tmp, CycleLog(Path(tmp) / "log.jsonl") as log:
        rep = run(task, io, log)
    cmds = task.cmds
    return {"converged": rep.converged, "iterations": rep.iterations, "moves": rep.moves,
            "stop": rep.stop_reason, "cmds": cmds}


def compare(a: dict, b: dict) -> bool:
    """Print the comparison per run; True when every run decided the same."""
    all_same = True
    for name, ra in a.items():
        rb = b.get(name)
        if rb is None:
            print(f"{name:24s} missing in the second recording")
            all_same = False
            continue
        keys = ("converged", "iterations", "moves", "stop")
        head = all(ra[k] == rb[k] for k in keys)
        ca, cb = ra["cmds"], rb["cmds"]
        cmds = len(ca) == len(cb) and all(x[:4] == y[:4] for x, y in zip(ca, cb, strict=True))
        delta = 0.0
        for x, y in zip(ca, cb, strict=False):
            for i in (4, 5):
                if x[i] is not None and y[i] is not None:
                    delta = max(delta, float(np.max(np.abs(np.subtract(x[i], y[i])))))
        all_same &= head and cmds
        print(f"{name:24s} cycles {ra['iterations']:4d}/{rb['iterations']:4d}, stop reason "
              f"{'same' if head else 'DIFFERENT'}, commands {'same' if cmds else 'DIFFERENT'}, "
              f"largest |Δ| of the predicted force and deflections {delta:.1e}")
    return all_same


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what", required=True)
    rec = sub.add_parser("record")
    rec.add_argument("out", type=Path)
    cmp_ = sub.add_parser("compare")
    cmp_.add_argument("before", type=Path)
    cmp_.add_argument("after", type=Path)
    args = ap.parse_args(argv)
    if args.what == "record":
        out = {}
        for name, kw in RUNS.items():
            out[name] = record_one(kw)
            print(f"{name:24s} {out[name]['iterations']:4d} cycles: {out[name]['stop']}",
                  flush=True)
        args.out.write_text(json.dumps(out))
        return 0
    same = compare(json.loads(args.before.read_text()), json.loads(args.after.read_text()))
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
