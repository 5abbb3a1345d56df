"""Issue 43: bad calls end in one ``kinestat: error:`` line and status 2 — a cycle log that is
not UTF-8, a URDF scale of zero or below."""

from __future__ import annotations

import pytest

from kinestat.cli.main import main
from tests.urdf_arms import arm_path


def _one_error(capsys, argv) -> str:
    code = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("kinestat: error:"), (code, err)
    return err[0]


@pytest.mark.parametrize(("content", "what"), [
    (b'\xff\xfe{"type": "start"}\n', "not UTF-8 text"),
    (b'{"type": "start"}\n[1, 2]\n', "line 2 is not a cycle record"),
    (b"[" * 100_000 + b"]" * 100_000 + b"\n", "line 1 is not a cycle record"),
])
def test_view_log_on_a_file_that_is_not_a_cycle_log(capsys, tmp_path, content, what):
    p = tmp_path / "log.jsonl"
    p.write_bytes(content)
    assert what in _one_error(capsys, ["view", "log", str(p), "--no-open"])


@pytest.mark.parametrize("scale", ["0", "-1", "nan", "-inf"])
def test_urdf_scale_zero_or_negative_is_refused(capsys, scale):
    msg = _one_error(capsys, ["fk", str(arm_path("ur5")), "--tip", "tool0", "--scale", scale,
                              "--q", "0,0,0,0,0,0"])
    assert "--scale" in msg and "> 0" in msg


@pytest.mark.parametrize(("argv", "what"), [
    (["--rate", "nan"], "--rate must be in"), (["--rate", "0"], "--rate must be in"),
    (["--rate", "1e999"], "--rate must be in"), (["--log", "."], "is a directory"),
])
def test_control_refuses_a_bad_rate_or_log_before_printing_anything(capsys, argv, what):
    """The header of the run used to be printed first, the error as a second line."""
    assert what in _one_error(capsys, ["control", *argv])


def test_a_huge_command_line_is_refused_at_once(capsys):
    """200,003 arguments (a mutated command line of the campaign) kept Click's parser busy for
    10 s and printed a 600 KB error line."""
    import time

    t0 = time.monotonic()
    msg = _one_error(capsys, ["disp", *(["x", "="] * 100_000), "--json"])
    assert "200002 arguments, more than the 1000" in msg and time.monotonic() - t0 < 1.0


def test_an_error_line_quoting_a_huge_value_is_cut(capsys):
    msg = _one_error(capsys, ["fk", "puma762", "--q-deg", "1" * 5000])
    assert len(msg) <= 1000 + len("kinestat: error: ")
