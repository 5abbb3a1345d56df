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
def control_run(tmp_path_factory):
    """A simulated control run made by the public command, ``kinestat control --log FILE
    --view`` (the browser replaced by a recorder): (log path, opened URLs, JSON stdout)."""
    import contextlib
    import io
    import json
    import tempfile
    import webbrowser

    d = tmp_path_factory.mktemp("run")
    p = d / "log.jsonl"
    opened: list[str] = []
    buf = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(buf):
        mp.setattr(webbrowser, "open", lambda url, *a, **k: opened.append(url) or True)
        mp.setattr(tempfile, "tempdir", str(d))
        code = main(["control", "--log", str(p), "--no-plot", "--json", "--view"])
    assert code == 0 and p.is_file()
    return p, opened, json.loads(buf.getvalue())


@pytest.fixture(scope="session")
def control_log(control_run):
    return control_run[0]
