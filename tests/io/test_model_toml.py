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


@pytest.mark.parametrize("text,where", [
    ("notation = 'xyz'\n[[joints]]\n", "notation"),
    ("notation = 'standard_dh'\n", "joints"),
    ("notation = 'standard_dh'\n[[joints]]\ntype = 'ball'\n", "joints[1].type"),
    ("notation = 'standard_dh'\n[[joints]]\nd = 'x'\n", "joints[1].d"),
    ("notation = 'standard_dh'\n[[joints]]\nd = nan\n", "joints[1].d"),
    ("notation = 'standard_dh'\n[[joints]]\nlimits = [1, 0]\n", "joints[1].limits"),
    ("notation = 'standard_dh'\nbase = [[1,0],[0,1]]\n[[joints]]\n", "base"),
    ("notation = 'standard_dh'\n[[joints]]\nd = [\n", None),
])
def test_errors_name_the_field(text, where):
    with pytest.raises(ParseError) as exc:
        loads_model(text, source="bad.toml")
    assert "bad.toml" in str(exc.value)
    if where:
        assert where in str(exc.value)


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
