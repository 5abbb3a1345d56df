"""``kinestat dh-from-axes`` end to end."""

import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.io.model_toml import read_model
from kinestat.serial.fk import joint_axes

# A 3R arm given by hand: a vertical waist axis, shoulder and elbow axes horizontal (parallel),
# 300 above the floor and 400 apart, and a tool point 100 beyond the elbow. The DH geometry is
# known by inspection: a = (0, 400, 100), |α1| = 90°, α2 = α3 = 0.


def arm_doc():
    return {
        "name": "demo",
        "length_unit": "mm",
        "tool": [[1, 0, 0, 500], [0, 1, 0, 0], [0, 0, 1, 300], [0, 0, 0, 1]],
        "axes": [
            {"point": [0, 0, 0], "direction": [0, 0, 1]},
            {"name": "shoulder", "point": [0, 7, 300], "direction": [0, -2, 0]},
            {"plucker": [0.0, -1.0, 0.0, *map(float, np.cross([400, 0, 300], [0, -1, 0]))]},
        ],
    }


def to_toml(doc):
    import tomli_w

    return tomli_w.dumps(doc)


def run_json(capsys, *args):
    assert main(list(args)) == 0
    return json.loads(capsys.readouterr().out)


@pytest.fixture
def arm_file(tmp_path):
    p = tmp_path / "arm.toml"
    p.write_text(to_toml(arm_doc()))
    return p


def test_table_of_a_hand_made_arm(capsys, arm_file):
    out = run_json(capsys, "dh-from-axes", str(arm_file), "--json")
    t = out["table"]
    assert [r["joint"] for r in t] == ["1", "shoulder", "3"]
    np.testing.assert_allclose([r["a"] for r in t], [0, 400, 100], atol=1e-9)
    np.testing.assert_allclose([abs(r["alpha_deg"]) for r in t], [90, 0, 0], atol=1e-9)
    assert [r["relation"] for r in t] == ["intersecting", "parallel", "parallel"]
    assert t[1]["d"] == 0.0  # parallel axes: x_2 through o_1
    # frame 0: z along the waist axis, origin on it
    B = np.array(out["base"])
    np.testing.assert_allclose(B[:3, 2], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(B[:2, 3], [0, 0], atol=1e-12)
    assert out["length_unit"] == "mm" and out["model_file"] is None


def test_radians_and_degrees_agree(capsys, arm_file):
    a = run_json(capsys, "dh-from-axes", str(arm_file), "--json")
    b = run_json(capsys, "dh-from-axes", str(arm_file), "--json", "--rad")
    for ra, rb in zip(a["table"], b["table"], strict=True):
        assert np.deg2rad(ra["theta_deg"]) == pytest.approx(rb["theta"], abs=1e-12)
        assert np.deg2rad(ra["alpha_deg"]) == pytest.approx(rb["alpha"], abs=1e-12)


def test_write_model_round_trips_the_axes(capsys, arm_file, tmp_path):
    out_model = tmp_path / "demo-model.toml"
    out = run_json(capsys, "dh-from-axes", str(arm_file), "--json", "--write-model",
                   str(out_model))
    assert out["model_file"] == str(out_model)
    m = read_model(out_model)
    assert m.notation == "standard_dh" and m.name == "demo" and m.length_unit == "mm"
    u, rho = joint_axes(m, np.zeros(3))
    np.testing.assert_allclose(u, [[0, 0, 1], [0, -1, 0], [0, -1, 0]], atol=1e-12)
    np.testing.assert_allclose(rho, [[0, 0, 0], [0, 0, 300], [400, 0, 300]], atol=1e-9)
    np.testing.assert_allclose(kinestat.fk(m, np.zeros(3)), arm_doc()["tool"], atol=1e-9)


def test_json_file_and_human_table(capsys, tmp_path):
    p = tmp_path / "arm.json"
    p.write_text(json.dumps(arm_doc()))
    assert main(["dh-from-axes", str(p)]) == 0
    text = capsys.readouterr().out
    assert "Standard DH table" in text and "shoulder" in text and "400.0000" in text
    assert "θ (deg)" in text


def test_puma560_axes_file(capsys, tmp_path, rng):
    """Axes of the embedded PUMA 560 at a random configuration, written as a file, give a model
    that moves like the PUMA."""
    m = kinestat.load("puma560")
    q0 = rng.uniform(-1, 1, 6)
    u, rho = joint_axes(m, q0)
    doc = {"length_unit": "m", "base": m.base.tolist(), "tool": kinestat.fk(m, q0).tolist(),
           "axes": [{"point": p.tolist(), "direction": d.tolist()}
                    for p, d in zip(rho, u, strict=True)]}
    f = tmp_path / "puma.json"
    f.write_text(json.dumps(doc))
    out_model = tmp_path / "puma-dh.toml"
    out = run_json(capsys, "dh-from-axes", str(f), "--json", "--write-model", str(out_model))
    np.testing.assert_allclose([r["a"] for r in out["table"]], m.parameters[:, 2], atol=1e-12)
    np.testing.assert_allclose([r["d"] for r in out["table"]], m.parameters[:, 1], atol=1e-12)
    rec = read_model(out_model)
    q = rng.uniform(-3, 3, (10, 6))
    np.testing.assert_allclose(kinestat.fk(rec, q - q0), kinestat.fk(m, q), atol=1e-9)


@pytest.mark.parametrize("body, msg", [
    ('[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 0]\n', "zero vector"),
    ('[[axes]]\npoint = [0, 0]\ndirection = [0, 0, 1]\n', "axes[1].point"),
    ('[[axes]]\ndirection = [0, 0, 1]\n', "missing 'point'"),
    ('[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 1]\ntype = "ball"\n', "unknown joint type"),
    ('[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 1]\ntype = "screw"\n', "non-zero pitch"),
    ('[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 1]\ncolour = 1\n', "unknown keys"),
    ('[[axes]]\nplucker = [0, 0, 1, 1, 0, 1]\n', "Plücker"),
    ('name = "x"\n', "at least one [[axes]]"),
    ('length_unit = "mm"\n'
     'tool = [[1, 0], [0, 1]]\n[[axes]]\npoint = [0,0,0]\ndirection = [0,0,1]\n', "4x4"),
    ('[[axes]\n', "not valid TOML"),
    ('length_unit = "mm"\n'
     'base = [[1,0,0,0.5],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n[[axes]]\npoint = [0,0,0]\n'
     'direction = [0,0,1]\n', "origin"),
])
def test_errors_are_clean(capsys, tmp_path, body, msg):
    p = tmp_path / "bad.toml"
    p.write_text(body)
    assert main(["dh-from-axes", str(p)]) == 2
    err = capsys.readouterr().err
    assert msg in err and "Traceback" not in err


def test_missing_file_and_bad_json(capsys, tmp_path):
    assert main(["dh-from-axes", str(tmp_path / "nope.toml")]) == 2
    assert "cannot read" in capsys.readouterr().err
    p = tmp_path / "bad.json"
    p.write_text('{"axes": [\n  {"point": [0, 0, 0],}\n]}')
    assert main(["dh-from-axes", str(p)]) == 2
    assert "line 2" in capsys.readouterr().err


_AXIS = 'length_unit = "mm"\n[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 1]\n'


@pytest.mark.parametrize("body, where", [
    # Plücker problems used to be reported as "joint axis [1]" (0-based) with no file or field
    (_AXIS + '[[axes]]\nplucker = [0, 0, 0, 0, 1, 0]\n', ", field axes[2].plucker"),
    (_AXIS + '[[axes]]\nplucker = [0, 0, 1, 0, 0, 1]\n', ", field axes[2].plucker"),
    # errors found by the algorithm (base off axis 1, non-rigid tool) used to lack the file
    ('base = [[1,0,0,5],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n' + _AXIS, ": base"),
    ('tool = [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n' + _AXIS, ": tool"),
])
def test_errors_name_file_and_field(capsys, tmp_path, body, where):
    p = tmp_path / "bad.toml"
    p.write_text(body)
    assert main(["dh-from-axes", str(p)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"kinestat: error: {p}{where}") and len(err.splitlines()) == 1


def test_binary_file_and_unwritable_model_are_clean(capsys, tmp_path):
    # both used to end in a Python traceback (UnicodeDecodeError, FileNotFoundError)
    p = tmp_path / "bin.toml"
    p.write_bytes(b"\xff\xfe\x00")
    assert main(["dh-from-axes", str(p)]) == 2
    assert "not a text file" in capsys.readouterr().err
    good = tmp_path / "arm.toml"
    good.write_text(_AXIS)
    out = tmp_path / "no" / "dir" / "m.toml"
    assert main(["dh-from-axes", str(good), "--write-model", str(out)]) == 2
    assert "cannot write model file" in capsys.readouterr().err
    assert not out.parent.exists()


def test_bad_tol_option_names_the_option(capsys, tmp_path):
    p = tmp_path / "arm.toml"
    p.write_text(_AXIS)
    assert main(["dh-from-axes", str(p), "--tol", "-1"]) == 2
    assert "--tol must be" in capsys.readouterr().err


def test_an_axes_file_without_a_length_unit_is_refused(tmp_path, capsys):
    p = tmp_path / "axes.toml"
    p.write_text('[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 1]\n')
    assert main(["dh-from-axes", str(p)]) == 2
    err = capsys.readouterr().err
    assert "missing 'length_unit'" in err and "axes.toml" in err and len(err.splitlines()) == 1
