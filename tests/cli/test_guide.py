"""``kinestat guide``: targets, commands, moves, joint rates, joint-limit stops, errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.cli.guide import parse_command, parse_move, read_commands
from kinestat.cli.main import main
from kinestat.errors import InputError, ParseError

TARGET5 = "10,-10,20,11,-10,20,10,-10,19"  # Illustration 5/7's target


def _json(capsys, args, status=0):
    assert main(["guide", *args, "--json"]) == status
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("kind", ["screw", "line", "general"])
def test_target_reached_by_each_path_type(capsys, kind):
    out = _json(capsys, ["nadkarni-config2", "--to", TARGET5, "--type", kind, "--steps", "20"])
    assert out["type"] == kind
    np.testing.assert_allclose(out["table"][-1], [-15, 20, 0, 90, 90, 0], atol=1e-7)
    np.testing.assert_allclose(out["final_hand_points"], np.reshape(
        [float(v) for v in TARGET5.split(",")], (3, 3)), atol=1e-8)


def test_commands_match_illustration_6_and_a_commands_file(capsys, tmp_path):
    a = _json(capsys, ["nadkarni-config2", "--command", "frame=global,dir=0,0,1,d=4,angle=-30",
                       "--command", "frame=hand,dir=1,0,0,d=-1,angle=15", "--steps", "10,5"])
    f = tmp_path / "cmds.txt"
    f.write_text("# Table A2-10 as SET THREE cards\n0 0 0 1 4 -30\n1 1 0 0 -1 15  # hand x\n")
    b = _json(capsys, ["nadkarni-config2", "--commands", str(f), "--steps", "10,5"])
    np.testing.assert_allclose(a["table"], b["table"], atol=1e-12)
    np.testing.assert_allclose(a["stage_hand_origins"], [[15, -25, 16], [15, -25, 17]],
                               atol=1e-8)


def test_q0_and_moves_and_joint_rates(capsys):
    out = _json(capsys, ["nadkarni-config1", "--q0-deg", "40,70,60,30,50,20",
                         "--move", "axis=0,0,1,angle=20,dir=1,0,0,d=2", "--steps", "40",
                         "--closed-loop", "--speed", "10"])
    np.testing.assert_allclose(out["table"][0], [40, 70, 60, 30, 50, 20], atol=1e-12)
    o = np.array(out["hand_origins"])
    np.testing.assert_allclose(o[-1] - o[0], [2, 0, 0], atol=1e-9)
    rates = np.array(out["joint_rates"])
    assert rates.shape == (len(out["table"]) - 1, 6)
    # 20° at 10 deg/s takes 2 s: the joint rates integrate to the joint motion (suggestion 1;
    # trapezoidal rule on the rates at the step starts, the last step's taken as constant)
    table = np.array(out["table"])
    dt = 2.0 / 40
    r = np.vstack([rates, rates[-1]])
    integral = np.sum(0.5 * (r[1:] + r[:-1]), axis=0) * dt
    err = np.abs(integral - (table[-1] - table[0]))
    assert np.all(err <= 0.02 * np.ptp(table, axis=0) + 0.05), err
    assert out["joint_rate_units"][0] == "deg/s"


def test_joint_limit_stop_prints_the_table_and_exits_2(capsys, tmp_path):
    from kinestat.io.library import embedded_text

    text = embedded_text("models", "nadkarni-config2.toml")
    text = text.replace('name = "4"\ntype = "revolute"', 'name = "4"\ntype = "revolute"\n'
                        'limits = [-180.0, 30.0]')
    assert "limits" in text
    model = tmp_path / "limited.toml"
    model.write_text(text)
    assert main(["guide", str(model), "--to", TARGET5, "--type", "line", "--steps", "27"]) == 2
    captured = capsys.readouterr()
    assert "Joint variables" in captured.out and "joint_limit" in captured.out
    assert "joint 4" in captured.err and "upper limit" in captured.err
    assert "Traceback" not in captured.err
    out = _json(capsys, [str(model), "--to", TARGET5, "--type", "line", "--steps", "27"], 2)
    assert out["stopped"] and out["stop_reason"] == "joint_limit"
    assert out["events"][-1]["joint"] == 4
    assert np.max(np.array(out["table"])[:, 3]) <= 30.0


@pytest.mark.parametrize("args,words", [
    (["nadkarni-config2"], "nothing to do"),
    (["nadkarni-config2", "--to", "1,2,3"], "9 comma-separated"),
    (["nadkarni-config2", "--to", TARGET5, "--type", "spiral"], "--type"),
    (["nadkarni-config2", "--to", TARGET5, "--command", "dir=0,0,1,d=1"], "not a mix"),
    (["nadkarni-config2", "--command", "dir=0,0,0,d=1"], "zero"),
    (["nadkarni-config2", "--command", "frame=tool,dir=0,0,1"], "frame"),
    (["nadkarni-config2", "--command", "dir=0,0,1,speed=3"], "unknown key"),
    (["nadkarni-config2", "--q0-deg", "1,2", "--to", TARGET5], "q0-deg"),
    (["no-such-model", "--to", TARGET5], "unknown model"),
])
def test_bad_requests_are_clear_errors(capsys, args, words):
    assert main(["guide", *args]) == 2
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err


def test_parsers():
    c = parse_command("frame=hand, dir=1,0,0, d=-1, angle=15")
    assert c["frame"] == "hand" and c["distance"] == -1 and c["angle_deg"] == 15
    np.testing.assert_allclose(c["direction"], [1, 0, 0])
    mv = parse_move("axis=0,0,1,angle=30")
    assert mv["angle_deg"] == 30 and mv["distance"] == 0
    with pytest.raises(InputError):
        parse_command("dir=1,0,0,angle=abc")
    with pytest.raises(InputError):
        parse_command("d=1")


def test_commands_file_errors_say_where(tmp_path):
    f = tmp_path / "c.txt"
    f.write_text("0 0 0 1 4 -30\n2 1 0 0 1 1\n")
    with pytest.raises(ParseError) as info:
        read_commands(f)
    assert info.value.line == 2
    f.write_text("# nothing\n")
    with pytest.raises(ParseError):
        read_commands(f)
    with pytest.raises(InputError):
        read_commands(tmp_path / "missing.txt")
