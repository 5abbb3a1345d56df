"""``kinestat screw``: JSON and table output on displacements with known screws, inputs, errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.cli.main import main


def _known_pose():
    """Quarter turn about the vertical line through (1, 0, 0), then 2 up along it."""
    c, s = 0.0, 1.0
    Q = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    centre = np.array([1.0, 0, 0])
    T = np.eye(4)
    T[:3, :3] = Q
    T[:3, 3] = centre - Q @ centre + [0, 0, 2.0]
    return T


def _csv(a) -> str:
    return ",".join(repr(float(x)) for x in np.ravel(a))


def _run_json(capsys, args):
    assert main(["screw", *args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_known_screw_from_inline_poses(capsys):
    out = _run_json(capsys, ["--pose1", _csv(np.eye(4)), "--pose2", _csv(_known_pose())])
    np.testing.assert_allclose(out["axis"], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(out["point"], [1, 0, 0], atol=1e-12)
    assert out["angle_deg"] == pytest.approx(90.0)
    assert out["translation"] == pytest.approx(2.0)
    assert out["pitch"] == pytest.approx(2.0 / (np.pi / 2))
    assert out["pure_translation"] is False


def test_pose_files_and_first_pose_not_identity(tmp_path, capsys):
    T1 = np.eye(4)
    T1[:3, 3] = [5.0, -2.0, 7.0]
    T2 = _known_pose() @ T1
    f1, f2 = tmp_path / "a.txt", tmp_path / "b.txt"
    rows1 = "\n".join(" ".join(str(float(x)) for x in r) for r in T1[:3])
    f1.write_text("# pose 1, three rows\n" + rows1)
    f2.write_text("\n".join(", ".join(str(float(x)) for x in r) for r in T2) + "  # full 4x4\n")
    out = _run_json(capsys, ["--pose1", str(f1), "--pose2", str(f2)])
    np.testing.assert_allclose(out["point"], [1, 0, 0], atol=1e-12)
    assert out["angle_deg"] == pytest.approx(90.0)


def test_points_pure_translation(capsys):
    p = np.array([[0, 0, 0], [0, 0, 1.0], [1.0, 0, 0]])
    out = _run_json(capsys, ["--points1", _csv(p), "--points2", _csv(p + [3.0, 0, -4.0])])
    assert out["pitch"] == "inf" and out["pure_translation"] is True
    np.testing.assert_allclose(out["axis"], [-0.6, 0, 0.8], atol=1e-12)  # u3 >= 0
    assert out["translation"] == pytest.approx(-5.0)
    assert out["angle_deg"] == 0.0


def test_table_output(capsys):
    p = "25,0,20,30,0,20,25,0,10"
    q = "-20.30,-7.83,-6.66,-20.65,-8.29,-5.85,-21.06,-7.18,-6.62"
    assert main(["screw", "--points1", p, "--points2", q]) == 0
    text = capsys.readouterr().out
    assert "axis u" in text and "pitch" in text and "rotation (deg)" in text


@pytest.mark.parametrize(
    "args, message",
    [
        ([], "either --pose1"),
        (["--pose1", ",".join(["0"] * 16)], "both --pose1 and --pose2"),
        (["--points1", "0,0,0,0,0,1,1,0,0", "--pose2", _csv(np.eye(4))], "either"),
        (["--points1", "0,0,0,0,0,1", "--points2", "0,0,0,0,0,1"], "expected 9"),
        (["--points1", "0,0,0,0,0,1,0,0,2", "--points2", "0,0,0,0,0,1,1,0,0"], "collinear"),
        (["--points1", "0,0,0,0,0,1,1,0,nan", "--points2", "0,0,0,0,0,1,1,0,0"], "finite"),
        (["--pose1", "no-such-file.txt", "--pose2", "x"], "neither a file"),
        (["--pose1", _csv(2 * np.eye(4)), "--pose2", _csv(np.eye(4))], "not a rigid pose"),
    ],
)
def test_errors_exit_2(capsys, args, message):
    assert main(["screw", *args]) == 2
    assert message in capsys.readouterr().err


def test_bad_pose_file(tmp_path, capsys):
    f = tmp_path / "bad.txt"
    f.write_text("1 0 0 0\n0 1 zero 0\n0 0 1 0\n")
    assert main(["screw", "--pose1", str(f), "--pose2", str(f)]) == 2
    err = capsys.readouterr().err
    assert "bad.txt, line 2" in err and "'zero'" in err
    f.write_text("1 0 0\n")
    assert main(["screw", "--pose1", str(f), "--pose2", str(f)]) == 2
    assert "got 3" in capsys.readouterr().err


def test_screw_of_two_fk_json_poses(tmp_path, capsys):
    # `kinestat fk --json` output used to be refused ("'{' is not a number"); the screw found
    # from it must carry the first pose onto the second (checked with SciPy's rotation vector)
    from scipy.spatial.transform import Rotation

    from kinestat.spatial.displacement import pose_from_screw

    files = []
    for i, q in enumerate(["180,10,20,30,40,50", "170,15,25,35,45,55"]):
        assert main(["fk", "puma762", "--q-deg", q, "--json"]) == 0
        f = tmp_path / f"fk{i}.json"
        f.write_text(capsys.readouterr().out)
        files.append(f)
    out = _run_json(capsys, ["--pose1", str(files[0]), "--pose2", str(files[1])])
    T1, T2 = (np.array(json.loads(f.read_text())["pose"]) for f in files)
    D = pose_from_screw(out["axis"], out["point"], np.radians(out["angle_deg"]),
                        out["translation"])
    np.testing.assert_allclose(D @ T1, T2, atol=1e-9)
    rotvec = Rotation.from_matrix(T2[:3, :3] @ T1[:3, :3].T).as_rotvec(degrees=True)
    np.testing.assert_allclose(np.array(out["axis"]) * out["angle_deg"], rotvec, atol=1e-9)


def test_json_pose_file_forms(tmp_path, capsys):
    T = _known_pose()
    for i, doc in enumerate([T.tolist(), T[:3].ravel().tolist()]):
        f = tmp_path / f"p{i}.json"
        f.write_text(json.dumps(doc))
        out = _run_json(capsys, ["--pose1", _csv(np.eye(4)), "--pose2", str(f)])
        assert out["angle_deg"] == pytest.approx(90.0)
    f = tmp_path / "bad.json"
    for text, msg in [('{"x": 1}', '"pose" key'), ("[[1, 2], [3, 4]]", "shape (2, 2)"),
                      ('{"pose": [1,', "not valid JSON")]:
        f.write_text(text)
        assert main(["screw", "--pose1", str(f), "--pose2", str(f)]) == 2
        err = capsys.readouterr().err
        assert msg in err and "bad.json" in err


def test_binary_pose_file_and_degenerate_second_points(tmp_path, capsys):
    # a binary file used to end in a UnicodeDecodeError traceback
    f = tmp_path / "bin.txt"
    f.write_bytes(b"\xff\xfe\x00")
    assert main(["screw", "--pose1", str(f), "--pose2", str(f)]) == 2
    assert "not a text file" in capsys.readouterr().err
    # degenerate points now say which option holds them
    assert main(["screw", "--points1", "0,0,0,0,0,1,1,0,0",
                 "--points2", "0,0,0,0,0,0,1,0,0"]) == 2
    assert capsys.readouterr().err.startswith("kinestat: error: --points2: points 1 and 2")
