"""``kinestat disp``: the JSON contract for every MS, tables, plots, stops and errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.cli.main import main
from kinestat.io.disp_deck import embedded_deck_text


def _json(capsys, args, status=0):
    assert main(["disp", *args, "--json"]) == status
    return json.loads(capsys.readouterr().out)


def test_ms1_contract(capsys):
    out = _json(capsys, ["illustration1"])
    assert out["ms"] == 1 and len(out["screws"]) == 2
    for s in out["screws"]:
        assert set(s) >= {"axis", "point", "translation", "angle_deg", "pitch"}
        assert abs(np.linalg.norm(s["axis"]) - 1) < 1e-12


def test_ms2_and_ms3_contract(capsys):
    out = _json(capsys, ["illustration2"])
    assert len(out["joints"]) == 7
    assert set(out["joints"][0]) >= {"origin_star", "origin", "axis", "normal"}
    out3 = _json(capsys, ["illustration3"])
    assert "screws" in out3 and "joints" in out3


@pytest.mark.parametrize("name,ms", [("illustration4", 0), ("illustration5", 4),
                                     ("illustration6", 5), ("illustration7", 6)])
def test_guidance_contract(capsys, name, ms):
    # the default is DISP: one row per step; MS 0 and 4 end with DISP's correction rows onto
    # the target to the printed precision (0.0005), the others keep the first-order residual
    # Illustration 4 starts just off a singularity: 12 steps of 4.4° from there go astray
    k = "22" if ms == 0 else "12"
    bare = _json(capsys, [name, "--steps", k])
    n_settle = sum(e["kind"] == "settle" for e in bare["events"])
    assert len(bare["table"]) == 1 + sum(bare["steps"]) + n_settle
    if ms in (0, 4):
        assert n_settle >= 1 and bare["final_pose_error"]["position"] <= 5e-4
        none = _json(capsys, [name, "--steps", k, "--no-settle"])
        assert len(none["table"]) == 1 + sum(none["steps"])
        assert any("first-order residual" in n for n in none["notes"])
    else:
        assert n_settle == 0
        assert any("first-order residual" in n for n in bare["notes"])  # 12 steps leave one
    out = _json(capsys, [name, "--steps", k, "--settle"])
    assert out["ms"] == ms
    table = np.array(out["table"])
    assert table.shape[1] == 6 and table.shape[0] >= 13
    fhp = np.array(out["final_hand_points"])
    assert fhp.shape == (3, 3)
    np.testing.assert_allclose(np.linalg.norm(fhp[1:] - fhp[0], axis=1), 1.0, atol=1e-9)
    assert isinstance(out["events"], list)
    for ev in out["events"]:
        assert "step" in ev and "kind" in ev
    assert out["final_pose_error"]["position"] < 1e-8
    if ms == 5:
        assert np.array(out["stage_hand_origins"]).shape == (2, 3)
        np.testing.assert_allclose(out["stage_hand_origins"][0], [15, -25, 16], atol=1e-8)
    else:
        assert "stage_hand_origins" not in out


def test_per_stage_steps_closed_loop_and_second_order(capsys):
    out = _json(capsys, ["illustration6", "--steps", "8,4", "--closed-loop", "--no-settle"])
    assert out["steps"] == [8, 4] and len(out["table"]) == 13
    assert out["max_path_deviation"]["position"] < 1e-9
    out = _json(capsys, ["illustration6", "--steps", "8,4", "--second-order", "--no-settle"])
    assert out["steps"] == [8, 4]


def test_human_output_and_plots(capsys, tmp_path):
    assert main(["disp", "illustration6", "--plot", str(tmp_path / "plots")]) == 0
    text = capsys.readouterr().out
    assert "Joint variables" in text and "initial" in text and "final" in text
    for name in ("joints.png", "hand-path.png"):
        p = tmp_path / "plots" / name
        assert p.exists() and p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["disp", "illustration1"]) == 0
    assert "Screw axes" in capsys.readouterr().out


def test_deck_file_and_bad_decks(capsys, tmp_path):
    good = tmp_path / "ill4.dat"
    good.write_text(embedded_deck_text("illustration4"))
    out = _json(capsys, [str(good), "--steps", "5", "--no-settle"])
    assert out["ms"] == 0
    bad = tmp_path / "bad.dat"
    bad.write_text(embedded_deck_text("illustration4").replace("    0    2    0    0",
                                                               "    0    2    0    7"))
    assert main(["disp", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "kinestat: error:" in err and "IO" in err and "Traceback" not in err
    assert main(["disp", "no-such-deck"]) == 2
    assert "embedded" in capsys.readouterr().err
    assert main(["disp", "illustration6", "--steps", "a,b"]) == 2
    assert "--steps" in capsys.readouterr().err


def test_unreachable_target_deck_stops_with_status_2(capsys, tmp_path):
    text = embedded_deck_text("illustration4").replace(
        "    -20.30     -7.83     -6.66\n    -20.65     -8.29     -5.85\n"
        "    -21.06     -7.18     -6.62",
        "    200.00      0.00      0.00\n    200.00      0.00      1.00\n"
        "    201.00      0.00      0.00")
    deck = tmp_path / "far.dat"
    deck.write_text(text)
    assert main(["disp", str(deck), "--steps", "30", "--no-settle", "--json"]) == 0  # no check
    assert "from the target" in " ".join(json.loads(capsys.readouterr().out)["notes"])
    assert main(["disp", str(deck), "--steps", "30", "--json"]) == 2  # DISP's correction
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert out["stopped"] is True and out["stop_reason"]
    assert "kinestat: error:" in captured.err and "Traceback" not in captured.err


def test_progress_bar_on_a_terminal(capsys, monkeypatch):
    from rich.console import Console

    import kinestat.cli.disp as cli_disp

    monkeypatch.setattr(cli_disp, "err_console", Console(stderr=True, force_terminal=True))
    with cli_disp.progress_reporter(True) as prog:
        assert prog is not None
        prog(3, 10)
        prog(10, 10)
    with cli_disp.progress_reporter(False) as prog:
        assert prog is None
    assert main(["disp", "illustration6", "--steps", "4"]) == 0
    assert "Joint variables" in capsys.readouterr().out


# Nadkarni 1977, Table A2-9 (published), rows 2-9 and the final row; row 1's θ4 is a misprint
# (10.000 for 10.886: docs/seed-errata.md, G1).
TABLE_A2_9 = {
    2: [-0.948, 27.775, 7.407, 21.801], 3: [-1.960, 28.790, 7.111, 32.005],
    4: [-3.108, 29.464, 6.815, 41.009], 5: [-4.229, 29.864, 6.519, 48.652],
    6: [-5.317, 29.953, 6.222, 55.008], 7: [-6.254, 29.919, 5.926, 60.255],
    8: [-7.138, 29.674, 5.630, 64.592], 9: [-7.918, 29.343, 5.333, 68.199],
}


def test_disp_1977_flag_reproduces_table_a2_9(capsys):
    assert main(["disp", "illustration5-published", "--disp-1977", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    table = out["table"]
    assert out["total_steps"] == 38  # the caption: "Total 38 steps"
    for row, values in TABLE_A2_9.items():
        np.testing.assert_allclose(table[row][:4], values, atol=6e-4, err_msg=f"row {row}")
        np.testing.assert_allclose(table[row][4:], [90.0, 0.0], atol=6e-4)
    np.testing.assert_allclose(table[-1], [-15.0, 20.0, 0.0, 90.0, 90.0, 0.0], atol=6e-4)
    assert main(["disp", "illustration5-published", "--disp-1977", "--closed-loop"]) == 2
    assert "cannot be combined" in capsys.readouterr().err
