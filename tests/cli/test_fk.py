"""``kinestat fk`` end to end."""

import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main


def run_json(capsys, *args):
    assert main(list(args)) == 0
    return json.loads(capsys.readouterr().out)


def test_fk_puma762_tool_point(capsys):
    q_deg = [200, 10, 20, 30, 40, 50]
    out = run_json(capsys, "fk", "puma762", "--q-deg", ",".join(map(str, q_deg)),
                   "--tool-point-6", "0,0,235", "--json")
    T = kinestat.fk(kinestat.load("puma762"), np.deg2rad(q_deg))
    np.testing.assert_allclose(out["pose"], T, atol=1e-9)
    np.testing.assert_allclose(out["tool_point"], T[:3, 3] + 235 * T[:3, 2], atol=1e-9)
    np.testing.assert_allclose(out["s6"], T[:3, 2], atol=1e-12)
    np.testing.assert_allclose(out["a67"], T[:3, 0], atol=1e-12)
    assert set(out) >= {"tool_point", "s6", "a67", "pose"}


def test_fk_radians_and_degrees_agree(capsys):
    a = run_json(capsys, "fk", "puma560", "--q", "0.1,0.2,0.3,0.4,0.5,0.6", "--json")
    b = run_json(capsys, "fk", "puma560", "--q-deg",
                 ",".join(str(np.rad2deg(x)) for x in [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]), "--json")
    np.testing.assert_allclose(a["pose"], b["pose"], atol=1e-12)


def test_fk_prismatic_values_are_lengths(capsys):
    out = run_json(capsys, "fk", "nadkarni-config2", "--q-deg", "0,25,8,0,90,0", "--json")
    m = kinestat.load("nadkarni-config2")
    np.testing.assert_allclose(out["pose"], kinestat.fk(m, m.q_home), atol=1e-12)


@pytest.mark.parametrize("args,msg", [
    (["fk", "puma762", "--q-deg", "1,2"], "expected 6"),
    (["fk", "puma762"], "exactly one"),
    (["fk", "nosuchmodel", "--q", "0"], "unknown model"),
    (["fk", "puma762", "--q", "1,2,3,4,5,nan"], "finite"),
])
def test_fk_errors(capsys, args, msg):
    assert main(args) == 2
    assert msg in capsys.readouterr().err


def test_fk_other_models_use_their_own_words(capsys):
    out = run_json(capsys, "fk", "puma560", "--q", "0.1,0.2,0.3,0.4,0.5,0.6", "--json")
    m = kinestat.load("puma560")
    T = kinestat.fk(m, [0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    assert "s6" not in out and "a67" not in out
    np.testing.assert_allclose(out["z_base_end"], T[:3, 2], atol=1e-12)
    np.testing.assert_allclose(out["x_base_end"], T[:3, 0], atol=1e-12)
    assert out["joint_names"] == [j.name for j in m.joints]
    assert main(["fk", "puma560", "--q", "0.1,0.2,0.3,0.4,0.5,0.6"]) == 0
    text = capsys.readouterr().out
    assert "S6" not in text and "a67" not in text
    assert all(j.name in text for j in m.joints)


def test_fk_puma762_human_output_keeps_thesis_words(capsys):
    assert main(["fk", "puma762", "--q-deg", "200,10,20,30,40,50"]) == 0
    text = capsys.readouterr().out
    assert "S6_F" in text and "a67_F" in text


def test_fk_puma762_gives_the_generic_names_and_the_thesis_names(capsys):
    q_deg = [200.0, 20.0, 30.0, 40.0, 50.0, 60.0]
    a = run_json(capsys, "fk", "puma762", "--q-deg", ",".join(map(str, q_deg)),
                 "--tool-offset", "0,0,235", "--json")
    b = run_json(capsys, "fk", "puma762", "--q-deg", ",".join(map(str, q_deg)),
                 "--tool-point-6", "0,0,235", "--json")
    assert a == b  # --tool-point-6 is the thesis's alias of --tool-offset
    T = kinestat.fk(kinestat.load("puma762"), np.radians(q_deg))
    for generic, thesis, col in (("z_base_end", "s6", 2), ("x_base_end", "a67", 0)):
        np.testing.assert_allclose(a[generic], T[:3, col], atol=1e-12)
        assert a[thesis] == a[generic]
    np.testing.assert_allclose(a["tool_point"], T[:3, :3] @ [0, 0, 235.0] + T[:3, 3],
                               atol=1e-9)

