"""Bad command lines of every kind the command-line campaign (scripts/cli_fuzz_campaign.py)
found, and a sample of every command: each ends in exactly one ``kinestat: error:`` line that
names the option (or the file) at fault, status 2, no traceback, and no file left behind.
Good input at the edges (a path with blanks and non-ASCII letters, -0, angles at ±180°) runs.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import kinestat
from kinestat.cli.main import main

P16 = "1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1"
DATA = Path(kinestat.__file__).parent / "data"

# (argv, the text the error line must hold); ``{fx}`` is a folder of bad files, ``{out}`` an
# output path inside the working directory that must not exist afterwards
BAD = [
    # malformed lists, wrong counts, non-finite numbers, bad choices
    (["fk", "puma762", "--q", "1,,2,3,4,5"], "--q"),
    (["fk", "puma762", "--q-deg", "nan,0,0,0,0,0"], "--q-deg"),
    (["fk", "puma762", "--q", "0,0,0,0,0,0", "--euler", "XYZW"], "--euler"),
    (["fk", "puma762", "--q", "0,0,0,0,0,0", "--length-unit", "mm"], "--length-unit"),
    (["screw", "--pose1", P16, "--pose2", "1;2;3"], "--pose2"),
    (["platform", "fk", "--legs", "0,60,60,60,60,60"], "--legs"),
    (["platform", "stiffness", "--twist-order", "bogus"], "--twist-order"),
    (["ik", "puma560", "--pose", P16, "--seed", "-3"], "--seed"),
    (["ik", "puma560", "--pose", P16, "--limits", "bogus"], "--limits"),
    (["ik", "puma560", "--pose", P16, "--current-deg", "1,2"], "--current-deg"),
    (["ik", "ur5", "--pose", P16, "--all", "--lock", "6", "--self-motion", "0"],
     "--self-motion"),
    (["guide", "puma560", "--to-pose", P16, "--cond-limit", "0"], "--cond-limit"),
    (["disp", "illustration5", "--cond-limit", "nan"], "--cond-limit"),
    (["disp", "illustration5", "--steps", "1,,2"], "--steps"),
    (["disp", "illustration5", "--damped", "--singular", "stop"], "--damped"),
    (["ik", "puma762", "--tool-point", "100,200,300", "--s6", "0,0,1", "--a67", "1,0,0",
      "--q0-deg", "0,0,0,0,0,0"], "--q0-deg"),
    (["sweep", "workspace", "--samples", "2", "--scheduler", "tcp://127.0.0.1:1", "--threads",
      "--output", "{out}"], "--threads"),
    (["control", "--align-tol-deg", "200", "--no-plot"], "--align-tol-deg"),
    (["control", "--task", "follow", "--travel", "-1", "--no-plot"], "--travel"),
    (["control", "--task", "follow", "--tilt-deg", "100", "--no-plot"], "--tilt-deg"),
    (["control", "--serial-format", "bogus", "--no-plot"], "--serial-format"),
    (["control", "--plot", "{out}", "--no-plot"], "--plot"),
    (["control", "--task", "follow", "--travel-dir", "0,0,0", "--no-plot"], "--travel-dir"),
    (["control", "--task", "follow", "--travel-step", "0", "--no-plot"], "--travel-step"),
    (["control", "--task", "follow", "--probe-span", "100", "--no-plot"], "--probe-span"),
    (["home", "--galil", "127.0.0.1:1", "--samples", "0"], "--samples"),
    (["sim", "galil", "--port", "-1", "--duration", "0.1"], "--port"),
    (["sim", "galil", "--rate", "0", "--duration", "0.1"], "--rate"),
    (["view", "model", "puma560", "--no-open", "--meshes", "bogus"], "--meshes"),
    (["sweep", "workspace", "--samples", "2", "--workers", "100000", "--output", "{out}"],
     "--workers"),
    (["sweep", "platform-range", "--grid", "2", "--range-deg", "-1,2,3", "--output", "{out}"],
     "--range-deg"),
    (["sweep", "platform-design", "--grid", "2", "--height", "0:70", "--output", "{out}"],
     "--height"),
    (["sweep", "platform-design", "--grid", "2", "--height", "50:70", "--stiffness", "-1",
      "--output", "{out}"], "--stiffness"),
    # files: binary, truncated, a URDF where TOML is expected, a directory
    (["fk", "{fx}/binary.toml", "--q", "0,0,0,0,0,0"], "binary.toml"),
    (["fk", "{fx}/robot.toml", "--q", "0,0,0,0,0,0"], "robot.toml"),
    (["disp", "{fx}/truncated.dat"], "truncated.dat"),
    (["view", "log", "{fx}/truncated.jsonl", "--no-open", "--html", "{out}"],
     "truncated.jsonl"),
    (["platform", "info", "--platform", "{fx}/robot.toml"], "robot.toml"),
    # empty names: not the current folder
    (["fk", "", "--q", "0,0,0,0,0,0"], "'model'"),
    (["disp", " "], "'deck'"),
    (["dh-from-axes", ""], "'file'"),
    (["platform", "info", "--platform", ""], "--platform"),
    (["control", "--log", "", "--no-plot"], "--log"),
    (["view", "model", "puma560", "--no-open", "--html", ""], "--html"),
    (["sweep", "workspace", "--samples", "3", "--output", ""], "--output"),
    (["disp", "illustration5", "--plot", ""], "--plot"),
    # outputs that cannot be written: refused before any work, naming the option
    (["screw", "--pose1", P16, "--pose2", P16, "--view", "--html", "/proc/x.html"], "--html"),
    (["view", "model", "puma560", "--no-open", "--html", "{fx}/binary.toml/x.html"], "--html"),
    (["platform", "fk", "--legs", "70,70,70,70,70,70", "--html", "{fx}"], "--html"),
    (["disp", "illustration5", "--plot", "/proc/x"], "--plot"),
    (["guide", "puma560", "--to-pose", P16, "--plot", "{fx}/binary.toml"], "--plot"),
    (["control", "--plot", "/proc/x"], "--plot"),
    (["control", "--log", "/proc/x.jsonl", "--no-plot"], "--log"),
    (["control", "--view", "--html", "/proc/x.html", "--no-plot"], "--html"),
    (["home", "--galil", "127.0.0.1:1", "--log", "/proc/x.jsonl"], "--log"),
    (["dh-from-axes", "{fx}/axes.toml", "--write-model", "/proc/m.toml"], "--write-model"),
    (["sweep", "workspace", "--samples", "3", "--output", "/proc/o"], "--output"),
]


@pytest.fixture(scope="module")
def fx(tmp_path_factory) -> Path:
    """Bad and edge files: binary, empty, truncated, a URDF named .toml, a blank-named model."""
    d = tmp_path_factory.mktemp("fx")
    (d / "binary.toml").write_bytes(b"\x00\x01\xff\xfe garbage \x80")
    (d / "robot.toml").write_text('<?xml version="1.0"?>\n<robot name="r"><link name="a"/>'
                                  "</robot>\n")
    deck = (DATA / "decks" / "illustration5.dat").read_text().splitlines(keepends=True)
    (d / "truncated.dat").write_text("".join(deck[:3]))
    (d / "truncated.jsonl").write_text('{"type": "start", "config": {"a": 1')
    (d / "axes.toml").write_text('length_unit = "m"\n[[axes]]\npoint = [0, 0, 0]\n'
                                 "direction = [0, 0, 1]\n")
    sp = d / "dir with blanks"
    sp.mkdir()
    shutil.copy(DATA / "models" / "puma560.toml", sp / "mödel ü.toml")
    return d


def _fill(argv: list[str], fx: Path, out: Path) -> list[str]:
    return [a.replace("{fx}", str(fx)).replace("{out}", str(out)) for a in argv]


@pytest.mark.parametrize(("argv", "names"), BAD, ids=[" ".join(a)[:60] for a, _ in BAD])
def test_bad_input_is_one_error_line_naming_it(capsys, monkeypatch, tmp_path, fx, argv, names):
    monkeypatch.setenv("BROWSER", "true")
    monkeypatch.chdir(tmp_path)
    before = set(p.name for p in fx.iterdir())
    code = main(_fill(argv, fx, tmp_path / "out-target"))
    captured = capsys.readouterr()
    lines = [ln for ln in captured.err.splitlines()
             if ln.strip() and not ln.startswith("kinestat: compiling")]
    assert code == 2, captured.err
    assert len(lines) == 1 and lines[0].startswith("kinestat: error:"), lines
    assert _fill([names], fx, tmp_path)[0] in lines[0]
    assert "Traceback" not in captured.err + captured.out
    assert list(tmp_path.iterdir()) == []  # no partial output, no run directory
    assert set(p.name for p in fx.iterdir()) == before


GOOD = [
    ["fk", "{fx}/dir with blanks/mödel ü.toml", "--q", "-0,0,0,0,0,0"],
    ["fk", "puma762", "--q-deg", "-180,0,0,0,0,180"],
    ["platform", "ik", "--pose", "HOME"],
    ["view", "model", "puma560", "--no-open", "--html", "{out}/dir with blanks/ü view.html"],
]


@pytest.mark.parametrize("argv", GOOD, ids=[" ".join(a)[:60] for a in GOOD])
def test_good_input_at_the_edges_runs(capsys, monkeypatch, tmp_path, fx, argv):
    monkeypatch.setenv("BROWSER", "true")
    (tmp_path / "dir with blanks").mkdir()
    assert main(_fill(argv, fx, tmp_path)) == 0, capsys.readouterr().err


def test_ctrl_c_while_serving_is_one_line_and_status_130(tmp_path):
    """``view --serve`` stops on Ctrl-C: Typer alone exited 130 printing a blank line only."""
    import os
    import signal
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[2]
    proc = subprocess.Popen(
        [sys.executable, "-m", "kinestat.cli.main", "view", "model", "puma560", "--serve",
         "--no-open"], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(root)},
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert "serving http://" in proc.stdout.readline()
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130
    assert [ln for ln in err.splitlines() if ln.strip()] == ["kinestat: interrupted"]
