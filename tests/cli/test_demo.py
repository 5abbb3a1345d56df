"""``kinestat demo`` runs end to end and its numbers are consistent."""

import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.io.library import prototype
from kinestat.parallel import leg_lengths
from kinestat.robots.puma762 import closed_form as puma762


def test_demo_json(capsys):
    assert main(["demo", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["illustration1"]["screws"]) == 2
    assert len(out["illustration2"]["joints"]) == 7
    # every PUMA solution reproduces the Appendix C pose
    for q in np.deg2rad(out["puma762_appendix_c"]["solutions_deg"]):
        f = puma762.forward(q)
        np.testing.assert_allclose(f.tool_point, [725, 190, 650], atol=1e-6)
        np.testing.assert_allclose(f.s6, [1, 0, 0], atol=1e-9)
    # platform modes come in mirror pairs and reproduce the legs
    legs = [79.6804, 81.8285, 81.2669, 68.6500, 67.2037, 68.2854]
    poses = np.array(out["platform_appendix_b"]["poses"])
    assert out["platform_appendix_b"]["modes"] % 2 == 0
    expected = np.broadcast_to(legs, (len(poses), 6))
    np.testing.assert_allclose(leg_lengths(prototype(), poses), expected, atol=1e-9)


def test_demo_human(capsys):
    assert main(["demo"]) == 0
    text = capsys.readouterr().out
    assert "Illustration 2" in text and "assembly modes" in text
    assert kinestat.__version__


def test_demo_states_each_wrist_family_relation_correctly(capsys, monkeypatch):
    # A "difference" family (θ5 = 0) fixes θ6 − θ4; the demo used to print it as θ4 − θ6.
    # Feed the demo a pose at θ5 = 0 and check the printed value against the generating q.
    import re

    q_deg = np.array([150.0, 30.0, 40.0, 20.0, 0.0, 50.0])
    f = puma762.forward(np.radians(q_deg))
    real = puma762.reverse
    monkeypatch.setattr(puma762, "reverse",
                        lambda *a, **k: real(f.tool_point, f.s6, f.a67))
    assert main(["demo"]) == 0
    text = capsys.readouterr().out
    m = re.search(r"wrist-singular family: (θ\d [+−] θ\d) = (-?[\d.]+)°", text)
    assert m is not None
    a, op, b = m.group(1).split()
    val = {"θ4": q_deg[3], "θ6": q_deg[5]}
    expected = val[a] + val[b] if op == "+" else val[a] - val[b]
    assert (float(m.group(2)) - expected + 180) % 360 - 180 == pytest.approx(0, abs=1e-3)
