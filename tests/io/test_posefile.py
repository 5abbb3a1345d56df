"""Pose files: every accepted form gives the same pose; bad content names the file."""

import json

import numpy as np
import pytest

import kinestat
from kinestat.cli._output import parse_pose
from kinestat.errors import InputError, ParseError
from kinestat.io.posefile import read_pose_file


@pytest.fixture
def pose():
    return kinestat.fk(kinestat.load("puma762"), np.deg2rad([200, 10, 20, 30, 40, 50]))


def test_all_forms_agree(tmp_path, pose):
    forms = {
        "a.json": json.dumps({"pose": pose.tolist(), "other": 1}),
        "b.json": json.dumps(pose.tolist()),
        "c.json": json.dumps(pose.ravel().tolist()),
        "d.toml": "pose = " + json.dumps(pose.tolist()) + "\n",
        "e.txt": "# a pose\n" + "\n".join(" ".join(repr(float(v)) for v in row) for row in pose),
        "f.txt": "\n".join(", ".join(repr(float(v)) for v in row) for row in pose[:3]),
    }
    for name, text in forms.items():
        (tmp_path / name).write_text(text)
        np.testing.assert_allclose(read_pose_file(tmp_path / name), pose, atol=1e-12,
                                   err_msg=name)
        np.testing.assert_allclose(parse_pose(str(tmp_path / name)), pose, atol=1e-12)
    np.testing.assert_allclose(parse_pose(",".join(repr(float(v)) for v in pose.ravel())), pose)


def test_batch_only_where_allowed(tmp_path, pose):
    p = tmp_path / "many.json"
    p.write_text(json.dumps([pose.tolist(), pose.tolist()]))
    assert read_pose_file(p, allow_batch=True).shape == (2, 4, 4)
    with pytest.raises(ParseError, match="4x4"):
        read_pose_file(p)


@pytest.mark.parametrize("name,text,msg", [
    ("a.json", "{", "not valid JSON"),
    ("b.json", '{"q": 1}', '"pose" key'),
    ("c.toml", "pose = [", "not valid TOML"),
    ("d.txt", "1 2 3", "expected 16"),
    ("e.txt", "1 2 x", "not a number"),
    ("f.json", "[[1, 2], [3, 4]]", "4x4"),
    ("g.json", json.dumps([[float("nan")] * 4] * 4).replace("NaN", "NaN"), "NaN"),
])
def test_bad_content_names_the_file(tmp_path, name, text, msg):
    p = tmp_path / name
    p.write_text(text)
    with pytest.raises(ParseError, match=msg) as exc:
        read_pose_file(p)
    assert name in str(exc.value)


def test_binary_and_missing(tmp_path):
    p = tmp_path / "bin.dat"
    p.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ParseError, match="not a text file"):
        read_pose_file(p)
    with pytest.raises(InputError, match="does not exist"):
        parse_pose(str(tmp_path / "missing.json"))
    with pytest.raises(InputError, match="neither a file"):
        parse_pose("home-ish")
