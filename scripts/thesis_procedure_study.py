"""The thesis's procedure over 20 random workpieces (issue 12): properties and figures.

Runs ``kinestat control --procedure thesis`` on the in-process simulated cell (thesis legs,
thesis calibration) for 20 random planes (0.3-3 mm ahead of the start tool point, normal tilted
0-8° from −F_req), with the thesis's 1 mm step and with 0.2 mm, checks the procedure's
properties on every run (tests/app/test_thesis_procedure.py) and prints the figures; then the
same workpieces with the improved procedure, and the bias of the nominal calibration read on
the final counts of each converged run.

    .venv/bin/python scripts/thesis_procedure_study.py
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control  # noqa: E402
from kinestat.control.controller import THESIS_FORCE_DIRECTION  # noqa: E402
from kinestat.control.wrench import measure  # noqa: E402
from tests.app.test_thesis_procedure import (  # noqa: E402
    START,
    check_thesis_properties,
    random_workpiece,
    run_thesis,
)


def main(n: int = 20) -> None:
    rng = np.random.default_rng(2011)
    planes = [random_workpiece(rng) for _ in range(n)]
    nominal = prepare_control(ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                                             start_tool_point=START, cell=SimulatedCell(),
                                             calibration="nominal")).config.model
    with tempfile.TemporaryDirectory() as tmp:
        tmp_path = Path(tmp)
        for procedure, step in (("thesis", 1.0), ("thesis", 0.2), ("kinestat", 1.0)):
            rows = []
            for point, normal in planes:
                prep, rep, recs = run_thesis(tmp_path, point, normal, step=step,
                                             procedure=procedure)
                if procedure == "thesis":
                    check_thesis_properties(rep, step, 0.5)
                err = (None if rep.true_force is None or rep.equivalent_wrench is None else
                       float(np.linalg.norm(rep.equivalent_wrench[:3] - rep.true_force)))
                bias = None
                last = [r for r in recs if r["type"] == "cycle"][-1]["measured"]
                if rep.converged:
                    m = measure(nominal, np.radians(last["joints_deg"]), last["counts"],
                                nominal.platform.home_pose)
                    bias = float(np.linalg.norm(m.wrench[:3] - rep.true_force))
                rows.append((rep.converged, rep.iterations,
                             [c["action"] for c in rep.cycles].count("reorient"),
                             rep.true_force_magnitude, err, bias, rep.stop_reason))
            conv = [r for r in rows if r[0]]
            print(f"procedure {procedure}, step {step} mm: {len(conv)}/{n} converged, "
                  f"{sum(r[6].startswith('cannot settle') for r in rows)} cannot settle, "
                  f"{sum(not r[0] and not r[6].startswith('cannot settle') for r in rows)} "
                  f"other stops; reorientations {sorted({r[2] for r in rows})}")
            if conv:
                it = [r[1] for r in conv]
                tf = [r[3] for r in conv]
                er = [r[4] for r in conv if r[4] is not None]
                bi = [r[5] for r in conv if r[5] is not None]
                print(f"  converged: cycles {min(it)}-{max(it)} (mean {np.mean(it):.1f}); true "
                      f"|F| {min(tf):.3f}-{max(tf):.3f} N; |W_eq force - true| max "
                      f"{max(er):.4f} N; nominal calibration on the same counts: |error| "
                      f"{min(bi):.2f}-{max(bi):.2f} N")
            others = {r[6] for r in rows if not r[0] and not r[6].startswith("cannot settle")}
            for why in sorted(others):
                print("  stop:", why[:160])


if __name__ == "__main__":
    main()
