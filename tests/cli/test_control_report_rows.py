"""The console report prints the equivalent wrench's force beside its torques, so that the
printed rows satisfy torque_about_base − torque_about_tool = tool_point × force."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def _row(text: str, label: str) -> np.ndarray:
    lines = [ln for ln in text.splitlines() if label in ln]
    assert len(lines) == 1, (label, text)
    cells = [c.strip() for c in lines[0].split("│") if c.strip()]
    return np.array([float(v) for v in cells[-3:]])


def test_printed_equivalent_force_and_torques_are_consistent(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="200")
    log = tmp_path / "log.jsonl"
    run = subprocess.run([sys.executable, "-m", "kinestat.cli.main", "control", "--no-plot",
                          "--log", str(log)], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    f_eq = _row(run.stdout, "equivalent wrench: force (N)")
    m_tool = _row(run.stdout, "torque about tool point")
    m_base = _row(run.stdout, "torque about robot base")
    p = _row(run.stdout, "tool point (mm)")
    # every value printed to 4 decimals (±5e-5): the bound of the rounding in p × f and the
    # difference (about 0.13 N·mm here; the point estimate's force misses by ~10 N·mm)
    atol = 5e-5 * (2 * (np.abs(p).sum() + np.abs(f_eq).sum()) + 2) + 1e-9
    np.testing.assert_allclose(m_base - m_tool, np.cross(p, f_eq), rtol=0, atol=atol)
    f_point = _row(run.stdout, "force, point estimate (N)")
    assert np.max(np.abs(m_base - m_tool - np.cross(p, f_point))) > atol  # the old pairing
    end = json.loads(log.read_text().splitlines()[-1])["report"]
    np.testing.assert_allclose(end["equivalent_force"], end["equivalent_wrench"][:3])
    np.testing.assert_allclose(f_eq, end["equivalent_force"], atol=1e-4)
