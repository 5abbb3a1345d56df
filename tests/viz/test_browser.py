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
from kinestat.viz.html import extract_scene, render_html
from kinestat.viz.scene import model_scene

pytestmark = pytest.mark.skipif(
    headless.find_browser() is None,
    reason="no headless Chromium: run `make browser` (installs the Debian package chromium as "
           "root) or set KINESTAT_BROWSER to a Chromium/Chrome executable")

#: a canvas showing something has a grey-level variance far above a blank one (0)
MIN_VARIANCE = 20.0


def _views(rph_model_path, control_log, ur5_path):
    """Every kind of page, each as `kinestat view … --html` writes it: (args, model, q)."""
    log = read_cycle_log(control_log)[1]
    res = run_deck(embedded_deck("illustration5")).result
    ur5 = kinestat.load(str(ur5_path), tip="tool0")
    p762 = kinestat.load("puma762")
    return {
        "model-ur5-meshes": ([str(ur5_path), "--tip", "tool0", "--q-deg",
                              "20,-60,80,-110,-90,30"], ur5, np.radians([20, -60, 80, -110, -90,
                                                                         30])),
        "model-opens-in-limits": (["puma762"], p762, np.clip(0, p762.lower, p762.upper)),
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
    from tests.urdf_arms import arm_path

    d = tmp_path_factory.mktemp("pages")
    out = {}
    for name, (args, m, q) in _views(rph_model_path, control_log, arm_path("ur5")).items():
        path = d / f"{name}.html"
        assert main(["view", *args, "--html", str(path)]) == 0
        out[name] = (path, m, q)
    return out


@pytest.fixture(scope="module")
def browser():
    with headless.Browser() as b:
        yield b


OVERFLOW_JS = headless.PANEL_OVERFLOW_JS


PAGES = ["model", "model-rph", "model-ur5-meshes", "model-opens-in-limits", "platform", "screw",
         "disp", "log"]


@pytest.mark.parametrize("name", PAGES)
def test_page_loads_draws_and_agrees_with_fk(pages, name, browser):
    """Every page kind: drawn (not blank), nothing on the console, the model inside the frame
    and the floor in view, nothing spilling out of the side panel."""
    path, m, q = pages[name]
    page = browser.load(path, evaluate=OVERFLOW_JS)
    status = page.status
    assert status.get("ready"), (status, page.console)
    assert status["errors"] == [] and page.console == (), (status["errors"], page.console)
    assert status["webgl"]
    assert headless.canvas_variance(page.png) > MIN_VARIANCE
    assert status["in_frame"] and status["floor_visible"], status.get("floor")
    assert page.value == {"bad": [], "panel": 0}, page.value
    assert headless.page_problems(page, min_variance=MIN_VARIANCE) == []
    if name == "model-ur5-meshes":  # every visual mesh of the UR5 loaded and drawn
        assert status["meshes"] == {"loaded": 7, "failed": []}
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


LIMITS_JS = """(() => {
  const el = document.getElementById("joint1"), out = el.nextSibling, v = window.kinestatViewer;
  const first = {value: Number(el.value), label: out.textContent, min: Number(el.min),
                 max: Number(el.max)};
  const moved = [];
  for (const x of [0, -50, 400, 123.4]) {
    el.value = x; el.dispatchEvent(new Event("input"));
    moved.push({value: Number(el.value), label: out.textContent});
  }
  return {first: first, moved: moved, frames: v.status.fk_frames};
})()"""


def test_model_opens_within_limits_and_sliders_stay_there(pages, browser):
    """The PUMA 762's joint 1 is limited to [20°, 340°]: the page opens at 20° (nearest zero),
    slider and label agree, and no value typed or dragged takes it outside."""
    path, m, q = pages["model-opens-in-limits"]
    s = extract_scene(path.read_text(encoding="utf-8"))
    np.testing.assert_allclose(s["q"], np.clip(0.0, m.lower, m.upper), atol=0)
    assert s["limits"][0] == [m.lower[0], m.upper[0]] and s["q_units"][0] == "rad"
    page = browser.load(path, screenshot=False, evaluate=LIMITS_JS)
    v = page.value
    assert v["first"]["value"] == pytest.approx(20.0) and v["first"]["label"] == "20.00°"
    assert (v["first"]["min"], v["first"]["max"]) == pytest.approx((20.0, 340.0))
    shown = [x["value"] for x in v["moved"]]
    assert shown == pytest.approx([20.0, 20.0, 340.0, 123.4])
    assert [x["label"] for x in v["moved"]] == ["20.00°", "20.00°", "340.00°", "123.40°"]
    q2 = np.clip(0.0, m.lower, m.upper)
    q2[0] = np.radians(123.4)  # the last value set: the page's FK is kinestat's there
    np.testing.assert_allclose(np.array(v["frames"]), fk_frames(m, q2), atol=1e-9, rtol=0)


FIT_JS = """(async () => {
  const v = window.kinestatViewer;
  v.camera.position.multiplyScalar(0.05); v.controls.target.set(1e4, 1e4, 0);
  v.controls.update(); v.publish();
  const before = v.status.in_frame;
  document.getElementById("fit").click(); v.publish();
  return {before: before, after: v.status.in_frame};
})()"""


@pytest.mark.parametrize("name", ["model", "log"])
def test_frame_all_brings_the_scene_back(pages, browser, name):
    """Looking away leaves the model out of the frame (the check can fail); "frame all"
    frames it again."""
    page = browser.load(pages[name][0], screenshot=False, evaluate=FIT_JS)
    assert page.value == {"before": False, "after": True}


MODES_JS = """(() => {
  const v = window.kinestatViewer, sel = document.getElementById("modes");
  const opts = [...sel.options].map(o => [Number(o.value), o.textContent]);
  const groups = () => [...document.querySelectorAll("#legend summary")].map(e => e.textContent);
  const first = {mode: v.status.mode, groups: groups()};
  sel.value = opts[2][0]; sel.dispatchEvent(new Event("change"));
  const second = {mode: v.status.mode, groups: groups()};
  return {opts: opts, first: first, second: second};
})()"""


def test_platform_page_shows_one_mode_at_a_time(pages, browser):
    path = pages["platform"][0]
    s = extract_scene(path.read_text(encoding="utf-8"))
    page = browser.load(path, screenshot=False, evaluate=MODES_JS)
    v = page.value
    assert [o[0] for o in v["opts"]] == [m["index"] for m in s["modes"]]
    assert v["opts"][0][1].endswith("(physical)") and len(v["opts"]) == 8
    assert v["first"]["mode"] == s["modes"][0]["index"]
    assert len(v["first"]["groups"]) == 1 and v["first"]["groups"][0].startswith(
        s["modes"][0]["label"])
    k = s["modes"][2]["index"]
    assert v["second"]["mode"] == k and v["second"]["groups"][0].startswith(f"mode {k + 1}")


CURSOR_JS = """(() => {
  const t = document.getElementById("timeline"), v = window.kinestatViewer, out = [];
  for (const k of [0, Number(t.max), 2]) {
    t.value = k; t.dispatchEvent(new Event("input"));
    out.push({step: v.status.step, cursor: v.status.cursor.cycle});
  }
  return out;
})()"""


def test_replay_plot_cursor_follows_the_slider(pages, browser):
    path = pages["log"][0]
    s = extract_scene(path.read_text(encoding="utf-8"))
    n = len(s["steps"])
    assert s["series"]["cycle"] == [int(st["label"].split()[1][:-1]) for st in s["steps"]]
    page = browser.load(path, screenshot=False, evaluate=CURSOR_JS)
    assert page.value == [{"step": k, "cursor": s["series"]["cycle"][k]}
                          for k in (0, n - 1, 2)]


def test_long_names_and_state_strings_stay_in_the_panel(tmp_path, rph_model_path, control_log,
                                                        browser):
    """Joint names of 60 letters and a 135-letter state string: wrapped or truncated, nothing
    spills out of the side panel (the check fails on the unstyled page)."""
    from kinestat.viz.cell_scene import cell_scene

    long = "a_very_long_joint_name_that_goes_on_and_on_" + "x" * 17
    text = rph_model_path.read_text(encoding="utf-8").replace('name = "1"', f'name = "{long}"')
    model = tmp_path / "long.toml"
    model.write_text(text, encoding="utf-8")
    s = model_scene(kinestat.load(str(model)), [0.4, 120.0, -1.1])
    start, cycles, end = read_cycle_log(control_log)
    c = cell_scene(start, cycles, end)
    c["info"][0] = "135 cycles, states " + "abpt" * 33 + "abc"
    c["steps"][0]["label"] = "cycle 1: " + "z" * 140
    for name, scene in (("long-model", s), ("long-log", c)):
        path = tmp_path / f"{name}.html"
        path.write_text(render_html(scene), encoding="utf-8")
        page = browser.load(path, screenshot=False, evaluate=OVERFLOW_JS)
        assert page.console == () and page.value == {"bad": [], "panel": 0}, page.value
        bare = tmp_path / f"{name}-bare.html"  # without the panel's rules it does spill
        bare.write_text(render_html(scene).replace("overflow-wrap: anywhere", "")
                        .replace("text-overflow: ellipsis;", "").replace(
                            "grid-template-columns: 84px", "grid-template-columns: auto"),
                        encoding="utf-8")
        page = browser.load(bare, screenshot=False, evaluate=OVERFLOW_JS)
        assert page.value["bad"] or page.value["panel"] > 0
