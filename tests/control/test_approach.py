"""The start move from the home position (after `kinestat home`) goes as a sequence of
commands, each within the envelope's per-command step and the axis limits, verified move by
move; `kinestat control --galil` then reaches the start pose (QA item 5)."""

from __future__ import annotations

import json

import numpy as np

from kinestat.app.control_run import DEFAULT_START, default_plane
from kinestat.app.sim_cell import SimHarness, control_model, start_counts
from kinestat.cli.main import main
from kinestat.control.approach import approach_waypoints
from kinestat.control.controller import THESIS_FORCE_DIRECTION, ControllerConfig
from kinestat.control.envelope import Envelope
from kinestat.control.log import read_log
from kinestat.control.tuning import TUNING
from kinestat.hardware.puma762_axes import AXIS_DEG_PER_COUNT
from kinestat.hardware.puma762_homing import HOME_COUNTS
from kinestat.parallel.platform import special_6_6
from kinestat.serial.puma762 import AXIS_LIMITS_DEG
from kinestat.sim.contact import make_cell
from kinestat.sim.sensor import Sensor


def _cell(distance: float = 2.5):
    p0 = np.array([float(v) for v in DEFAULT_START.split(",")])
    pp, pn = default_plane(p0, THESIS_FORCE_DIRECTION, distance, 5.0)
    cell = make_cell(special_6_6(), plane_point=pp, plane_normal=pn)
    cfg = ControllerConfig(model=control_model(cell, Sensor()),
                           force=4 * THESIS_FORCE_DIRECTION, start_tool_point=p0)
    return cell, cfg


def test_waypoints_split_a_long_move_within_the_step_and_end_at_the_goal():
    _, cfg = _cell()
    model, env = cfg.model, Envelope()
    goal = start_counts(cfg, HOME_COUNTS)
    wps = approach_waypoints(env, model, HOME_COUNTS, goal)
    np.testing.assert_array_equal(wps[-1], goal)
    res = np.asarray(model.axis_deg_per_count)
    prev = HOME_COUNTS.astype(float)
    per = TUNING.approach_step_fraction * env.max_joint_step_deg
    for wp in wps:
        step = np.abs(wp - prev) * res
        assert np.all(step <= per + 1e-9)
        # axis 5's motor step with the axis 4 -> 5 compensation stays within the limit
        assert step[4] + abs(model.coupling) * step[3] <= env.max_joint_step_deg
        prev = wp
    assert len(wps) >= np.max(np.abs(goal - HOME_COUNTS) * res) / env.max_joint_step_deg
    # a short move is one command
    assert len(approach_waypoints(env, model, goal - 100, goal)) == 1


def test_control_from_the_home_position_reaches_the_start_pose(tmp_path, capsys):
    # the workpiece (an infinite plane) 1 m ahead: the home pose's tool is on its free side
    # (with the default 2.5 mm it would be 210 mm inside the plane at home)
    cell, cfg = _cell(1000.0)
    goal = start_counts(cfg, HOME_COUNTS)
    far = np.max(np.abs(goal - HOME_COUNTS) * AXIS_DEG_PER_COUNT)
    assert far > 30  # refused as one command before this fix
    log = tmp_path / "log.jsonl"
    with SimHarness(cell, Sensor(), start_counts=HOME_COUNTS, record=True) as h:
        host, port = h.galil_address
        code = main(["control", "--galil", f"{host}:{port}", "--serial", h.serial_path,
                     "--no-plot", "--json", "--log", str(log), "--max-iterations", "1"])
        commands = list(h.controller.commands)
    out = capsys.readouterr().out
    report = json.loads(out[out.index("{"):])
    recs = read_log(log)
    approach = [r for r in recs if r["type"] == "approach"]
    assert len(approach) >= 2
    assert [a["waypoint"] for a in approach] == list(range(1, len(approach) + 1))
    moves = [r for r in recs if r["type"] == "move" and r["cycle"] == 0]
    assert len(moves) == len(approach) + 1  # one per command, verified by read-back each
    # every PA sent: inside the axis limits and within 30° of the previous position
    pas = [np.array([float(v) for v in c[2:].split(",")]) for c in commands
           if c.startswith("PA")]
    prev = HOME_COUNTS.astype(float)
    for pa in pas:
        deg = pa * AXIS_DEG_PER_COUNT
        assert np.all((deg >= AXIS_LIMITS_DEG[:, 0]) & (deg <= AXIS_LIMITS_DEG[:, 1]))
        assert np.max(np.abs(pa - prev)[[0, 1, 2, 3, 5]] * AXIS_DEG_PER_COUNT[[0, 1, 2, 3, 5]]) \
            <= 30
        prev = pa
    # the start pose was reached: the first measurement is at the commanded start
    cyc = [r for r in recs if r["type"] == "cycle"]
    assert cyc, (code, report["stop_reason"])
    np.testing.assert_allclose(cyc[0]["measured"]["tool_point"], cfg.start_tool_point, atol=0.5)


def test_home_then_control_on_one_simulated_controller(tmp_path, capsys):
    """`kinestat home` on a robot at an unknown position, then `kinestat control --galil` on
    the same simulated controller (the harness's DMC replaced by an unhomed one)."""
    from kinestat.sim.dmc import DmcSimulator, SimClock
    from kinestat.sim.galil_server import GalilSimServer

    cell, cfg = _cell(1000.0)
    h = SimHarness(cell, Sensor())
    # simulated time (0.05 s per command), as the homing tests: the coarse move takes seconds
    h.controller = DmcSimulator.unknown_start(4, clock=SimClock(step_per_command=0.05))
    h.server = GalilSimServer(controller=h.controller)
    with h:
        host, port = h.galil_address
        addr = f"{host}:{port}"
        assert main(["home", "--galil", addr, "--json", "--log", str(tmp_path / "h.jsonl")]) == 0
        capsys.readouterr()
        main(["control", "--galil", addr, "--serial", h.serial_path, "--no-plot", "--json",
              "--log", str(tmp_path / "c.jsonl"), "--max-iterations", "1"])
    out = capsys.readouterr().out
    report = json.loads(out[out.index("{"):])
    recs = read_log(tmp_path / "c.jsonl")
    assert any(r["type"] == "approach" for r in recs), report["stop_reason"]
    cyc = [r for r in recs if r["type"] == "cycle"]
    assert cyc, report["stop_reason"]
    np.testing.assert_allclose(cyc[0]["measured"]["tool_point"], cfg.start_tool_point, atol=0.5)
