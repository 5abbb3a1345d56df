"""The controller's arm stays revolute-only although ik_all now solves prismatic arms (the
Stanford arm): its axis angles and limits are degrees, a boom's limits are lengths."""

from __future__ import annotations

import pytest

import kinestat
from kinestat.control.arm import ChainArm
from kinestat.errors import ModelError


def test_a_prismatic_arm_is_refused_naming_the_joint():
    model = kinestat.load("stanford")
    assert kinestat.ik_all(model, kinestat.fk(model, model.q_home)).n_solutions > 0
    with pytest.raises(ModelError, match="joint 3 of model 'stanford' is prismatic"):
        ChainArm(model)
