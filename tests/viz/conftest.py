"""Fixtures of the viewer tests: a small R-P-H chain, a control run's cycle log, the browser."""

from __future__ import annotations

import pytest

from kinestat.cli.main import main

RPH_TOML = """
name = "rph-test"
notation = "standard_dh"
length_unit = "mm"
angle_unit = "deg"

[[joints]]
name = "1"
type = "revolute"
theta = 10.0
d = 300.0
a = 50.0
alpha = 90.0
limits = [-170.0, 170.0]

[[joints]]
name = "2"
type = "prismatic"
theta = 0.0
d = 100.0
a = 200.0
alpha = -90.0
limits = [0.0, 400.0]

[[joints]]
name = "3"
type = "screw"
pitch = 20.0
theta = 30.0
d = 40.0
a = 120.0
alpha = 45.0
"""


@pytest.fixture(scope="session")
def rph_model_path(tmp_path_factory):
    p = tmp_path_factory.mktemp("models") / "rph.toml"
    p.write_text(RPH_TOML, encoding="utf-8")
    return p


@pytest.fixture(scope="session")
def control_log(tmp_path_factory):
    """A simulated control run's log, made by the public command (`kinestat control --log`)."""
    p = tmp_path_factory.mktemp("run") / "log.jsonl"
    code = main(["control", "--log", str(p), "--no-plot", "--json"])
    assert code == 0 and p.is_file()
    return p
