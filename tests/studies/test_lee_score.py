"""``sweep platform-design --score lee``: the grid's best design is Lee's optimum, found
independently by scipy.optimize on |det j| computed here from the leg lines."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import minimize

from kinestat.cli.main import main
from kinestat.parallel import special_6_6
from kinestat.studies.base import build_study
from kinestat.studies.engine import run_reference
from kinestat.studies.platform_design import platform_design_spec

A = 60.0  # the prototype's top side (mm), kept fixed: |det j| grows as a length cubed


def _det_lines(b: float, h: float, twist_deg: float, offsets=(0.0, 0.0)) -> float:
    """|det| of the six unit leg lines (direction; moment about the base origin) at home,
    over A³, from the design's attachment points."""
    p = special_6_6(base_side=b, top_side=A, base_offset=offsets[0], top_offset=offsets[1],
                    height=h, twist=math.radians(twist_deg))
    H = p.home_pose
    top = p.top_points @ H[:3, :3].T + H[:3, 3]
    s = top - p.base_points
    s /= np.linalg.norm(s, axis=1)[:, None]
    J = np.vstack([s.T, np.cross(p.base_points, s).T])
    return abs(float(np.linalg.det(J))) / A ** 3


def _optimum(x0=(100.0, 45.0, -45.0), offsets=(0.0, 0.0)) -> np.ndarray:
    r = minimize(lambda x: -_det_lines(*x, offsets=offsets), x0, method="Nelder-Mead",
                 options={"xatol": 1e-7, "fatol": 1e-12, "maxiter": 5000})
    assert r.success
    return r.x


def test_lees_optimum_by_an_independent_search_is_b_2a_h_a():
    # the seed's §3.1.2 (Lee): |det j| is largest with the base side twice the top side, the
    # height equal to the top side, the top turned 60° relative to the base (the octahedral
    # 3-3, edge offsets 0)
    b, h, tw = _optimum()
    assert b == pytest.approx(2 * A, rel=1e-5) and h == pytest.approx(A, rel=1e-5)
    assert tw == pytest.approx(-60.0, abs=1e-3)


def test_the_sweeps_best_is_the_independent_optimum_within_the_grid_step():
    # grid steps of 12 mm (base side), 6 mm (height) and 15° (twist), not centred on 120/60/-60
    spec = platform_design_spec(values={"base_offset": "0", "top_offset": "0",
                                        "base_side": "61:181", "height": "31:91",
                                        "twist_deg": "-90:-30:5"},
                                grid=11, poses=1, score="lee", chunk_size=256)
    s = run_reference(build_study("platform-design", spec))
    assert s["score"] == "lee" and s["designs"] == 11 * 11 * 5
    best = s["best"]["params"]
    b, h, tw = _optimum()
    assert abs(best["base_side"] - b) <= 12.0
    assert abs(best["height"] - h) <= 6.0
    assert abs(best["twist_deg"] - tw) <= 15.0
    # the sweep's score is the independent |det j| / A³ at its best design, and the grid max
    assert s["best"]["lee"] == pytest.approx(_det_lines(best["base_side"], best["height"],
                                                        best["twist_deg"]), rel=1e-9)
    assert s["lee"]["max"] == s["best"]["lee"]


def test_the_special_6_6s_own_optimum_moves_with_its_edge_points():
    # with the prototype's edge points (28 mm base, 14 mm top; twist -60°) Lee's 3-3 optimum
    # is not the 6-6's: the independent search and a sweep over the same box agree on another
    r = minimize(lambda x: -_det_lines(x[0], x[1], -60.0, (28.0, 14.0)), (100.0, 45.0),
                 method="Nelder-Mead", options={"xatol": 1e-7, "fatol": 1e-12})
    b, h = r.x
    assert r.success and b < 110.0 and h < 40.0
    spec = platform_design_spec(values={"base_side": "72:132", "height": "20:70"}, grid=11,
                                poses=1, score="lee", chunk_size=256)
    s = run_reference(build_study("platform-design", spec))
    best = s["best"]["params"]
    assert abs(best["base_side"] - b) <= 6.0 and abs(best["height"] - h) <= 5.0


def test_the_cli_score_option(capsys, tmp_path):
    out = tmp_path / "lee"
    assert main(["sweep", "platform-design", "--score", "lee", "--base-offset", "0",
                 "--top-offset", "0", "--base-side", "90:150", "--height", "40:80", "--grid", "5",
                 "--poses", "1", "--threads", "--workers", "1", "--no-plots", "--json",
                 "--output", str(out)]) == 0
    res = json.loads(capsys.readouterr().out)
    best = res["summary"]["best"]["params"]
    assert res["summary"]["score"] == "lee"
    assert (best["base_side"], best["height"]) == (120.0, 60.0)
    assert main(["sweep", "platform-design", "--score", "det", "--output",
                 str(tmp_path / "x")]) == 2
    assert "--score must be one of table-3-1, lee" in capsys.readouterr().err
