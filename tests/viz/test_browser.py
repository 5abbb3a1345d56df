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
from kinestat.cli.main import main
from kinestat.disp import run_deck
from kinestat.io.disp_deck import embedded_deck
from kinestat.serial.fk import fk_frames
from kinestat.viz import headless
from kinestat.viz.cell_scene import read_cycle_log
from kinestat.viz.html import render_html
from kinestat.viz.scene import model_scene

pytestmark = pytest.mark.skipif(
    headless.find_browser() is None,
    reason="no headless Chromium: run `make browser` (installs the Debian package chromium as "
           "root) or set KINESTAT_BROWSER to a Chromium/Chrome executable")

#: a canvas showing something has a grey-level variance far above a blank one (0)
MIN_VARIANCE = 20.0


def _views(rph_model_path, control_log):
    """Every kind of page, each as `kinestat view … --html` writes it: (args, model, q)."""
    log = read_cycle_log(control_log)[1]
    res = run_deck(embedded_deck("illustration5")).result
    return {
        "model": (["model", "puma762", "--q-deg", "30,-30,20,5,40,-15", "--frames"],
                  kinestat.load("puma762"), np.radians([30, -30, 20, 5, 40, -15])),
        "model-rph": (["model", str(rph_model_path), "--q", "0.4,120,-1.1", "--frames"],
                      kinestat.load(str(rph_model_path)), np.array([0.4, 120.0, -1.1])),
        "platform": (["platform", "--legs", "81.47,81.27,80.97,68,67.8,68.1"], None, None),
        "screw": (["screw", "--points1", "0,0,0,0,0,1,1,0,0", "--points2",
                   "2,1,0.5,2,1,1.5,2,2,0.5"], None, None),
        "disp": (["disp", "illustration5"], res.model, res.q[0]),
        "log": (["log", str(control_log)], kinestat.load("puma762"),
                np.radians(log[0]["measured"]["joints_deg"])),
    }


@pytest.fixture(scope="module")
def pages(tmp_path_factory, rph_model_path, control_log):
    d = tmp_path_factory.mktemp("pages")
    out = {}
    for name, (args, m, q) in _views(rph_model_path, control_log).items():
        path = d / f"{name}.html"
        assert main(["view", *args, "--html", str(path)]) == 0
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


SLIDER_JS = """(() => {
  const el = document.getElementById("joint2");
  el.value = 37.3; el.dispatchEvent(new Event("input"));
  return {value: Number(el.value), frames: window.kinestatViewer.status.fk_frames};
})()"""


def test_slider_moves_the_arm_by_page_fk(pages, browser):
    """Dragging a slider recomputes every frame in the page, equal to kinestat.fk."""
    path, m, q = pages["model"]
    page = browser.load(path, screenshot=False, evaluate=SLIDER_JS)
    assert page.console == ()
    q2 = q.copy()
    q2[1] = np.radians(page.value["value"])  # the slider's value, on its step grid
    assert abs(page.value["value"] - 37.3) < 0.5
    np.testing.assert_allclose(np.array(page.value["frames"]), fk_frames(m, q2), atol=1e-9,
                               rtol=0)


IK_JS = """(async () => {
  document.getElementById("ik-target").value = "%s";
  document.getElementById("ik-go").click();
  const out = document.getElementById("ik-out");
  for (let i = 0; i < 600 && !out.textContent; i++) await new Promise(r => setTimeout(r, 50));
  const v = window.kinestatViewer;
  const first = {text: out.textContent, n: document.getElementById("ik-pick").options.length,
                 frames: v.status.fk_frames, gizmo: v.gizmo !== null};
  const ball = v.gizmo.object.position.toArray();   // where the gizmo's ball was put
  await v.ikTo(%s);                                 // what letting go of the ball does
  return {...first, ball: ball, frames2: v.status.fk_frames};
})()"""


def test_served_page_asks_the_server_for_ik(browser):
    """--serve: the page's IK box sends the target to the server and shows the answer."""
    import threading

    from kinestat.viz.serve import make_server

    m = kinestat.load("puma762")
    q = np.radians([30, -40, 20, 10, 50, 0])
    srv = make_server(model_scene(m, q), model=m)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        T0 = kinestat.fk(m, q)
        target = T0[:3, 3] + [40.0, -25.0, 15.0]
        url = f"http://127.0.0.1:{srv.server_address[1]}/"
        target2 = T0[:3, 3] + [-30.0, 20.0, -40.0]
        page = browser.load(url, screenshot=False, evaluate=IK_JS % (
            ",".join(repr(float(x)) for x in target), [float(x) for x in target2]))
    finally:
        srv.shutdown()
        srv.server_close()
    assert page.console == () and page.status["ready"]
    assert "solution" in page.value["text"] and page.value["n"] >= 2 and page.value["gizmo"]
    end = np.array(page.value["frames"])[-1]
    np.testing.assert_allclose(end[:3, 3], target, atol=1e-6)
    np.testing.assert_allclose(end[:3, :3], T0[:3, :3], atol=1e-9)
    np.testing.assert_allclose(page.value["ball"], target, atol=1e-9)  # the typed target
    end2 = np.array(page.value["frames2"])[-1]
    np.testing.assert_allclose(end2[:3, 3], target2, atol=1e-6)
    np.testing.assert_allclose(end2[:3, :3], T0[:3, :3], atol=1e-9)
