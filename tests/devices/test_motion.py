"""Coordinated moves: the axes of every move start and finish together (issue 12 item 6)."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.app.sim_cell import SimHarness, start_counts
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import run
from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX
from kinestat.devices.motion import coordinated_move_plan, move_plan
from kinestat.errors import InputError
from kinestat.sim.dmc import DmcSimulator, SimClock, trapezoid


def _durations(plan, current, target):
    d = np.asarray(target, dtype=float) - np.asarray(current, dtype=float)
    out = []
    for k in range(6):
        segs = trapezoid(d[k], plan.speed[k], plan.accel[k], plan.decel[k])
        out.append(sum(t for t, _ in segs))
    return np.array(out)


@pytest.mark.parametrize("seed", range(8))
def test_coordinated_axes_finish_together_within_the_limits(seed):
    rng = np.random.default_rng(seed)
    cur = rng.integers(-50000, 50000, 6)
    delta = rng.integers(-20000, 20000, 6) * (rng.random(6) < 0.8)
    delta[rng.integers(0, 6)] = int(rng.integers(1, 5))  # a tiny move among large ones
    tgt = cur + delta
    plan = coordinated_move_plan(cur, tgt, THESIS_SPEED_MAX, THESIS_ACCEL)
    assert np.all(plan.speed <= np.asarray(THESIS_SPEED_MAX) + 1e-9)
    assert np.all(plan.accel <= np.asarray(THESIS_ACCEL) + 1e-9)
    moving = delta != 0
    dur = _durations(plan, cur, tgt)[moving]
    assert np.ptp(dur) <= 1e-3 * dur.max() + 1e-6
    # some axis runs at one of its limits (the plan is as fast as the limits allow)
    v_lim = np.isclose(plan.speed[moving], np.asarray(THESIS_SPEED_MAX)[moving], rtol=1e-6)
    a_lim = np.isclose(plan.accel[moving], np.asarray(THESIS_ACCEL)[moving], rtol=1e-6)
    assert v_lim.any() and a_lim.any()


def test_the_simulated_dmc_stops_every_axis_at_the_same_time():
    clock = SimClock()
    dmc = DmcSimulator(clock=clock, coupling=0.0)
    tgt = np.array([12000, -3000, 800, 250, -40, 7])
    plan = coordinated_move_plan(np.zeros(6), tgt, THESIS_SPEED_MAX, THESIS_ACCEL)
    for cmd, vals in (("AC", plan.accel), ("DC", plan.decel), ("SP", plan.speed),
                      ("PA", tgt)):
        assert dmc.handle(cmd + " " + ",".join(f"{v:.4f}" for v in vals)) == ":"
    assert dmc.handle("BG") == ":"
    ends = np.full(6, np.nan)
    t = 0.0
    while np.isnan(ends).any() and t < 20:
        t = clock.advance(0.001)
        for k, m in enumerate(dmc.moving()):
            if not m and np.isnan(ends[k]):
                ends[k] = t
    assert np.ptp(ends) <= 0.002
    np.testing.assert_array_equal(np.rint(dmc.encoder_counts()), tgt)


def test_thesis_rule_and_bad_rule():
    p = move_plan("thesis", np.zeros(6), [400, 8, 0, 0, 0, 100000], THESIS_SPEED_MAX,
                  THESIS_ACCEL)
    assert p.speed.tolist()[:2] == [100.0, 10.0] and p.speed[5] == THESIS_SPEED_MAX[5]
    assert p.target.tolist() == [400, 8, 0, 0, 0, 100000]  # no +5 nudge
    with pytest.raises(InputError):
        move_plan("fastest", np.zeros(6), np.ones(6), 1, 1)


def test_the_log_records_every_moves_deltas_and_speeds(tmp_path):
    req = ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION,
                         start_tool_point=np.array([-400.0, 800.0, -100.0]),
                         cell=SimulatedCell(), max_iterations=12)
    prep = prepare_control(req)
    with SimHarness(prep.cell, prep.sensor, start_counts=start_counts(prep.config),
                    record=True) as h:
        io = h.device_io(reader_options={"stale_after": 0.3}, client_timeout=0.5)
        with CycleLog(tmp_path / "l.jsonl") as log:
            rep = run(prep.config, io, log)
        sent = [c for c in h.controller.commands if c.startswith("SP ")]
    recs = read_log(tmp_path / "l.jsonl")
    moves = [r["move"] for r in recs if r["type"] == "move"]
    assert rep.converged and len(moves) == rep.moves == len(sent)
    for m, sp in zip(moves, sent, strict=True):
        assert len(m["delta_counts"]) == 6 and len(m["speed"]) == 6
        np.testing.assert_allclose([float(v) for v in sp[3:].split(",")], m["speed"],
                                   atol=1e-4)
        d = np.abs(np.asarray(m["delta_counts"], dtype=float))
        mv = d > 0
        if mv.sum() > 1:  # speeds proportional to the deltas: one cruise time
            ratio = d[mv] / np.asarray(m["speed"])[mv]
            assert np.ptp(ratio) <= 1e-3 * ratio.max() + 1e-3


@pytest.mark.parametrize("seed", range(6))
def test_limit_accel_caps_each_axis_by_its_travel_and_keeps_the_axes_together(seed):
    """Every moving axis accelerates at most rate × its travel; a coordinated move stays
    coordinated (its axes still finish together) and lasts at least the triangular profile's
    2 √(1 / rate) at that rate."""
    from kinestat.devices.motion import limit_accel

    rng = np.random.default_rng(100 + seed)
    cur = rng.integers(-50000, 50000, 6)
    delta = rng.integers(-3000, 3000, 6) * (rng.random(6) < 0.8)
    delta[0] = int(rng.integers(50, 3000))
    tgt = cur + delta
    rate = float(rng.uniform(0.05, 2.0))
    plan = coordinated_move_plan(cur, tgt, THESIS_SPEED_MAX, THESIS_ACCEL)
    slow = limit_accel(plan, cur, rate)
    moving = delta != 0
    assert np.all(slow.accel[moving] <= rate * np.abs(delta[moving]) + 1e-3)
    assert np.all(slow.decel[moving] <= rate * np.abs(delta[moving]) + 1e-3)
    assert np.all(slow.accel <= plan.accel) and np.array_equal(slow.speed, plan.speed)
    assert np.array_equal(slow.accel[~moving], plan.accel[~moving])
    dur = _durations(slow, cur, tgt)[moving]
    assert np.ptp(dur) <= 1e-3 * dur.max() + 1e-6
    assert dur.max() >= 2.0 * np.sqrt(1.0 / rate) * (1 - 1e-3)
    assert limit_accel(plan, cur, None) is plan


@pytest.mark.parametrize("rate", [0.0, -1.0, float("nan"), float("inf")])
def test_limit_accel_refuses_a_rate_that_is_not_a_positive_number(rate):
    from kinestat.devices.motion import limit_accel

    plan = coordinated_move_plan([0] * 6, [100] * 6, THESIS_SPEED_MAX, THESIS_ACCEL)
    with pytest.raises(InputError, match="acceleration rate"):
        limit_accel(plan, [0] * 6, rate)
