"""Viewer scenes: every pose equals what kinestat computes, independently of the scene code."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kinestat
from kinestat.errors import InputError
from kinestat.io.library import prototype
from kinestat.io.urdf import read_urdf, to_urdf
from kinestat.parallel.fk import fk_list
from kinestat.parallel.legs import leg_lengths, top_points_in_base
from kinestat.serial.fk import fk_frames
from kinestat.spatial.displacement import frame_from_triple, screw_from_poses
from kinestat.viz.cell_scene import cell_scene, read_cycle_log
from kinestat.viz.html import extract_scene, render_html
from kinestat.viz.scene import guidance_scene, model_scene, platform_scene, screw_scene


def _frames(scene) -> dict:
    return {f["name"]: np.array(f["pose"]) for f in scene["frames"]}


def _chain_ok(model, q, frames: dict):
    F = fk_frames(model, q)
    for i in range(model.n):
        np.testing.assert_allclose(frames[f"joint{i + 1}"], F[i], atol=1e-9, rtol=0)
    np.testing.assert_allclose(frames["end"], kinestat.fk(model, q), atol=1e-9, rtol=0)
    assert len(frames) == model.n + 1


@pytest.mark.parametrize("name", ["puma762", "puma560", "nadkarni-config1"])
def test_model_scene_frames_are_fk(name, rng):
    m = kinestat.load(name)
    lo = np.where(np.isfinite(m.lower), m.lower, -math.pi)
    hi = np.where(np.isfinite(m.upper), m.upper, math.pi)
    q = rng.uniform(lo, hi)
    s = json.loads(json.dumps(model_scene(m, q)))  # through JSON, as the page gets it
    _chain_ok(m, q, _frames(s))
    assert s["robot"]["live"] and len(s["robot"]["constants"]) == m.n + 1
    np.testing.assert_array_equal(s["robot"]["q"], q)


def test_rph_chain_and_urdf_round_trip(rph_model_path, tmp_path):
    m = kinestat.load(str(rph_model_path))
    assert [j.kind for j in m.joints] == ["revolute", "prismatic", "screw"]
    q = np.array([0.3, 150.0, -0.7])
    _chain_ok(m, q, _frames(model_scene(m, q)))
    assert model_scene(m, q)["robot"]["pitches"] == [0.0, 0.0, 20.0]
    p = kinestat.load("puma762")
    u = tmp_path / "puma.urdf"
    u.write_text(to_urdf(p), encoding="utf-8")
    mu = read_urdf(u)
    q6 = np.radians([30, -20, 30, -40, 50, -60])
    _chain_ok(mu, q6, _frames(model_scene(mu, q6)))


def test_platform_scene_modes_legs_and_wrench():
    p = prototype()
    L = leg_lengths(p, p.home_pose) + np.array([0.5, 0.3, 0.0, 0.0, -0.2, 0.1])
    poses = fk_list(p, L)
    s = platform_scene(p, poses, legs=L, physical=1)
    fr = _frames(s)
    np.testing.assert_array_equal(fr["base"], np.eye(4))
    for k, T in enumerate(poses):  # every mode in the base frame, as platform fk gives it
        np.testing.assert_allclose(fr[f"top{k + 1}"], T, atol=1e-12)
        # the legs drawn join the base points to the top points of this mode
        legs = [it for it in s["items"] if it["type"] == "segment" and it["mode"] == k]
        np.testing.assert_allclose([it["b"] for it in legs], top_points_in_base(p, T),
                                   atol=1e-9)
        np.testing.assert_allclose(np.linalg.norm(np.subtract([it["b"] for it in legs],
                                                              [it["a"] for it in legs]), axis=1),
                                   L, atol=1e-6)
        assert {it["group"] for it in s["items"] if it["mode"] == k} == {
            f"mode {k + 1}" + (" (physical)" if k == 1 else "")}
    # the selector: the physical mode first, then the others in order
    assert [m["index"] for m in s["modes"]] == [1, 0, *range(2, len(poses))]
    assert s["modes"][0]["label"] == "mode 2 (physical)"
    np.testing.assert_allclose(fr["end"], poses[1], atol=1e-12)
    # leg colours: tension reddish, compression bluish (leg P is stretched, S shortened)
    legs1 = {it["label"].split()[1][:-1]: it["color"]
             for it in s["items"] if it["type"] == "segment" and it["mode"] == 0}
    red = lambda c: int(c[1:3], 16) > int(c[5:7], 16)  # noqa: E731
    assert red(legs1["P"]) and not red(legs1["S"])


def test_platform_wrench_axis_is_the_line_of_action():
    p = prototype()
    T = p.home_pose.copy()
    T[:3, 3] += [0.4, -0.3, -0.5]
    s = platform_scene(p, [T])
    line = next(it for it in s["items"] if it["type"] == "line")
    arrow = next(it for it in s["items"] if it["type"] == "arrow")
    from kinestat.parallel.statics import spring_wrench

    w = spring_wrench(p, T)
    f, m0 = w[:3], w[3:]
    r = np.array(line["point"])
    # about a point of the axis the moment is parallel to the force (Poinsot)
    m_r = m0 - np.cross(r, f)
    assert np.linalg.norm(np.cross(m_r, f)) <= 1e-9 * np.linalg.norm(f) * max(
        np.linalg.norm(m_r), 1.0)
    np.testing.assert_allclose(np.cross(arrow["vector"], f), 0.0, atol=1e-9)


def test_screw_scene_axis_and_path():
    P1 = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0]], float)
    P2 = np.array([[2, 1, 0.5], [2, 1, 1.5], [2, 2, 0.5]], float)
    T1, T2 = frame_from_triple(P1), frame_from_triple(P2)
    s = screw_scene(T1, T2, points1=P1, points2=P2)
    sc = screw_from_poses(T1, T2)
    line = next(it for it in s["items"] if it["type"] == "line")
    np.testing.assert_allclose(np.cross(line["direction"], sc.axis), 0, atol=1e-12)
    # the axis drawn passes through the screw's point
    d = np.array(line["point"]) - sc.point
    np.testing.assert_allclose(np.cross(d, sc.axis), 0, atol=1e-9)
    path = np.array(next(it for it in s["items"] if it["type"] == "polyline")["points"])
    np.testing.assert_allclose(path[0], T1[:3, 3], atol=1e-9)
    np.testing.assert_allclose(path[-1], T2[:3, 3], atol=1e-9)
    # every path point keeps its distance to the axis (a helix about it)
    u = np.asarray(sc.axis)
    rel = path - sc.point
    radial = np.linalg.norm(rel - np.outer(rel @ u, u), axis=1)
    np.testing.assert_allclose(radial, radial[0], atol=1e-9)
    np.testing.assert_allclose(_frames(s)["end"], T2, atol=1e-12)


def test_guidance_scene_steps_follow_the_run():
    from kinestat.disp import run_deck
    from kinestat.io.disp_deck import embedded_deck

    run = run_deck(embedded_deck("illustration5"))
    res = run.result
    s = guidance_scene(res)
    assert len(s["steps"]) == res.q.shape[0]
    for k in (0, len(s["steps"]) // 2, len(s["steps"]) - 1):
        st = s["steps"][k]
        np.testing.assert_array_equal(st["q"], res.q[k])
        _chain_ok(res.model, res.q[k], {f["name"]: np.array(f["pose"]) for f in st["frames"]})
    _chain_ok(res.model, res.q[0], _frames(s))
    hand = np.array(s["items"][0]["points"])
    np.testing.assert_allclose(hand, kinestat.fk(res.model, res.q)[:, :3, 3], atol=1e-9)


def test_cell_scene_replays_the_log(control_log):
    start, cycles, end = read_cycle_log(control_log)
    s = cell_scene(start, cycles, end)
    m = kinestat.load("puma762")
    assert len(s["steps"]) == len(cycles)
    for st, c in zip(s["steps"], cycles, strict=True):
        q = np.radians(c["measured"]["joints_deg"])
        _chain_ok(m, q, {f["name"]: np.array(f["pose"]) for f in st["frames"]})
        assert st["state"] == c["state"]
        # the tool ends at the measured tip; the measured force arrow starts there
        tool = next(it for it in st["items"] if it["label"] == "tool")
        np.testing.assert_allclose(tool["b"], c["measured"]["tip"], atol=1e-12)
        # the end frame carries the logged tool axis (S6 = z of frame 6)
        np.testing.assert_allclose(np.array(st["frames"][-1]["pose"])[:3, 2],
                                   c["measured"]["tool_axis"], atol=1e-3)
    _chain_ok(m, np.radians(cycles[0]["measured"]["joints_deg"]), _frames(s))


@pytest.mark.parametrize("text,msg", [
    ('{"type": "cycle"}\n', "first record must be a 'start'"),
    ('{"type": "start", "config": {}}\n', "no 'cycle' record"),
    ('{"type": "start", "config": {}}\n{"type": "cycle", "cycle": 1, "measured": {}}\n',
     "lacks measured"),
    ("not json\n", "not JSON"),
])
def test_bad_logs_are_refused(tmp_path, text, msg):
    p = tmp_path / "log.jsonl"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=msg):
        read_cycle_log(p)
    with pytest.raises(InputError, match="not found"):
        read_cycle_log(tmp_path / "missing.jsonl")


def test_a_run_folder_reads_as_its_log(control_log, tmp_path):
    assert read_cycle_log(control_log.parent) == read_cycle_log(control_log)
    with pytest.raises(InputError, match="directory without a log.jsonl"):
        read_cycle_log(tmp_path)


def test_html_embeds_the_scene_verbatim():
    m = kinestat.load("puma762")
    s = model_scene(m)
    s["title"] = "a </script><script>alert(1)</script> title"
    html = render_html(s)
    assert extract_scene(html) == json.loads(json.dumps(s))
    # scene, meshes, three.js, viewer: nothing leaks out
    assert html.count("</script>") == 4
    assert "three.js 0.187.0" in html
