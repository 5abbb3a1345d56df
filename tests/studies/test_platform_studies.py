"""Platform range, design and tolerance studies against independent computations."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kinestat.cli.main import main
from kinestat.errors import InputError
from kinestat.io.library import prototype
from kinestat.parallel import leg_lengths, special_6_6, spring_wrench
from kinestat.studies.base import build_study
from kinestat.studies.engine import run_reference
from kinestat.studies.platform_design import platform_design_spec
from kinestat.studies.platform_range import platform_range_spec
from kinestat.studies.tolerance import tolerance_spec

RANGE = np.array([3.5, 3.5, 4.0, np.radians(4.0), np.radians(4.0), np.radians(6.0)])


def _poses(platform, d):
    """Poses displaced by d = (x, y, z, rotation vector) about the top's centre at home."""
    H = platform.home_pose
    c = (platform.top_points @ H[:3, :3].T + H[:3, 3]).mean(axis=0)
    out = []
    for row in d:
        R = Rotation.from_rotvec(row[3:]).as_matrix()
        T = np.eye(4)
        T[:3, :3] = R @ H[:3, :3]
        T[:3, 3] = c + row[:3] + R @ (H[:3, 3] - c)
        out.append(T)
    return np.array(out)


def test_range_grid_counts_match_direct_computation():
    p = prototype()
    s = run_reference(build_study("platform-range", platform_range_spec(grid=3,
                                                                        chunk_size=100)))
    d = np.array(list(itertools.product(*[np.linspace(-r, r, 3) for r in RANGE])))
    T = _poses(p, d)
    defl = np.abs(leg_lengths(p, T) - p.free_lengths).max(axis=1)
    fz = np.abs(spring_wrench(p, T)[:, 2])
    ok = (defl <= 5.0) & (fz <= 50.0)
    assert s["poses"] == 729
    assert s["within_deflection"] == int(np.sum(defl <= 5.0))
    assert s["within_both"] == int(ok.sum())
    assert s["max_deflection"]["max"] == pytest.approx(defl.max(), rel=1e-12)
    assert s["force_z"]["max"] == pytest.approx(fz.max(), rel=1e-12)
    assert 0 < s["within_both"] < 729  # the box corners exceed 5 mm, the axes do not
    assert s["axis_check"]["meets"] is True


def test_range_stiffness_at_home_equals_platform_stiffness_command(capsys):
    s = run_reference(build_study("platform-range", platform_range_spec(samples=10)))
    assert main(["platform", "stiffness", "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(s["stiffness_home"], cli["stiffness"], rtol=1e-12, atol=1e-12)
    K = np.array(s["stiffness_home"])
    # unloaded at home: K symmetric (Vibhute eq. 2-17 with zero load)
    np.testing.assert_allclose(K, K.T, atol=1e-9)


def test_design_grid_scores_the_prototype_as_the_thesis():
    spec = platform_design_spec(values={"stiffness": "2.627,20", "height": "50,60"},
                                poses=64, chunk_size=3)
    s = run_reference(build_study("platform-design", spec))
    assert s["designs"] == 4 and s["valid"] == 4
    ref = s["reference"]
    assert ref is not None and ref["params"]["stiffness"] == 2.627
    assert ref["params"]["height"] == 60.0
    assert ref["meets_spec"] is True  # Table 3-1's ranges, each within 5 mm and 50 N
    # independently: a k = 20 N/mm design needs far more than 50 N for the 4 mm z range
    stiff = special_6_6(stiffness=20.0)
    T = stiff.home_pose.copy()
    T[2, 3] += 4.0
    assert abs(spring_wrench(stiff, T)[2]) > 50.0
    assert s["meets_spec"] == 2  # the two k = 2.627 designs only
    assert s["best"]["params"]["stiffness"] == 2.627


def test_design_counts_impossible_designs():
    spec = platform_design_spec(values={"base_offset": "28,500"}, poses=8)
    s = run_reference(build_study("platform-design", spec))
    assert s["designs"] == 2 and s["valid"] == 1 and s["invalid_reasons"] == {"InputError": 1}


def test_tolerance_without_errors_is_exact():
    spec = tolerance_spec(samples=40, chunk_size=16, sigma_mount=0, sigma_k=0, sigma_offset=0)
    s = run_reference(build_study("tolerance", spec))
    assert s["samples"] == 40 and s["failed"] == 0
    assert s["force_error"]["max"] < 1e-9 and s["torque_error"]["max"] < 1e-7


def test_tolerance_spring_errors_scale_linearly():
    # with exact geometry the pose is recovered exactly and the wrench error is
    # sum_i dk_i k_i (l_i - l0_i) $_i: linear in the spring errors (same seed, same draws)
    def rms(sigma_k):
        spec = tolerance_spec(samples=40, sigma_mount=0, sigma_k=sigma_k, sigma_offset=0)
        return run_reference(build_study("tolerance", spec))["force_error"]["rms"]

    a, b = rms(0.05), rms(0.10)
    assert a > 0 and b / a == pytest.approx(2.0, rel=1e-6)


def test_tolerance_mounting_errors_give_errors():
    s = run_reference(build_study("tolerance", tolerance_spec(samples=40, sigma_k=0,
                                                               sigma_offset=0)))
    assert s["force_error"]["rms"] > 0.01 and s["failed"] == 0


def test_bad_platform_specs(tmp_path):
    with pytest.raises(InputError, match="exactly one"):
        platform_range_spec(grid=3, samples=5)
    with pytest.raises(InputError, match="at least 2"):
        platform_range_spec(grid=1)
    with pytest.raises(InputError, match="unknown design parameters"):
        platform_design_spec(values={"colour": "1"})
    with pytest.raises(InputError, match="sigma-k"):
        tolerance_spec(sigma_k=-1)
    with pytest.raises(InputError):
        platform_range_spec(str(tmp_path / "missing.toml"), samples=3)
