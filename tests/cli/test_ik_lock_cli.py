"""``kinestat ik MODEL --pose ... --all --lock J=VALUE`` and ``--self-motion N`` on a 7-joint arm
(the Panda): solutions re-checked here with the 7-joint model's ``kinestat.fk``."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from tests.urdf_arms import ARMS, arm_path


def _run(capsys, *args, status=0):
    assert main([*map(str, args)]) == status
    return capsys.readouterr()


def _panda():
    return kinestat.load(arm_path("panda"), tip=ARMS["panda"][1]), \
        [arm_path("panda"), "--tip", ARMS["panda"][1]]


def _pose(T):
    return ",".join(f"{v:.17g}" for v in np.asarray(T).ravel())


@pytest.mark.parametrize("joint", ["3", "panda_joint5", "7"])
def test_lock_gives_every_solution_with_the_joint_held(joint, capsys):
    m, args = _panda()
    q = np.array([0.3, 0.5, -0.4, -1.2, 0.2, 0.8, -0.3])
    j = {"3": 2, "panda_joint5": 4, "7": 6}[joint]
    T = kinestat.fk(m, q)
    out = json.loads(_run(capsys, "ik", *args, "--pose", _pose(T), "--all", "--lock",
                          f"{joint}={float(np.degrees(q[j]))!r}", "--json").out)
    qs = np.array([s["q"] for s in out["solutions"]])
    assert len(qs) == out["n_solutions"] >= 1
    np.testing.assert_allclose(kinestat.fk(m, qs), np.broadcast_to(T, (len(qs), 4, 4)),
                               atol=1e-9)
    np.testing.assert_allclose(qs[:, j], q[j], atol=1e-12)
    assert np.min(np.max(np.abs(np.mod(qs - q + np.pi, 2 * np.pi) - np.pi), axis=1)) < 1e-7
    assert out["locked"][0]["index"] == j + 1


def test_self_motion_samples_the_joint_over_its_limits(capsys):
    m, args = _panda()
    T = kinestat.fk(m, np.array([0.3, 0.5, -0.4, -1.2, 0.2, 0.8, -0.3]))
    out = json.loads(_run(capsys, "ik", *args, "--pose", _pose(T), "--all", "--lock", "3",
                          "--self-motion", "5", "--json").out)
    samples = out["self_motion"]["samples"]
    assert [s["value"] for s in samples] == pytest.approx(np.linspace(m.lower[2], m.upper[2], 5))
    qs = np.array([s["q"] for smp in samples for s in smp["solutions"]])
    assert len(qs) == out["n_solutions"] > 0
    np.testing.assert_allclose(kinestat.fk(m, qs), np.broadcast_to(T, (len(qs), 4, 4)),
                               atol=1e-9)
    _run(capsys, "ik", *args, "--pose", _pose(T), "--all", "--lock", "3", "--self-motion", "3")


@pytest.mark.parametrize("extra, message", [
    (["--lock", "9=1"], "neither a joint number"),
    (["--lock", "3"], "expected J=VALUE"),
    (["--lock", "3=1", "--self-motion", "4"], "no value"),
    (["--self-motion", "4"], "needs the joint"),
    (["--lock", "3=1", "--lock", "4=1"], "6 free joints"),
])
def test_lock_errors(extra, message, capsys):
    _, args = _panda()
    err = _run(capsys, "ik", *args, "--pose", "1,0,0,0.3,0,1,0,0,0,0,1,0.5,0,0,0,1", "--all",
               *extra, status=2).err
    assert "kinestat: error:" in err and message in err
