"""The loop runs any task behind the task protocol (issue 41): the press, the thesis's
procedure and follow are tasks, and a new task is one class."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pytest

from kinestat.app.control_run import prepare_control
from kinestat.app.sim_cell import InProcessIO, start_counts
from kinestat.control.controller import Command, ControllerConfig, start
from kinestat.control.follow_task import FollowTask
from kinestat.control.log import CycleLog, read_log
from kinestat.control.loop import run
from kinestat.control.press_task import PressTask
from kinestat.control.runspec import RunSpec
from kinestat.control.task import Task, as_task
from kinestat.control.thesis_task import ThesisTask
from kinestat.errors import InputError


@dataclass(frozen=True, eq=False)
class HoldTask:
    """A task written in a test: go to the start pose, then measure ``cycles`` times without
    moving and report the largest force seen."""

    config: ControllerConfig
    cycles: int = 3
    name: str = "hold"

    def start(self, q_now, counts_now):
        return start(self.config, q_now, counts_now=counts_now)

    def decide(self, state, meas):
        new = replace(state, cycle=state.cycle + 1, top_pose=meas.top_pose,
                      done=state.cycle + 1 >= self.cycles)
        kind = "done" if new.done else "measure"
        info = {"info": {"force_seen": float(meas.force_magnitude)}}
        return Command(kind=kind, label="a", action="measure" if kind == "measure" else "",
                       reason="held" if new.done else "", **info), new

    def report(self, cycles):
        return {"task": self.name, "largest_force": max(c["force_seen"] for c in cycles)}


def test_the_three_tasks_are_tasks():
    prep = prepare_control(RunSpec())
    assert isinstance(PressTask(prep.config), Task)
    assert isinstance(ThesisTask(prep.config), Task)
    follow = prepare_control(RunSpec(task="follow"))
    assert isinstance(follow.task, FollowTask) and isinstance(follow.task, Task)
    assert follow.task.config is follow.config
    assert isinstance(prep.task, PressTask)
    thesis = replace(prep.config, procedure="thesis")
    assert isinstance(as_task(thesis), ThesisTask)


def test_a_new_task_is_one_class_the_loop_runs_as_it_is(tmp_path):
    prep = prepare_control(RunSpec())
    task = HoldTask(prep.config, cycles=4)
    assert isinstance(task, Task)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with CycleLog(tmp_path / "log.jsonl") as log:
        rep = run(task, io, log)
    assert rep.converged and rep.stop_reason == "held" and rep.iterations == 4
    assert rep.moves == 1  # the start move only: the task never moved
    records = read_log(tmp_path / "log.jsonl")
    cycles = [r for r in records if r["type"] == "cycle"]
    assert [c["decision"] for c in cycles] == ["measure"] * 3 + ["done"]
    assert all("force_seen" in c["task"] for c in cycles)
    figures = task.report(rep.cycles)
    assert figures["largest_force"] == max(c["force_seen"] for c in rep.cycles)
    assert figures["largest_force"] < prep.config.contact_force  # the tool is clear


def test_the_press_task_decides_as_the_bare_config(tmp_path):
    """The press behind the protocol and the bare ControllerConfig give the same run."""
    prep = prepare_control(RunSpec())
    reports = []
    for task in (PressTask(prep.config), prep.config):
        io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
        with CycleLog(tmp_path / f"{len(reports)}.jsonl") as log:
            reports.append(run(task, io, log))
    a, b = reports
    assert a.converged and (a.iterations, a.states) == (b.iterations, b.states)
    assert np.array_equal(a.tool_point, b.tool_point)


def test_a_run_spec_given_to_the_loop_is_one_clear_error(tmp_path):
    with CycleLog(tmp_path / "log.jsonl") as log, pytest.raises(InputError, match="control.run"):
        run(RunSpec(), None, log)


def test_control_run_runs_a_spec_as_the_command_does(tmp_path):
    """``kinestat.control.run(RunSpec(...))``: the package root hands it the application's
    runner; the report is the command's (the same decisions as the loop on the same cell)."""
    import kinestat.control as control

    out = control.run(RunSpec(), log=tmp_path / "log.jsonl")
    assert out["converged"] and out["states"] == "aaabe"
    assert (tmp_path / "log.jsonl").exists()
    with pytest.raises(InputError, match="builds its own cell"):
        control.run(RunSpec(), object())
