"""The thesis's 1 mm-step procedure on compliant (wood-like) workpieces (issue 40).

Runs ``kinestat control --procedure thesis --step 1`` on the in-process simulated cell
(thesis legs and calibration, 4 N along F_req, tolerance 0.5 N) against the default plane and
the 20 random planes of ``scripts/thesis_procedure_study.py`` (0.3-3 mm ahead, normal tilted
0-8°, seed 2011), for each workpiece stiffness given (N/mm; ``rigid`` for none), and prints per
stiffness: runs converged / cannot settle / other stops, the converged true |F| and W_eq's |F|,
and the force change of the last translation step (what one 1 mm step does to |F|).

    .venv/bin/python scripts/wood_study.py [k ...]      # default: 0.5 1 2 5 10 30 100 300 rigid
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from kinestat.app.control_run import (  # noqa: E402
    DEFAULT_PLANE_DISTANCE,
    DEFAULT_PLANE_TILT_DEG,
    ControlRequest,
    SimulatedCell,
    default_plane,
    prepare_control,
)
from kinestat.app.sim_cell import InProcessIO, start_counts  # noqa: E402
from kinestat.control.controller import THESIS_FORCE_DIRECTION  # noqa: E402
from kinestat.control.log import CycleLog  # noqa: E402
from kinestat.control.loop import run  # noqa: E402
from tests.app.test_thesis_procedure import START, random_workpiece  # noqa: E402


def run_one(tmp: Path, point, normal, stiffness):
    """One thesis-procedure run (1 mm step) on a plane of the given stiffness (None: rigid)."""
    cell = SimulatedCell(plane_point=point, plane_normal=normal, workpiece_stiffness=stiffness)
    req = ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START, cell=cell,
                         step=1.0, force_tol=0.5, procedure="thesis", max_iterations=40)
    prep = prepare_control(req)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with CycleLog(tmp / "run.jsonl") as log:
        return run(prep.config, io, log)


def _force_jump(rep) -> float | None:
    """|F| change over the last translation step that was in contact before and after."""
    mags = [float(np.linalg.norm(c["force"])) if c.get("force") is not None else 0.0
            for c in rep.cycles]
    steps = [b - a for a, b in zip(mags[:-1], mags[1:], strict=True) if a > 0.25 and b > 0.25]
    return abs(steps[-1]) if steps else None


def main(stiffnesses: list[float | None], n: int = 20) -> None:
    rng = np.random.default_rng(2011)
    planes = [default_plane(START, THESIS_FORCE_DIRECTION, DEFAULT_PLANE_DISTANCE,
                            DEFAULT_PLANE_TILT_DEG)]
    planes += [random_workpiece(rng) for _ in range(n)]
    print("k (N/mm) | default plane: stop, true |F| | random planes: converged / cannot settle "
          "/ other | converged true |F| (N) | last in-contact step's |dF| (N)")
    with tempfile.TemporaryDirectory() as tmp:
        for k in stiffnesses:
            rows = []
            for point, normal in planes:
                rep = run_one(Path(tmp), point, normal, k)
                rows.append((rep.converged, rep.true_force_magnitude, rep.stop_reason,
                             _force_jump(rep)))
            d = rows[0]
            rand = rows[1:]
            conv = [r[1] for r in rand if r[0]]
            settle = sum(r[2].startswith("cannot settle") for r in rand)
            jumps = [r[3] for r in rand if r[3] is not None]
            print(f"{'rigid' if k is None else f'{k:g}'} | "
                  f"{'done' if d[0] else d[2][:30]}, {d[1] or 0.0:.3f} | "
                  f"{len(conv)} / {settle} / {len(rand) - len(conv) - settle} | "
                  + (f"{min(conv):.2f}-{max(conv):.2f} (median {np.median(conv):.2f})"
                     if conv else "-")
                  + (f" | {min(jumps):.2f}-{max(jumps):.2f}" if jumps else " | -"), flush=True)
            for why in sorted({r[2] for r in rand if not r[0]
                               and not r[2].startswith("cannot settle")}):
                print("   stop:", why[:140])


if __name__ == "__main__":
    args = sys.argv[1:] or ["0.5", "1", "2", "5", "10", "30", "100", "300", "rigid"]
    main([None if a == "rigid" else float(a) for a in args])
