"""Regressions of the bad-input campaign (issue 11): each input used to escape as a bare
OverflowError, ValueError, RecursionError or TypeError, or (URDF cycles) never to end. Each
must now be a ParseError naming the file and, where there is one, the field."""

from __future__ import annotations

import json
import re
import signal
import textwrap

import numpy as np
import pytest

from kinestat.errors import ParseError
from kinestat.io import (
    from_urdf,
    loads_model,
    loads_platform,
    read_axes_file,
    read_model,
    read_pose_file,
    read_urdf,
)
from kinestat.io.textfile import parse_json, parse_toml, read_text_file

HUNDREDS = "1" + "0" * 400  # beyond a float (about 309 digits)
THOUSANDS = "9" * 5000  # beyond Python's 4300-digit int-from-string limit
DEEP = 100_000

MODEL = textwrap.dedent("""\
    name = "arm"
    notation = "standard_dh"
    length_unit = "m"
    angle_unit = "deg"
    [[joints]]
    theta = 0.0
    d = 0.5
    a = {a}
    alpha = 90.0
    limits = [-90.0, {hi}]
    """)
PLATFORM = textwrap.dedent("""\
    length_unit = "mm"
    force_unit = "N"
    [design]
    base_side = 120.0
    top_side = 60.0
    base_offset = 28.0
    top_offset = 14.0
    home_height = {h}
    stiffness = 2.627
    """)


@pytest.fixture
def no_hang():
    """Fail (instead of hanging the suite) if the test takes more than 20 s."""
    def boom(signum, frame):
        raise AssertionError("took longer than 20 s: the reader does not terminate")

    old = signal.signal(signal.SIGALRM, boom)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


def test_the_seed_documents_are_valid():
    # the regressions below change one value of these documents
    assert loads_model(MODEL.format(a="0.1", hi="90.0")).n == 1
    assert loads_platform(PLATFORM.format(h="60.0")).name == "<string>"


# ------------------------------------------------------------------ integers beyond a float

@pytest.mark.parametrize("a, hi, field", [(HUNDREDS, "90.0", "joints[1].a"),
                                          ("0.1", HUNDREDS, "joints[1].limits"),
                                          ("-" + HUNDREDS, "90.0", "joints[1].a")])
def test_model_integer_of_hundreds_of_digits(a, hi, field):
    with pytest.raises(ParseError, match=r"arm\.toml, field " + re.escape(field)) as ei:
        loads_model(MODEL.format(a=a, hi=hi), source="arm.toml")
    assert ei.value.field == field and ei.value.file == "arm.toml"


def test_platform_integer_of_hundreds_of_digits():
    with pytest.raises(ParseError, match="401 digits") as ei:
        loads_platform(PLATFORM.format(h=HUNDREDS), source="p.toml")
    assert ei.value.field == "design.home_height"


@pytest.mark.parametrize("body, field", [
    ('[[axes]]\npoint = [0, 0, {n}]\ndirection = [0, 0, 1]\n', "axes[1].point[2]"),
    ('length_unit = "mm"\ntol = {n}\n[[axes]]\npoint = [0, 0, 0]\ndirection = [0, 0, 1]\n',
     "tol"),
])
def test_axes_integer_of_hundreds_of_digits(tmp_path, body, field):
    p = tmp_path / "axes.toml"
    p.write_text(body.format(n=HUNDREDS))
    with pytest.raises(ParseError) as ei:
        read_axes_file(p)
    assert ei.value.field == field and ei.value.file == str(p)


@pytest.mark.parametrize("name, text", [
    ("pose.json", json.dumps({"pose": [[1, 0, 0, int(HUNDREDS)], [0, 1, 0, 0], [0, 0, 1, 0],
                                       [0, 0, 0, 1]]})),
    ("pose.toml", f"pose = [[1, 0, 0, {HUNDREDS}], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]"),
])
def test_pose_integer_of_hundreds_of_digits(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    with pytest.raises(ParseError, match="too large") as ei:
        read_pose_file(p)
    assert ei.value.file == str(p)


# ------------------------------------------------ integers beyond the 4300-digit conversion

def test_model_integer_of_5000_digits():
    with pytest.raises(ParseError, match="too many digits") as ei:
        loads_model(MODEL.format(a=THOUSANDS, hi="90.0"), source="arm.toml")
    assert ei.value.file == "arm.toml"


@pytest.mark.parametrize("name, text", [
    ("pose.json", "[" + THOUSANDS + "]"),
    ("axes.json", '{"axes": [{"point": [0, 0, ' + THOUSANDS + '], "direction": [0, 0, 1]}]}'),
])
def test_json_integer_of_5000_digits(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    reader = read_pose_file if name.startswith("pose") else read_axes_file
    with pytest.raises(ParseError, match="not valid JSON: an integer has too many digits"):
        reader(p)


# ---------------------------------------------------------------- deeply nested arrays

@pytest.mark.parametrize("name, text", [
    ("model.toml", "x = " + "[" * DEEP + "]" * DEEP),
    ("pose.toml", "pose = " + "[" * DEEP),
    ("pose.json", "[" * DEEP + "]" * DEEP),
    ("axes.json", '{"axes": ' + "[" * DEEP + "]" * DEEP + "}"),
    ("axes.toml", "axes = " + "[" * DEEP + "]" * DEEP),
])
def test_deeply_nested_arrays(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    reader = {"model": read_model, "pose": read_pose_file, "axes": read_axes_file}[
        name.split(".")[0]]
    with pytest.raises(ParseError, match="nested too deeply") as ei:
        reader(p)
    assert ei.value.file == str(p)


def test_parse_helpers_name_the_source():
    with pytest.raises(ParseError, match=r"^a\.toml: not valid TOML: .*line 1"):
        parse_toml("x = = 1", "a.toml")
    with pytest.raises(ParseError, match=r"^b\.json, line 2: not valid JSON") as ei:
        parse_json('{\n"x": }', "b.json")
    assert ei.value.line == 2


# ------------------------------------------------------------------------ wrong types

@pytest.mark.parametrize("key, value", [("notation", "[]"), ("notation", "{}"),
                                        ("notation", "1"), ("angle_unit", "[]")])
def test_wrong_type_for_a_choice(key, value):
    text = MODEL.format(a="0.1", hi="90.0")
    text = (text.replace('notation = "standard_dh"', f"notation = {value}") if key == "notation"
            else text.replace('angle_unit = "deg"', f"angle_unit = {value}"))
    with pytest.raises(ParseError, match=f"{key} must be one of") as ei:
        loads_model(text, source="arm.toml")
    assert ei.value.field == key


def test_joint_type_of_the_wrong_type():
    text = MODEL.format(a="0.1", hi="90.0").replace("theta = 0.0", "type = [1]")
    with pytest.raises(ParseError, match="unknown joint type") as ei:
        loads_model(text)
    assert ei.value.field == "joints[1].type"


def test_binary_file_is_a_parse_error(tmp_path):
    p = tmp_path / "arm.toml"
    p.write_bytes(b"name = \"\xff\xfe\"\n")
    with pytest.raises(ParseError, match="not a text file") as ei:
        read_text_file(p, "model file")
    assert ei.value.file == str(p)


# --------------------------------------------------------------------------------- URDF

def _chain_urdf(n: int, extra: str = "") -> str:
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(f'<joint name="j{i + 1}" type="revolute"><parent link="l{i}"/>'
                     f'<child link="l{i + 1}"/><origin xyz="0 0 0.1" rpy="0 0 0"/>'
                     '<axis xyz="0 0 1"/></joint>' for i in range(n))
    return f'<robot name="chain">{links}{joints}{extra}</robot>'


def test_urdf_limit_that_is_not_a_number():
    text = _chain_urdf(1).replace('<axis xyz="0 0 1"/>',
                                  '<axis xyz="0 0 1"/><limit lower="abc" upper="1"/>')
    with pytest.raises(ParseError, match="cannot read a number from 'abc'") as ei:
        from_urdf(text, source="arm.urdf")
    assert ei.value.field == "joint 'j1' limit lower" and ei.value.file == "arm.urdf"


def test_urdf_joint_cycle_ends_with_a_parse_error(no_hang):
    # l3 -> l4 -> l3 hangs off nothing; asked for tip l3, the old walk followed it forever
    cycle = ('<link name="c1"/><link name="c2"/>'
             '<joint name="loop_a" type="revolute"><parent link="c1"/><child link="c2"/></joint>'
             '<joint name="loop_b" type="revolute"><parent link="c2"/><child link="c1"/></joint>')
    with pytest.raises(ParseError, match="closes a cycle of joints") as ei:
        from_urdf(_chain_urdf(2, cycle), tip="c1")
    assert "'loop_" in str(ei.value)


def test_urdf_self_loop_and_second_parent(no_hang):
    self_loop = ('<link name="s"/><joint name="me" type="revolute"><parent link="s"/>'
                 '<child link="s"/></joint>')
    with pytest.raises(ParseError, match="joint 'me' closes a cycle"):
        from_urdf(_chain_urdf(2, self_loop), tip="s")
    twice = '<joint name="again" type="revolute"><parent link="l0"/><child link="l2"/></joint>'
    with pytest.raises(ParseError, match="joint 'again': link 'l2' is already the child of "
                                         "joint 'j2'"):
        from_urdf(_chain_urdf(2, twice))


def test_urdf_chain_of_16000_joints(tmp_path, no_hang):
    # 34 s when the leaf search rebuilt a set per link; linear now (timed by the campaign)
    n = 16_000
    p = tmp_path / "long.urdf"
    p.write_text(_chain_urdf(n))
    model = read_urdf(p)
    assert model.n == n
    # every joint sits 0.1 above the previous one along z: the origins add up
    assert np.isclose(np.asarray(model.constants)[:, 2, 3].sum(), 0.1 * n)


def test_urdf_origin_overflowing_with_the_scale_and_reversed_limits():
    far = _chain_urdf(1).replace('xyz="0 0 0.1"', 'xyz="1e300 0 0"')
    with pytest.raises(ParseError, match="not finite") as ei:
        from_urdf(far, scale=1e10, source="arm.urdf")
    assert ei.value.field == "joint 'j1' origin xyz"
    reversed_ = _chain_urdf(1).replace('<axis xyz="0 0 1"/>',
                                       '<axis xyz="0 0 1"/><limit lower="2" upper="1"/>')
    with pytest.raises(ParseError, match="not an interval") as ei:
        from_urdf(reversed_, source="arm.urdf")
    assert ei.value.file == "arm.urdf" and ei.value.field == "joint 'j1' limit"
