"""TOML model files: round trips and errors."""

import numpy as np
import pytest

import kinestat
from kinestat.errors import ParseError
from kinestat.io.model_toml import dumps_model, loads_model, read_model, write_model


@pytest.mark.parametrize("name", kinestat.list_models())
def test_round_trip_embedded(name, tmp_path, rng):
    m = kinestat.load(name)
    p = tmp_path / "m.toml"
    write_model(m, p)
    m2 = read_model(p)
    assert m2.notation == m.notation and m2.n == m.n
    assert [j.kind for j in m2.joints] == [j.kind for j in m.joints]
    np.testing.assert_allclose(m2.lower, m.lower)
    np.testing.assert_allclose(m2.upper, m.upper)
    np.testing.assert_allclose(m2.q_home, m.q_home, atol=1e-12)
    q = m.q_home + rng.uniform(-1, 1, (10, m.n))
    np.testing.assert_allclose(kinestat.fk(m2, q), kinestat.fk(m, q), atol=1e-10)
    assert dumps_model(m2) == dumps_model(m)


def test_radians_file():
    text = dumps_model(kinestat.load("puma762"), angle_unit="rad")
    m = loads_model(text)
    np.testing.assert_allclose(kinestat.fk(m, np.ones(6)),
                               kinestat.fk(kinestat.load("puma762"), np.ones(6)))



def _refused_naming(text: str, where: str | None) -> None:
    """``text`` is refused with a ParseError naming the file and, when given, ``where``."""
    with pytest.raises(ParseError) as exc:
        loads_model(text, source="bad.toml")
    assert "bad.toml" in str(exc.value)
    if where:
        assert where in str(exc.value)

@pytest.mark.parametrize("text,where", [
    ("notation = 'xyz'\n[[joints]]\n", "notation"),
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "", "joints"),
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[[joints]]\ntype = 'ball'\n", "joints[1].type"),
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[[joints]]\nd = 'x'\n", "joints[1].d"),
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[[joints]]\nd = nan\n", "joints[1].d"),
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[[joints]]\nlimits = [1, 0]\n", "joints[1].limits"),
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "base = [[1,0],[0,1]]\n[[joints]]\n", "base"),
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[[joints]]\nd = [\n", None),
])
def test_errors_name_the_field(text, where):
    _refused_naming(text, where)


def test_unknown_model_name():
    from kinestat.errors import InputError

    with pytest.raises(InputError, match="unknown model"):
        kinestat.load("puma999")


def test_write_is_atomic(tmp_path):
    p = tmp_path / "m.toml"
    p.write_text("old")

    class Bad:
        notation = "chain"
        name = "x"

    with pytest.raises(kinestat.KinestatError):
        write_model(Bad(), p)  # type: ignore[arg-type]
    assert p.read_text() == "old"


_NAD = ("notation = 'nadkarni'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "frame_points = [[0,0,0],[0,0,1],[1,0,0]]\n"
        "[[joints]]\nr = 0\nalpha = 0\na = 1\ntheta = 0\n")


@pytest.mark.parametrize("text,where", [
    # pitch on a revolute joint used to turn it silently into a screw (DH notations) or be
    # dropped (nadkarni); on a prismatic joint it was dropped
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[[joints]]\npitch = 2.0\n", "joints[1].pitch"),
    ("notation = 'modified_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[[joints]]\ntype = 'prismatic'\npitch = 2.0\n",
     "joints[1].pitch"),
    (_NAD + "pitch = 2.0\n", "joints[1].pitch"),
    # keys of another notation used to be ignored without a word
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "frame_points = [[0,0,0],[0,0,1],[1,0,0]]\n[[joints]]\n",
     "frame_points"),
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[hand]\nr = 1\n[[joints]]\n", "hand"),
    ("notation = 'nadkarni'\nq_home = [1.0]\n" + _NAD.split("\n", 1)[1], "q_home"),
    # a scalar q_home used to escape as a TypeError traceback
    ("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "q_home = 5\n[[joints]]\n", "q_home"),
    # degenerate frame points: the message lacked the file
    ("notation = 'nadkarni'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "frame_points = [[0,0,0],[0,0,1],[0,0,2]]\n"
     "[[joints]]\nr = 0\nalpha = 0\na = 1\ntheta = 0\n", None),
])
def test_misplaced_or_malformed_keys_are_refused(text, where):
    _refused_naming(text, where)


def test_screw_joint_with_pitch_still_reads():
    m = loads_model("notation = 'standard_dh'\n"
     "length_unit = 'mm'\nangle_unit = 'deg'\n"
     "[[joints]]\ntype = 'screw'\npitch = 2.0\n")
    T = kinestat.fk(m, [np.pi / 2])
    np.testing.assert_allclose(T[:3, 3], [0, 0, np.pi], atol=1e-12)  # h q along z


def test_binary_file_is_a_parse_error(tmp_path):
    p = tmp_path / "bin.toml"
    p.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ParseError, match="not a text file"):
        read_model(p)


def test_unwritable_destination_is_an_input_error(tmp_path):
    from kinestat.errors import InputError

    m = kinestat.load("puma560")
    with pytest.raises(InputError, match="cannot write model file"):
        write_model(m, tmp_path / "no" / "such" / "dir" / "m.toml")
    target = tmp_path / "d"
    target.mkdir()
    with pytest.raises(InputError, match="cannot write model file"):
        write_model(m, target)  # a directory: the temporary file is made beside it
    assert list(tmp_path.iterdir()) == [target]  # and removed again


@pytest.mark.parametrize("missing", ["angle_unit", "length_unit"])
def test_a_model_without_units_is_refused_naming_the_key(missing):
    # alpha = 1.5707963 used to be read silently as 1.57 degrees, and lengths as millimetres
    units = {"angle_unit": "angle_unit = 'rad'\n", "length_unit": "length_unit = 'm'\n"}
    text = ("notation = 'standard_dh'\n" + "".join(v for k, v in units.items() if k != missing)
            + "[[joints]]\nalpha = 1.5707963\na = 0.3\n")
    with pytest.raises(ParseError, match=f"missing '{missing}'.*add a line such as {missing}") \
            as exc:
        loads_model(text, source="arm.toml")
    assert exc.value.field == missing and "arm.toml" in str(exc.value)


def test_explicit_radians_are_read_as_radians():
    m = loads_model("notation = 'standard_dh'\nangle_unit = 'rad'\nlength_unit = 'm'\n"
                    "[[joints]]\nalpha = 1.5707963\na = 0.3\n")
    T = kinestat.fk(m, np.zeros(1))
    np.testing.assert_allclose(T[:3, :3], [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-7)
    assert m.length_unit == "m"
