"""TOML platform files: round trip, schema errors."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.errors import ParseError
from kinestat.io.library import prototype
from kinestat.io.platform_toml import dumps_platform, loads_platform, read_platform, write_platform
from kinestat.parallel.platform import Platform, special_6_6

DESIGN = """
name = "t"
length_unit = "mm"
force_unit = "N"
[design]
kind = "special-6-6"
base_side = 120.0
top_side = 60.0
base_offset = 28.0
top_offset = 14.0
home_height = 60.0
home_twist_deg = -60.0
stiffness = 2.627
"""


def same(a: Platform, b: Platform) -> None:
    for attr in ("base_points", "top_points", "stiffness", "free_lengths", "home_pose"):
        np.testing.assert_allclose(getattr(a, attr), getattr(b, attr), atol=1e-12, err_msg=attr)
    assert a.leg_names == b.leg_names and a.name == b.name
    assert (a.length_unit, a.force_unit) == (b.length_unit, b.force_unit)


def test_design_file_builds_the_prototype():
    same(loads_platform(DESIGN), special_6_6(name="t"))
    assert prototype().design is not None


@pytest.mark.parametrize("plat", [
    prototype(),
    special_6_6(base_side=(120, 110, 100), top_side=(60, 55, 50), base_offset=(20, 30, 25),
                top_offset=(10, 12, 14), height=55, twist=-1.0, stiffness=[1, 2, 3, 4, 5, 6],
                free_lengths=[80, 81, 82, 68, 69, 70], name="custom", length_unit="cm",
                force_unit="kN", leg_names=("a", "b", "c", "d", "e", "f")),
])
def test_round_trip_design_form(plat, tmp_path):
    same(loads_platform(dumps_platform(plat)), plat)
    f = tmp_path / "p.toml"
    write_platform(plat, f, description="round trip")
    same(read_platform(f), plat)


def test_round_trip_explicit_form(tmp_path):
    p = prototype()
    rng = np.random.default_rng(0)
    q = Platform(base_points=p.base_points + rng.normal(size=(6, 3)), top_points=p.top_points,
                 stiffness=p.stiffness * 1.1, free_lengths=p.free_lengths + 1.0,
                 home_pose=p.home_pose, name="explicit")
    text = dumps_platform(q)
    assert "[[legs]]" in text and "[design]" not in text
    same(loads_platform(text, "x.toml"), q)


def test_explicit_free_lengths_default_to_home():
    p = prototype()
    q = Platform(base_points=p.base_points, top_points=p.top_points, stiffness=p.stiffness,
                 free_lengths=p.free_lengths, home_pose=p.home_pose, name="x")
    text = "\n".join(line for line in dumps_platform(q).splitlines()
                     if not line.startswith("free_length"))
    np.testing.assert_allclose(loads_platform(text).free_lengths, p.free_lengths, atol=1e-12)


@pytest.mark.parametrize("edit, field", [
    (lambda s: s.replace('length_unit = "mm"\n', ""), "length_unit"),
    (lambda s: s.replace('"mm"', '"furlong"'), "length_unit"),
    (lambda s: s.replace("base_side = 120.0", 'base_side = "big"'), "design.base_side"),
    (lambda s: s.replace("top_side = 60.0", "top_side = [60.0, 60.0]"), "design.top_side"),
    (lambda s: s + "colour = 1\n", None),
    (lambda s: s.replace("home_height = 60.0\n", ""), "home_height"),
    (lambda s: s.replace("base_offset = 28.0", "base_offset = 60.0").replace(
        "top_offset = 14.0", "top_offset = 30.0"), None),
    (lambda s: s.replace("name = ", "name = [1] #"), None),
])
def test_schema_errors_name_the_place(edit, field):
    with pytest.raises(ParseError) as exc:
        loads_platform(edit(DESIGN), "plat.toml")
    assert exc.value.file == "plat.toml"
    if field is not None:
        assert exc.value.field == field


def test_singular_design_file_explains():
    bad = DESIGN.replace("base_offset = 28.0", "base_offset = 60.0").replace(
        "top_offset = 14.0", "top_offset = 30.0")
    with pytest.raises(ParseError, match="architecturally singular"):
        loads_platform(bad)


def test_both_forms_or_neither_is_an_error(tmp_path):
    with pytest.raises(ParseError, match="exactly one"):
        loads_platform('name = "x"\nlength_unit = "mm"\nforce_unit = "N"\n')
    with pytest.raises(ParseError, match="not valid TOML"):
        loads_platform("name = ")
    with pytest.raises(ParseError, match="cannot read"):
        read_platform(tmp_path / "missing.toml")


def test_binary_file_is_a_parse_error(tmp_path):
    # used to escape as a UnicodeDecodeError traceback
    p = tmp_path / "bin.toml"
    p.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ParseError, match="not a text file"):
        read_platform(p)


def test_unwritable_destination_is_an_input_error(tmp_path):
    from kinestat.errors import InputError

    with pytest.raises(InputError, match="cannot write platform file"):
        write_platform(prototype(), tmp_path / "missing" / "p.toml")
    target = tmp_path / "d"
    target.mkdir()
    with pytest.raises(InputError, match="cannot write platform file"):
        write_platform(prototype(), target)  # a directory
    assert list(tmp_path.iterdir()) == [target]  # the temporary file was removed
