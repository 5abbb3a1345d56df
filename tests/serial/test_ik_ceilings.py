"""Issue 11 item 8 for IK: ceilings on restarts and iterations, refused before any work."""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.errors import InputError
from kinestat.serial.ik import MAX_ITER, MAX_RESTARTS, ik, iter_ik

ARM = kinestat.load("nadkarni-config2")


@pytest.mark.parametrize("kw", [
    {"restarts": MAX_RESTARTS + 1}, {"restarts": 10**9}, {"restarts": -1},
    {"max_iter": MAX_ITER + 1}, {"max_iter": 2**64}, {"max_iter": 0}, {"max_iter": 2.0},
    {"restarts": True},
])
def test_effort_outside_the_ceilings_is_refused(kw):
    with pytest.raises(InputError, match="whole number from"):
        ik(ARM, np.eye(4), **kw)
    with pytest.raises(InputError, match="whole number from"):
        next(iter(iter_ik(ARM, np.eye(4)[None], **kw)))


def test_effort_at_the_ceilings_is_accepted():
    from kinestat.serial.fk import fk
    T = fk(ARM, ARM.q_home)
    r = ik(ARM, T, ARM.q_home, restarts=MAX_RESTARTS, max_iter=MAX_ITER)
    assert bool(r.success)


@pytest.mark.parametrize("opt,val", [("--restarts", "1000000000"),
                                     ("--max-iter", "18446744073709551616")])
def test_cli_refuses_in_one_line(opt, val, capsys):
    pose = "1,0,0,0.5,0,1,0,0,0,0,1,0.5,0,0,0,1"
    assert main(["ik", "nadkarni-config2", "--pose", pose, opt, val]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("kinestat: error:") and opt in err[0]
