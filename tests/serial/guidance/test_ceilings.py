"""Issue 11 items 6 and 8 for guidance: a ceiling on the steps of one run (refused before any
work, for Python callers and the CLI alike), inputs and numerics that end a run with a clear
report instead of a traceback, and Ctrl-C that says where the run was."""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import pytest

from kinestat.cli.main import main
from kinestat.disp import run_deck
from kinestat.errors import InputError
from kinestat.io.disp_deck import embedded_deck
from kinestat.serial.guidance.planners import command_path
from kinestat.serial.guidance.rules import FirstOrder, GuidanceOptions
from kinestat.serial.guidance.run import MAX_RUN_STEPS, GuidanceInterrupted, run_guidance
from tests.serial.guidance._models import C2


def _cmd(d: float, angle: float = 0.0):
    return lambda H: command_path(H, [0, 0, 1], d, angle)


@pytest.mark.parametrize("steps", [10**9, MAX_RUN_STEPS + 1, [MAX_RUN_STEPS // 2 + 1] * 2])
def test_step_ceiling_refused_before_work(steps):
    calls = []
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=f"ceiling of {MAX_RUN_STEPS}"):
        run_guidance(C2, C2.q_home, [_cmd(1.0), _cmd(1.0)], steps=steps,
                     progress=lambda d, t: calls.append(d))
    assert calls == [] and time.perf_counter() - t0 < 5.0


def test_steps_at_the_ceiling_are_accepted_in_sum():
    # the check counts the sum, so a split just under the ceiling passes the check (run 1 step
    # of the first stage and stop: the progress callback interrupts)
    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(GuidanceInterrupted) as ei:
        run_guidance(C2, C2.q_home, [_cmd(1.0), _cmd(1.0)],
                     steps=[MAX_RUN_STEPS // 2, MAX_RUN_STEPS // 2], progress=stop)
    assert (ei.value.step, ei.value.planned) == (1, MAX_RUN_STEPS // 2)
    assert "step 1 of" in str(ei.value)


@pytest.mark.parametrize("steps", [math.nan, math.inf, 2.5, "3", True, -1])
def test_bad_step_counts_are_input_errors(steps):
    with pytest.raises(InputError):
        run_guidance(C2, C2.q_home, [_cmd(1.0)], steps=steps)


def test_automatic_counts_share_the_run_ceiling():
    # stage 1: 10 explicit steps; stage 2 automatic needs ceiling - 5 steps of L/100: over the
    # run's ceiling together, refused when stage 2 is planned, before any of its steps
    L = 10.0
    d = (MAX_RUN_STEPS - 5.5) * 0.01 * L
    done = []
    with pytest.raises(InputError, match="more than 99990"):
        run_guidance(C2, C2.q_home, [_cmd(0.5), _cmd(d)], steps=[10, 0], length=L,
                     progress=lambda j, t: done.append(j))
    assert max(done) == 10
    with pytest.raises(InputError, match=f"more than {MAX_RUN_STEPS}"):  # one stage alone
        run_guidance(C2, C2.q_home, [_cmd(1.2 * MAX_RUN_STEPS * 0.01 * L)], length=L,
                     progress=lambda j, t: done.append(j))
    assert max(done) == 10


@pytest.mark.parametrize("steps", [None, 5])
def test_extreme_distance_is_a_clear_error(steps):
    with pytest.raises(InputError, match="not finite"):
        run_guidance(C2, C2.q_home, [_cmd(1e300)], steps=steps)


def test_linalg_failure_stops_with_a_report():
    class Failing:
        refinable = False

        def increment(self, path, s0, s1, inp):
            raise np.linalg.LinAlgError("SVD did not converge")

    r = run_guidance(C2, C2.q_home, [_cmd(1.0)], steps=4, rule=Failing(),
                     options=GuidanceOptions(settle=False))
    assert r.stopped and r.stop_kind == "numerical"
    assert "SVD did not converge" in r.stop_message and len(r.q) == 1


def test_non_finite_increments_stop_with_a_report():
    class Exploding:
        refinable = False

        def increment(self, path, s0, s1, inp):
            res = FirstOrder().increment(path, s0, s1, inp)
            return dataclasses.replace(res, dq=res.dq * math.inf)

    r = run_guidance(C2, C2.q_home, [_cmd(1.0)], steps=4, rule=Exploding(),
                     options=GuidanceOptions(settle=False))
    assert r.stopped and r.stop_kind == "numerical"
    assert np.all(np.isfinite(r.q))


def test_run_deck_applies_the_ceiling():
    deck = embedded_deck("illustration7")
    with pytest.raises(InputError, match="ceiling"):
        run_deck(deck, steps=10**9)


@pytest.mark.parametrize("argv", [
    ["disp", "illustration7", "--steps", "1000000000"],
    ["guide", "nadkarni-config2", "--command", "dir=0,0,1,d=1", "--steps", "1000000000"],
    ["guide", "nadkarni-config2", "--command", "dir=0,0,1,d=1e300"],
])
def test_cli_refuses_in_one_line(argv, capsys):
    t0 = time.perf_counter()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("kinestat: error:")
    assert time.perf_counter() - t0 < 30.0


@pytest.mark.parametrize("argv", [
    ["guide", "nadkarni-config2", "--command", "dir=0,0,1,d=1", "--steps", str(MAX_RUN_STEPS)],
    ["disp", "illustration7", "--steps", str(MAX_RUN_STEPS // 5)],
])
def test_ctrl_c_ends_a_long_run_in_one_line(argv, capsys, monkeypatch):
    """A real SIGINT, raised part-way through the run (after a fixed number of steps, so the
    check does not depend on how fast the machine is), ends it in one line with exit 130."""
    import os
    import signal

    from kinestat.serial.guidance import run as run_mod

    real_step, calls = run_mod._Run.step, []

    def step(self, st, j):
        calls.append(j)
        if len(calls) == 200:
            os.kill(os.getpid(), signal.SIGINT)
        return real_step(self, st, j)

    monkeypatch.setattr(run_mod._Run, "step", step)
    rc = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 130
    assert err[-1].startswith("kinestat: interrupted: the guidance run was stopped at step ")
    step, planned = (int(w) for w in err[-1].removesuffix(" planned").split()[-3::2])
    assert 0 < step < planned
