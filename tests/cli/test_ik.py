"""``kinestat ik``: PUMA 762 closed form and numerical IK from the command line."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.robots.puma762 import closed_form as P

APPENDIX_C = ["--tool-point", "725,190,650", "--s6", "1,0,0", "--a67", "0,0,1"]


def csv(v):
    return ",".join(str(float(x)) for x in np.ravel(v))


def run_json(capsys, args):
    rc = main(args)
    out = capsys.readouterr()
    assert rc == 0, out.err
    return json.loads(out.out)


def test_closed_form_json_appendix_c(capsys):
    data = run_json(capsys, ["ik", "puma762", *APPENDIX_C, "--json"])
    assert len(data["solutions"]) == 6 and len(data["singular_families"]) == 1
    target = P.frame6([725, 190, 650], [1, 0, 0], [0, 0, 1])
    q = np.radians([s["q_deg"] for s in data["solutions"]])
    assert np.allclose(P.forward(q).pose, target, atol=1e-9)
    for s in data["solutions"]:
        assert isinstance(s["within_limits"], bool)
        assert math.isclose(s["axis_deg"][0], s["q_deg"][0] + 180.0)
    fam = data["singular_families"][0]
    assert fam["kind"] == "sum" and abs(abs(fam["theta5_deg"]) - 180) < 1e-9
    rep = np.radians(fam["representative_q_deg"])
    assert np.allclose(P.forward(rep).pose, target, atol=1e-9)
    assert "selected" not in data


def test_closed_form_selection(capsys):
    cur = "-140,5,0,-30,80,0"
    data = run_json(capsys, ["ik", "puma762", *APPENDIX_C, "--current-deg", cur, "--json"])
    sel = data["selected"]
    assert sel is not None
    # the selected angles reach the pose and sit within the axis limits
    q = np.radians(sel["q_deg"])
    assert np.allclose(P.forward(q).pose, P.frame6([725, 190, 650], [1, 0, 0], [0, 0, 1]),
                       atol=1e-9)
    lim = np.asarray(data["axis_limits_deg"])
    assert np.all((np.array(sel["axis_deg"]) >= lim[:, 0]) & (np.array(sel["axis_deg"])
                                                               <= lim[:, 1]))
    # the same through axis angles
    axis_cur = ",".join(str(v) for v in P.to_axis_angles(np.radians([-140, 5, 0, -30, 80, 0]))
                        * 180 / math.pi)
    data2 = run_json(capsys, ["ik", "puma762", *APPENDIX_C, "--current-axis-deg", axis_cur,
                              "--json"])
    assert np.allclose(data2["selected"]["axis_deg"], sel["axis_deg"])


def test_closed_form_table_output(capsys):
    assert main(["ik", "puma762", *APPENDIX_C, "--current-deg", "-140,5,0,-30,80,0"]) == 0
    out = capsys.readouterr().out
    assert "6 isolated" in out and "family" in out and "selected" in out


def test_tool_point_6_and_normalize(capsys):
    q = np.radians([100.0, 20.0, 30.0, 40.0, 50.0, 60.0])
    f = P.forward(q, [0.0, 0.0, 235.0])
    s6 = f.s6 * 3.0  # not unit: needs --normalize
    args = ["ik", "puma762", "--tool-point", csv(f.tool_point),
            "--s6", csv(s6), "--a67", csv(f.a67),
            "--tool-point-6", "0,0,235", "--json"]
    assert main(args) == 2
    assert "unit" in capsys.readouterr().err
    data = run_json(capsys, args + ["--normalize"])
    sols = np.radians([s["q_deg"] for s in data["solutions"]])
    d = np.max(np.abs((sols - q + math.pi) % (2 * math.pi) - math.pi), axis=1)
    assert d.min() < 1e-9


def test_numerical_from_fk_json_file(capsys, tmp_path):
    assert main(["fk", "puma762", "--q-deg", "200,20,30,40,50,60", "--json"]) == 0
    path = tmp_path / "pose.json"
    path.write_text(capsys.readouterr().out)
    data = run_json(capsys, ["ik", "puma762", "--pose", str(path), "--q0-deg",
                             "190,10,20,30,40,50", "--json"])
    assert data["success"] is True
    m = kinestat.load("puma762")
    T = kinestat.fk(m, np.asarray(data["q"]))
    ref = kinestat.fk(m, np.radians([200, 20, 30, 40, 50, 60]))
    assert np.max(np.abs(T - ref)) < 1e-6
    assert np.allclose(np.radians(data["q_deg"]), data["q"])
    assert data["position_error"] <= 1e-9 * 1565 * 1.01 and data["rotation_error"] <= 1e-9


def test_numerical_pose_as_16_numbers(capsys):
    m = kinestat.load("puma560")
    q = m.q_home + 0.2
    T = kinestat.fk(m, q)
    data = run_json(capsys, ["ik", "puma560", "--pose", csv(T.ravel()),
                             "--json"])
    assert data["success"] is True
    assert np.max(np.abs(kinestat.fk(m, np.asarray(data["q"])) - T)) < 1e-6


def test_numerical_failure_exits_nonzero(capsys):
    far = np.eye(4)
    far[0, 3] = 5000.0
    rc = main(["ik", "puma762", "--pose", csv(far.ravel()), "--restarts", "1",
               "--max-iter", "20", "--json"])
    out = capsys.readouterr()
    assert rc == 2
    assert json.loads(out.out)["success"] is False
    assert "did not reach" in out.err


@pytest.mark.parametrize(
    "args, words",
    [
        (["ik", "puma762", "--tool-point", "0,0,200", "--s6", "1,0,0", "--a67", "0,0,1"],
         "φ1"),
        (["ik", "puma762", "--tool-point", "3000,0,0", "--s6", "1,0,0", "--a67", "0,0,1"],
         "too far"),
        (["ik", "puma762", "--tool-point", "725,190,650", "--s6", "1,0,0"], "--a67"),
        (["ik", "puma762", "--tool-point", "725,190,650", "--s6", "1,0,0", "--a67", "0,1,1"],
         "unit"),
        (["ik", "puma560", *APPENDIX_C], "only for puma762"),
        (["ik", "puma762", *APPENDIX_C, "--pose", "1,2"], "not both"),
        (["ik", "puma762"], "--pose"),
        (["ik", "nosuchmodel", "--pose", "1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1"], "unknown model"),
        (["ik", "puma762", "--pose", "1,2,3"], "16"),
        (["ik", "puma762", "--pose", "2,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1"], "rigid"),
        (["ik", "puma762", *APPENDIX_C, "--limits", "foo"], "--limits"),
        (["ik", "puma762", *APPENDIX_C, "--current-deg", "1,2,3"], "current-deg"),
    ],
)
def test_errors_are_clean(capsys, args, words):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("kinestat: error:") and words in err


def test_pose_json_file_errors(capsys, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert main(["ik", "puma762", "--pose", str(bad)]) == 2
    assert "JSON" in capsys.readouterr().err
    nokey = tmp_path / "nokey.json"
    nokey.write_text(json.dumps({"q": [1, 2]}))
    assert main(["ik", "puma762", "--pose", str(nokey)]) == 2
    assert "pose" in capsys.readouterr().err
    assert main(["ik", "puma762", "--pose", str(tmp_path / "missing.json")]) == 2
    assert "does not exist" in capsys.readouterr().err


@pytest.mark.parametrize("args, words", [
    (["--restarts", "-1"], "--restarts must be 0 or more"),
    (["--max-iter", "0"], "--max-iter must be at least 1"),
])
def test_numerical_budget_options_are_named(capsys, args, words):
    # the message used to come from the library: "max_iter must be at least 1 and restarts ..."
    assert main(["ik", "puma762", "--pose", csv(np.eye(4)), *args]) == 2
    assert words in capsys.readouterr().err


def test_fk_then_closed_form_ik_round_trip_through_the_cli(capsys):
    q_deg = np.array([150.0, 30.0, 40.0, 20.0, 60.0, 30.0])
    p6 = "10,-20,235"
    fk = run_json(capsys, ["fk", "puma762", "--q-deg", csv(q_deg), "--tool-point-6", p6,
                           "--json"])
    out = run_json(capsys, ["ik", "puma762", "--tool-point", csv(fk["tool_point"]),
                            "--s6", csv(fk["s6"]), "--a67", csv(fk["a67"]),
                            "--tool-point-6", p6, "--json"])
    diffs = [np.abs((np.array(s["q_deg"]) - q_deg + 180.0) % 360.0 - 180.0).max()
             for s in out["solutions"]]
    assert min(diffs) < 1e-7
    m = kinestat.load("puma762")
    for s in out["solutions"]:  # every solution reproduces the fk pose (generic chain)
        np.testing.assert_allclose(kinestat.fk(m, np.radians(s["q_deg"])), fk["pose"],
                                   atol=1e-8)
