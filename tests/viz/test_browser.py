"""Every kind of viewer page in a real browser (headless Chromium, WebGL on SwiftShader).

Per page: the viewer script finishes with no error and nothing on the console, the WebGL canvas
is not blank (grey-level variance of a screenshot), and the poses the page computes with its own
forward kinematics (JavaScript) equal kinestat's to 1e-9. Chromium comes from ``make browser``
(which ``make test`` runs); without it these tests skip.
"""

from __future__ import annotations

import numpy as np
import pytest

import kinestat
from kinestat.io.disp_deck import embedded_deck
from kinestat.parallel.fk import fk_list
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import prototype
from kinestat.serial.fk import fk_frames
from kinestat.serial.guidance.disp import run_deck
from kinestat.spatial.displacement import frame_from_triple
from kinestat.viz import headless
from kinestat.viz.cell_scene import cell_scene, read_cycle_log
from kinestat.viz.html import render_html
from kinestat.viz.scene import guidance_scene, model_scene, platform_scene, screw_scene

pytestmark = pytest.mark.skipif(
    headless.find_browser() is None,
    reason="no headless Chromium: run `make browser` (installs the Debian package chromium as "
           "root) or set KINESTAT_BROWSER to a Chromium/Chrome executable")

#: a canvas showing something has a grey-level variance far above a blank one (0)
MIN_VARIANCE = 20.0


def _pages(rph_model_path, control_log):
    p = prototype()
    L = leg_lengths(p, p.home_pose) + np.array([0.5, 0.3, 0.0, 0.0, -0.2, 0.1])
    P1 = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0]], float)
    P2 = np.array([[2, 1, 0.5], [2, 1, 1.5], [2, 2, 0.5]], float)
    run = run_deck(embedded_deck("illustration5"))
    start, cycles, end = read_cycle_log(control_log)
    rph = kinestat.load(str(rph_model_path))
    return {
        "model": (kinestat.load("puma762"), np.radians([10, -30, 20, 5, 40, -15]), None),
        "model-rph": (rph, np.array([0.4, 120.0, -1.1]), None),
        "platform": (None, None, platform_scene(p, fk_list(p, L), legs=L)),
        "screw": (None, None, screw_scene(frame_from_triple(P1), frame_from_triple(P2),
                                          points1=P1, points2=P2)),
        "disp": (run.result.model, run.result.q[0], guidance_scene(run.result)),
        "log": (kinestat.load("puma762"), np.radians(cycles[0]["measured"]["joints_deg"]),
                cell_scene(start, cycles, end)),
    }


@pytest.fixture(scope="module")
def pages(tmp_path_factory, rph_model_path, control_log):
    d = tmp_path_factory.mktemp("pages")
    out = {}
    for name, (m, q, scene) in _pages(rph_model_path, control_log).items():
        if scene is None:
            scene = model_scene(m, q, show_frames=True)
        path = d / f"{name}.html"
        path.write_text(render_html(scene), encoding="utf-8")
        out[name] = (path, m, q)
    return out


@pytest.fixture(scope="module")
def browser():
    with headless.Browser() as b:
        yield b


@pytest.mark.parametrize("name", ["model", "model-rph", "platform", "screw", "disp", "log"])
def test_page_loads_draws_and_agrees_with_fk(pages, name, browser):
    path, m, q = pages[name]
    page = browser.load(path)
    status = page.status
    assert status.get("ready"), (status, page.console)
    assert status["errors"] == [] and page.console == (), (status["errors"], page.console)
    assert status["webgl"]
    assert headless.canvas_variance(page.png) > MIN_VARIANCE
    if m is not None:  # the page's own FK (the sliders' code) against kinestat
        F_js = np.array(status["fk_frames"])
        np.testing.assert_allclose(F_js, fk_frames(m, q), atol=1e-9, rtol=0)
        np.testing.assert_allclose(F_js[-1], kinestat.fk(m, q), atol=1e-9, rtol=0)


def test_blank_canvas_is_detected(tmp_path, browser):
    """The variance check can fail: a scene with nothing in it leaves the canvas blank."""
    scene = model_scene(kinestat.load("puma762"))
    scene.update(robot=None, items=[], frames=[])
    path = tmp_path / "empty.html"
    path.write_text(render_html(scene), encoding="utf-8")
    page = browser.load(path)
    assert page.status["ready"] and page.status["errors"] == [] and page.console == ()
    assert headless.canvas_variance(page.png) < 1.0


def test_script_error_is_reported(tmp_path, browser):
    """A broken scene is caught: no status, and the exception is on the console."""
    scene = model_scene(kinestat.load("puma762"))
    scene["items"] = [{"type": "no-such-item"}]
    path = tmp_path / "broken.html"
    path.write_text(render_html(scene), encoding="utf-8")
    page = browser.load(path, screenshot=False)
    assert not page.status.get("ready")
    assert any("no-such-item" in line for line in page.console)
