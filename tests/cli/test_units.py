"""Every JSON record says its units (issue 16): a ``units`` object, added beside the old keys."""

from __future__ import annotations

import json

import pytest

from kinestat.cli.main import main

LEGS = "79.6804,81.8285,81.2669,68.65,67.2037,68.2854"
COMMANDS = [
    ["fk", "puma762", "--q-deg", "10,20,30,40,50,60"],
    ["fk", "puma560", "--q-deg", "10,20,30,40,50,60"],
    ["ik", "puma762", "--tool-point", "725,190,650", "--s6", "1,0,0", "--a67", "0,0,1"],
    ["ik", "puma560", "--pose", "1,0,0,0.4,0,1,0,0.1,0,0,1,0.8,0,0,0,1"],
    ["screw", "--points1", "25,0,20,30,0,20,25,0,10", "--points2",
     "-20.3,-7.83,-6.66,-20.65,-8.29,-5.85,-21.06,-7.18,-6.62"],
    ["disp", "illustration6", "--steps", "3"],
    ["guide", "nadkarni-config2", "--command", "frame=global,dir=0,0,1,d=4,angle=-30",
     "--steps", "3"],
    ["platform", "info"],
    ["platform", "fk", "--legs", LEGS],
    ["platform", "ik", "--pose", "home"],
    ["platform", "statics", "--pose", "home", "--wrench", "0,0,-10,0,0,0"],
    ["platform", "stiffness"],
    ["platform", "decompose", "--twist", "0,0,0,1,0,0", "--contact", "0,0,1,0,0,0"],
]


def _json(capsys, args) -> dict:
    assert main([*args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("args", COMMANDS, ids=[" ".join(a[:2]) for a in COMMANDS])
def test_every_json_record_has_units(capsys, args):
    rec = _json(capsys, args)
    u = rec["units"]
    assert u["angle"] == "rad" and u["angle_deg_keys"] == "deg"
    if "length_unit" in rec:  # the old key stays and agrees
        assert u["length"] == rec["length_unit"]
    if args[0] in ("fk", "ik", "guide") and args[1] != "puma762":
        model = _json(capsys, ["fk", args[1], "--q-deg", "0,0,0,0,0,0"])
        assert u["length"] == model["length_unit"]
    if args[0] == "platform":
        info = _json(capsys, ["platform", "info"])
        assert (u["length"], u["force"]) == (info["length_unit"], info["force_unit"])
