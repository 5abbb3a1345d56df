"""Your own tool and mount (issue 42): ``--tool-offset`` (P_tool_6), ``--a67`` and ``--mount``
reach the controller's model AND the simulated cell, so a run with another tool converges."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from kinestat.app.calibrations import resolve_mount
from kinestat.app.control_run import ControlRequest, SimulatedCell, prepare_control
from kinestat.app.sim_cell import InProcessIO, start_counts
from kinestat.cli.main import main
from kinestat.control.controller import THESIS_FORCE_DIRECTION
from kinestat.control.log import CycleLog
from kinestat.control.loop import run
from kinestat.errors import KinestatError
from kinestat.io.library import prototype
from kinestat.io.platform_toml import read_mount_file
from kinestat.robots.puma762 import closed_form as puma762
from kinestat.spatial.transforms import apply

START = np.array([-400.0, 800.0, -100.0])
TOOL = np.array([12.0, -8.0, 200.0])
A67 = np.array([0.0, 1.0, 0.0])  # perpendicular to the thesis's F_req direction (y = 0)


def _platform_file(tmp_path, mount_table: str) -> str:
    from importlib import resources

    text = (resources.files("kinestat.data") / "platforms" / "prototype-2011.toml").read_text()
    path = tmp_path / "platform.toml"
    path.write_text(text + "\n[mount]\n" + mount_table)
    return str(path)


def test_a_platform_files_mount_puts_the_base_centroid_on_s6_at_its_offset(tmp_path):
    path = _platform_file(tmp_path, "offset = 5.0\nturn_deg = 20.0\n")
    plat, _ = read_mount_file(path)
    M, source = resolve_mount(path, plat)
    assert source == path
    centroid = plat.base_points[:3].mean(axis=0)  # the base triangle O0 P0 Q0
    np.testing.assert_allclose(apply(M, centroid), [0.0, 0.0, 5.0], atol=1e-12)
    t = math.radians(20.0)
    np.testing.assert_allclose(M[:3, 0], [math.cos(t), math.sin(t), 0.0], atol=1e-12)
    # --platform with the same file gives it as the default mount
    M2, _ = resolve_mount(None, plat, path)
    np.testing.assert_allclose(M2, M)


@pytest.fixture(scope="module")
def other_tool_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("tool")
    path = _platform_file(tmp, "offset = 5.0\nturn_deg = 20.0\n")
    req = ControlRequest(force=4.0 * THESIS_FORCE_DIRECTION, start_tool_point=START,
                         cell=SimulatedCell(ideal_sensor=True), tool_point_6=TOOL, a67=A67,
                         mount=path)
    prep = prepare_control(req)
    io = InProcessIO(prep.cell, prep.sensor, start_counts=start_counts(prep.config))
    with CycleLog(tmp / "log.jsonl") as log:
        rep = run(prep.config, io, log)
    recs = [json.loads(line) for line in (tmp / "log.jsonl").read_text().splitlines()]
    return prep, rep, io, recs


def test_the_simulated_cell_carries_the_requested_tool_and_mount(other_tool_run):
    prep, _, _, _ = other_tool_run
    np.testing.assert_allclose(prep.cell.tool_point_6, TOOL, atol=1e-9)
    np.testing.assert_allclose(prep.config.model.tool_point_6, TOOL)
    np.testing.assert_allclose(prep.cell.mount, prep.config.model.mount)


def test_another_tool_converges_on_the_true_force(other_tool_run):
    prep, rep, io, recs = other_tool_run
    assert rep.converged, rep.stop_reason
    assert abs(rep.true_force_magnitude - 4.0) <= prep.config.force_tol
    assert rep.axis_error_deg < 0.5
    # the start pose realises the request: the robot's own forward analysis with the tool
    # puts P_tool_6 on the start point with a67 along --a67 (to the axes' resolution)
    first = next(r for r in recs if r["type"] == "cycle")
    q = np.radians(first["measured"]["joints_deg"])
    fwd = puma762.forward(q, TOOL)
    np.testing.assert_allclose(fwd.tool_point, START, atol=0.1)
    assert np.degrees(np.arccos(np.clip(fwd.a67 @ A67, -1, 1))) < 0.1
    # the measured tip is the simulator's, the moment about it vanishes
    np.testing.assert_allclose(rep.tip, io.truth()["tip"], atol=5e-3)
    assert np.linalg.norm(rep.torque_about_tip) <= 0.05


@pytest.mark.parametrize(("args", "message"), [
    (["--a67", "1,0,0"], "--a67 must be perpendicular"),
    (["--a67", "0,0,0"], "--a67 must be 3 finite numbers"),
    (["--tool-offset", "1,2"], "--tool-offset: expected 3"),
    (["--mount", "2,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1"], "--mount is not a rigid pose"),
    (["--mount", "1,2,3"], "--mount: expected 16"),
])
def test_bad_tool_and_mount_are_refused_before_anything_starts(tmp_path, capsys, args,
                                                               message):
    log = tmp_path / "run" / "log.jsonl"
    assert main(["control", "--log", str(log), "--no-plot", *args]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("error") == 1, err
    assert not log.exists()


def test_a_platform_file_without_a_mount_is_refused_as_mount(tmp_path):
    from importlib import resources

    path = tmp_path / "p.toml"
    path.write_text((resources.files("kinestat.data") / "platforms"
                     / "prototype-2011.toml").read_text())
    with pytest.raises(KinestatError, match=r"no \[mount\] table"):
        resolve_mount(str(path), prototype())
    bad = _platform_file(tmp_path, "offset = 1.0\npose = [[1,0,0,0],[0,1,0,0],[0,0,1,0],"
                                   "[0,0,0,1]]\n")
    with pytest.raises(KinestatError, match="either pose or offset"):
        resolve_mount(bad, prototype())


def test_a_pose_typed_to_four_decimals_is_made_rigid():
    c, s = 0.7071, 0.7071
    T = np.array([[c, -s, 0, 1.0], [s, c, 0, 2.0], [0, 0, 1, 3.0], [0, 0, 0, 1]])
    M, source = resolve_mount(T, prototype())
    assert source == "pose"
    np.testing.assert_allclose(M[:3, :3] @ M[:3, :3].T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(M[:3, 3], [1.0, 2.0, 3.0])
