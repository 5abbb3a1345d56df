"""``kinestat platform fk`` says which assembly mode is the physical one (issue 16)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.cli.main import main
from kinestat.io.library import prototype
from kinestat.parallel.legs import leg_lengths
from kinestat.spatial.se3 import so3_exp


def _fk(capsys, legs) -> dict:
    assert main(["platform", "fk", "--legs", ",".join(f"{x:.12g}" for x in legs), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_physical_mode_is_the_pose_near_home_that_made_the_legs(capsys, seed):
    p = prototype()
    rng = np.random.default_rng(seed)
    T = p.home_pose.copy()
    T[:3, :3] = so3_exp(rng.normal(scale=0.03, size=3)) @ T[:3, :3]
    T[:3, 3] += rng.normal(scale=0.5, size=3)
    out = _fk(capsys, leg_lengths(p, T))
    marked = [s for s in out["solutions"] if s["physical"]]
    assert len(marked) == 1
    assert out["solutions"][out["physical_mode"] - 1]["physical"]
    np.testing.assert_allclose(marked[0]["pose"], T, atol=1e-6)
    assert marked[0]["above_base"]


def test_the_human_output_marks_it_and_prints_its_pose(capsys):
    p = prototype()
    assert main(["platform", "fk", "--legs",
                 ",".join(f"{x:.12g}" for x in leg_lengths(p, p.home_pose))]) == 0
    out = capsys.readouterr().out
    assert out.count("physical") >= 2  # the table's mark and the pose's title
    assert out.count("Mode ") == 1  # only the physical pose without --all-poses
