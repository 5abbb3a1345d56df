"""``kinestat platform decompose`` end to end."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.cli.main import main
from kinestat.io.library import prototype
from kinestat.parallel._refine import apply_twist
from kinestat.parallel.kinestatic import DELTA, decompose_twist


def csv(x):
    return ",".join(repr(float(v)) for v in np.ravel(x))


def run_json(capsys, *args):
    assert main(["platform", *args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_decompose_uses_the_stiffness_the_stiffness_command_reports(capsys):
    p = prototype()
    pose = apply_twist(p.home_pose, np.r_[0.03, -0.02, 0.05, 1.0, -1.5, -2.0])
    w0 = np.r_[2.0, -1.0, -8.0, 40.0, 25.0, -10.0]
    contacts = [np.r_[0, 0, 1.0, 0, 0, 0], np.r_[1.0, 0, 0, 0, 60.0, 0]]
    T = np.r_[0.01, -0.02, 0.005, 1.0, 2.0, 3.0]
    K = np.array(run_json(capsys, "stiffness", "--pose", csv(pose), "--wrench", csv(w0),
                          "--twist-order", "axis")["stiffness"])
    args = ["decompose", "--pose", csv(pose), "--wrench", csv(w0), "--twist", csv(T)]
    for c in contacts:
        args += ["--contact", csv(c)]
    out = run_json(capsys, *args)
    assert set(out) >= {"freedom", "compliance", "lambda"}
    W = np.stack(contacts, axis=1)
    ref = decompose_twist(K, W, T)
    np.testing.assert_allclose(out["freedom"], ref.freedom, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(out["compliance"], ref.compliance, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(out["lambda"], ref.lam, rtol=1e-9)
    assert len(out["lambda"]) == 2 and out["twist_order"] == "axis"
    np.testing.assert_allclose(np.add(out["freedom"], out["compliance"]), T, atol=1e-12)
    assert np.abs(W.T @ DELTA @ np.array(out["freedom"])).max() <= 1e-12 * np.linalg.norm(T) * 60
    np.testing.assert_allclose(out["wrench_change"], W @ np.array(out["lambda"]))


def test_decompose_human_table(capsys):
    assert main(["platform", "decompose", "--contact", "0,0,1,0,0,0", "--twist",
                 "0.01,0,0,1,2,3"]) == 0
    text = capsys.readouterr().out
    assert "freedom T_f" in text and "compliance T_c" in text and "lambda =" in text
    assert "[w; v_O]" in text


@pytest.mark.parametrize("args, message", [
    (["--contact", "0,0,1,0,0,0", "--contact", "0,0,2,0,0,0"], "linearly dependent"),
    (["--contact", "0,0,1,0,0"], "expected 6"),
    (["--contact", "1,0,0,0,0,0"] * 7, "1 to 6"),
    (["--contact", "0,0,1,0,0,0", "--wrench", "0,0,1"], "--wrench"),
    (["--contact", "0,0,1,0,0,0", "--pose", "1,2,3"], "--pose"),
])
def test_decompose_errors_are_one_line(capsys, args, message):
    assert main(["platform", "decompose", "--twist", "0,0,0,1,0,0", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err and err.startswith("kinestat: error:")


def test_decompose_six_contacts_hold_the_tool_fast(capsys):
    """Six independent contact wrenches: no twist of freedom, the whole twist is compliance."""
    args = ["platform", "decompose", "--twist", "0.01,0.02,0,1,0,2", "--json"]
    for row in np.eye(6):
        args += ["--contact", ",".join(str(v) for v in row)]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert np.allclose(out["freedom"], 0.0, atol=1e-12)
    assert np.allclose(out["compliance"], [0.01, 0.02, 0, 1, 0, 2], atol=1e-12)
    assert len(out["lambda"]) == 6
