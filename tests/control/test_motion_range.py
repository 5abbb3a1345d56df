"""Table 3-1's motion ranges in the envelope: measured states outside stop the run, commands
predicted to leave them are refused before they are sent (issue 12 item 7)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from kinestat.app.calibrations import calibrated_model, resolve_calibration, resolve_platform
from kinestat.app.control_run import (
    ControlRequest,
    SimulatedCell,
    prepare_control,
)
from kinestat.app.sim_cell import InProcessIO, SimHarness, start_counts
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.control.envelope import MOTION_RANGE, Envelope, check_motion, top_motion
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import run
from kinestat.devices.cell_io import MotionProfile
from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX
from kinestat.sim.contact import Workpiece

START = np.array([-400.0, 800.0, -100.0])
FAST = MotionProfile(speed=tuple(20 * np.asarray(THESIS_SPEED_MAX)),
                     accel=tuple(400 * np.asarray(THESIS_ACCEL)))


def _model():
    p = resolve_platform(None)  # the prototype with the thesis's calibrated legs
    return calibrated_model(p, resolve_calibration("thesis", p))


def test_top_motion_of_a_known_displacement():
    model = _model()
    H = model.platform.home_pose
    rng = np.random.default_rng(0)
    for _ in range(5):
        rv = rng.normal(size=3) * 0.03
        t = rng.normal(size=3)
        T = np.eye(4)
        R = Rotation.from_rotvec(rv).as_matrix()
        c = model.platform.top_points.mean(axis=0)
        T[:3, :3] = R @ H[:3, :3]
        c_home = H[:3, :3] @ c + H[:3, 3]
        T[:3, 3] = c_home + t - T[:3, :3] @ c  # the centroid moves by t
        np.testing.assert_allclose(top_motion(model, T), np.concatenate([t, np.degrees(rv)]),
                                   atol=1e-9)
    assert not check_motion(Envelope(), model, H, "measured")
    T = H.copy()
    T[2, 3] += MOTION_RANGE[2] + 0.01
    bad = check_motion(Envelope(), model, T, "measured")
    assert len(bad) == 1 and "Table 3-1" in bad[0] and " z " in bad[0]


def _request(force: float) -> ControlRequest:
    return ControlRequest(force=force * THESIS_FORCE_DIRECTION, start_tool_point=START,
                          cell=SimulatedCell(), max_iterations=30)


# narrowed z ranges (Table 3-1: 4 mm; the 4 N goal needs ~1.0 mm, an approach step is
# predicted at ~1.0 mm if the workpiece were met at its start)
TIGHT = Envelope(motion_range=(3.5, 3.5, 0.9, 4.0, 4.0, 6.0))
ROT_X = Envelope(motion_range=(3.5, 3.5, 4.0, 2.0, 4.0, 6.0))


def test_a_command_predicted_to_leave_the_ranges_is_refused(tmp_path):
    """The run stops on a predicted motion before any command leaving the ranges is sent, and
    nothing measured is ever outside them."""
    prep = prepare_control(_request(4.0))
    cfg = replace(prep.config, envelope=TIGHT)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(cfg))
    with CycleLog(tmp_path / "l.jsonl") as log:
        rep = run(cfg, io, log)
    recs = read_log(tmp_path / "l.jsonl")
    assert not rep.converged and io.stopped
    assert "predicted top motion" in rep.stop_reason and "Table 3-1" in rep.stop_reason
    for r in recs:
        c = r.get("commanded")
        if c and c.get("predicted_top_pose") is not None:
            assert not check_motion(TIGHT, cfg.model, np.asarray(c["predicted_top_pose"]),
                                    "predicted")
        if r["type"] == "cycle":  # and nothing measured outside
            assert not check_motion(TIGHT, cfg.model,
                                    np.asarray(r["measured"]["top_pose"]), "measured")


def test_measured_state_outside_the_ranges_stops_with_st_and_a_complete_log(tmp_path):
    """Fault injection: the workpiece jumps 2.2 mm towards the tool during the approach
    (through the real Galil client and encoder reader): the next measurement is outside → ST,
    full log. (With the thesis's legs the platform buckles at ~8 N along F_req, before Table
    3-1's ranges: the test narrows the range about x to 2°; the jump turns the top ~2.4°.)"""
    prep = prepare_control(_request(4.0))
    cfg = replace(prep.config, envelope=ROT_X)
    path = tmp_path / "log.jsonl"
    with SimHarness(prep.cell, prep.sensor, start_counts=start_counts(cfg), record=True) as h:
        io = h.device_io(profile=FAST, client_timeout=0.5)

        def progress(rec):
            if rec["cycle"] == 2:
                wp = h.state.cell.workpiece
                moved = Workpiece(wp.point + 2.2 * wp.normal, wp.normal)
                h.state.cell = replace(h.state.cell, workpiece=moved)
                h.state._key = None

        with CycleLog(path) as log:
            rep = run(cfg, io, log, progress=progress)
        commands = list(h.controller.commands)
    recs = read_log(path)
    kinds = [r["type"] for r in recs]
    assert kinds[0] == "start" and kinds[-1] == "end" and "fault" in kinds
    assert kinds.count("cycle") == rep.iterations
    assert not rep.converged and "measured top motion about x" in rep.stop_reason
    assert [c for c in commands if not c.endswith(",_BGF")][-1] == "ST"  # then its proof
