"""``kinestat view``: every view writes a page whose scene matches kinestat; bad input exits 2."""

from __future__ import annotations

import socket

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.viz.html import extract_scene


def _scene(path):
    return extract_scene(path.read_text(encoding="utf-8"))


def _frames(scene) -> dict:
    return {f["name"]: np.array(f["pose"]) for f in scene["frames"]}


def test_view_model_html(tmp_path, capsys):
    out = tmp_path / "m.html"
    assert main(["view", "model", "puma762", "--q-deg", "30,-30,20,5,40,-15", "--html",
                 str(out)]) == 0
    assert str(out) in capsys.readouterr().out
    s = _scene(out)
    m = kinestat.load("puma762")
    q = np.radians([30, -30, 20, 5, 40, -15])
    np.testing.assert_allclose(_frames(s)["end"], kinestat.fk(m, q), atol=1e-9, rtol=0)


def test_view_platform_screw_disp_log(tmp_path, control_log):
    legs = "81.47,81.27,80.97,68,67.8,68.1"
    assert main(["view", "platform", "--legs", legs, "--html", str(tmp_path / "p.html")]) == 0
    assert _scene(tmp_path / "p.html")["kind"] == "platform"
    assert main(["view", "screw", "--points1", "0,0,0,0,0,1,1,0,0", "--points2",
                 "2,1,0,2,1,1,2,2,0", "--html", str(tmp_path / "s.html")]) == 0
    assert _scene(tmp_path / "s.html")["kind"] == "screw"
    assert main(["view", "disp", "illustration5", "--html", str(tmp_path / "d.html")]) == 0
    assert len(_scene(tmp_path / "d.html")["steps"]) > 10
    assert main(["view", "--log", str(control_log), "--html", str(tmp_path / "l.html")]) == 0
    assert main(["view", "log", str(control_log), "--html", str(tmp_path / "l2.html")]) == 0
    assert _scene(tmp_path / "l.html") == _scene(tmp_path / "l2.html")


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("kinestat: error: "), err
    return err[0]


def test_missing_and_foreign_logs(tmp_path, capsys):
    assert main(["view", "log", str(tmp_path / "nope.jsonl"), "--html",
                 str(tmp_path / "x.html")]) == 2
    assert "not found" in _one_error_line(capsys)
    old = tmp_path / "old.jsonl"
    old.write_text('{"kind": "start", "settings": {}}\n', encoding="utf-8")
    assert main(["view", "--log", str(old), "--html", str(tmp_path / "x.html")]) == 2
    assert "not a kinestat control cycle log of this version" in _one_error_line(capsys)
    assert not (tmp_path / "x.html").exists()


def test_port_in_use(capsys):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        port = s.getsockname()[1]
        assert main(["view", "model", "puma762", "--serve", "--port", str(port),
                     "--no-open"]) == 2
    line = _one_error_line(capsys)
    assert f"port {port}" in line and "in use" in line


@pytest.mark.parametrize("args,msg", [
    (["view", "model", "no-such-model", "--html", "x.html"], ""),
    (["view", "platform", "--legs", "1,2,3", "--html", "x.html"], "legs"),
    (["view", "screw", "--points1", "0,0,0,0,0,1,1,0,0", "--html", "x.html"], "points2"),
    (["view", "disp", "no-such-deck", "--html", "x.html"], "neither a file"),
    (["view", "disp", "illustration1", "--html", "x.html"], "no guidance run"),
    (["view"], "give a view"),
    (["view", "--html", "x.html", "model", "puma762"], "after the view's name"),
])
def test_bad_input_one_line(args, msg, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    assert msg in _one_error_line(capsys)


def test_serve_answers_page_scene_and_ik():
    import json
    import threading
    import urllib.request

    from kinestat.viz.scene import model_scene
    from kinestat.viz.serve import make_server

    m = kinestat.load("puma762")
    q = np.radians([40, -30, 20, 5, 40, -15])  # within the PUMA 762 limits (axis 1: 20..340)
    srv = make_server(model_scene(m, q), port=0, model=m)
    host, port = srv.server_address[:2]
    assert host == "127.0.0.1"
    th = threading.Thread(target=srv.serve_forever, daemon=True)
    th.start()
    try:
        base = f"http://127.0.0.1:{port}"
        page = urllib.request.urlopen(base + "/", timeout=10).read().decode()
        assert 'id="kinestat-scene"' in page
        scene = json.loads(urllib.request.urlopen(base + "/scene.json", timeout=10).read())
        assert scene["ik_url"] == "/ik"
        target = (kinestat.fk(m, q)[:3, 3] + [30.0, -20.0, 10.0]).tolist()
        req = urllib.request.Request(base + "/ik", method="POST",
                                     data=json.dumps({"q": q.tolist(), "target": target}).encode(),
                                     headers={"Content-Type": "application/json"})
        ans = json.loads(urllib.request.urlopen(req, timeout=30).read())
        assert len(ans["solutions"]) >= 2  # the PUMA's closed form gives several branches
        assert ans["outside_limits"] >= 0
        assert all(m.within_limits(np.array(sol)) for sol in ans["solutions"])
        for sol in ans["solutions"]:
            T = kinestat.fk(m, np.array(sol))
            np.testing.assert_allclose(T[:3, 3], target, atol=1e-6)
            np.testing.assert_allclose(T[:3, :3], kinestat.fk(m, q)[:3, :3], atol=1e-9)
    finally:
        srv.shutdown()
        srv.server_close()


@pytest.fixture
def opened(monkeypatch, tmp_path):
    """Record what the commands hand to the browser; temporary pages go to tmp_path."""
    import tempfile
    import webbrowser

    urls: list[str] = []
    monkeypatch.setattr(webbrowser, "open", lambda url, *a, **k: urls.append(url) or True)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    return urls


def _opened_scene(url: str) -> dict:
    from pathlib import Path
    from urllib.parse import urlparse
    from urllib.request import url2pathname

    return _scene(Path(url2pathname(urlparse(url).path)))


def test_view_flags_of_existing_commands(opened, capsys):
    import json

    legs = "81.47,81.27,80.97,68,67.8,68.1"
    assert main(["platform", "fk", "--legs", legs, "--json", "--view"]) == 0
    out = json.loads(capsys.readouterr().out)  # the JSON output stays clean
    s = _opened_scene(opened[-1])
    tops = [np.array(f["pose"]) for f in s["frames"] if f["name"].startswith("top")]
    assert s["kind"] == "platform" and len(tops) == out["count"]
    for T, sol in zip(tops, out["solutions"], strict=True):  # each mode where fk puts it
        np.testing.assert_allclose(T, np.array(sol["pose"]), atol=1e-9)
    assert s["modes"][0]["index"] == out["physical_mode"] - 1  # the physical one first
    assert main(["screw", "--points1", "0,0,0,0,0,1,1,0,0", "--points2", "2,1,0,2,1,1,2,2,0",
                 "--view"]) == 0
    assert _opened_scene(opened[-1])["kind"] == "screw"
    capsys.readouterr()
    assert main(["disp", "illustration5", "--json", "--view"]) == 0
    rec = json.loads(capsys.readouterr().out)
    s = _opened_scene(opened[-1])
    # one animation step per row of the DISP table; the hand path ends where DISP says
    assert s["kind"] == "disp" and len(s["steps"]) == len(rec["table"])
    np.testing.assert_allclose(s["items"][0]["points"], rec["hand_origins"], atol=1e-9)
    assert len(opened) == 3


def test_control_view_flag(control_run):
    log, urls, report = control_run
    assert report["converged"] and len(urls) == 1
    s = _opened_scene(urls[0])
    assert s["kind"] == "log"
    assert "".join(st["state"] for st in s["steps"]) == report["states"]


def test_serve_command_prints_its_loopback_address_and_serves():
    """`kinestat view model … --serve --no-open` in its own process: the printed address
    answers with the page; the process is stopped by its pid."""
    import os
    import re
    import signal
    import subprocess
    import sys
    import urllib.request
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    env = {**os.environ, "PYTHONPATH": str(root)}
    proc = subprocess.Popen(
        [sys.executable, "-c", "import sys; from kinestat.cli.main import main; "
         "sys.exit(main(sys.argv[1:]))", "view", "model", "puma762", "--serve", "--no-open"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = proc.stdout.readline()
        m = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
        assert m, line + proc.stderr.read() if proc.poll() is not None else line
        page = urllib.request.urlopen(m.group(0), timeout=20).read().decode()
        assert 'id="kinestat-scene"' in page and '"ik_url":"/ik"' in page
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130  # interrupted: "kinestat: interrupted"


def test_view_model_name_first_is_view_model(tmp_path):
    """`kinestat view MODEL …` is `kinestat view model MODEL …`: the same page."""
    a, b = tmp_path / "a.html", tmp_path / "b.html"
    args = ["--q-deg", "30,-30,20,5,40,-15", "--frames"]
    assert main(["view", "puma762", *args, "--html", str(a)]) == 0
    assert main(["view", "model", "puma762", *args, "--html", str(b)]) == 0
    assert _scene(a) == _scene(b)


def test_view_unknown_model_first_is_one_error(tmp_path, capsys):
    assert main(["view", "no-such-robot", "--html", str(tmp_path / "x.html")]) == 2
    assert "no-such-robot" in _one_error_line(capsys)


def test_html_flag_of_computing_commands(tmp_path, opened, capsys):
    """`--view --html FILE` writes the page there (no browser), the same scene `kinestat view`
    writes; the JSON output stays clean."""
    import json

    legs = "81.47,81.27,80.97,68,67.8,68.1"
    pts = ["--points1", "0,0,0,0,0,1,1,0,0", "--points2", "2,1,0,2,1,1,2,2,0"]
    cases = [
        (["platform", "fk", "--legs", legs], ["platform", "--legs", legs]),
        (["screw", *pts], ["screw", *pts]),
        (["disp", "illustration5"], ["disp", "illustration5"]),
    ]
    for k, (cmd, view) in enumerate(cases):
        a, b = tmp_path / f"a{k}.html", tmp_path / f"b{k}.html"
        assert main([*cmd, "--json", "--view", "--html", str(a)]) == 0
        json.loads(capsys.readouterr().out)
        assert main(["view", *view, "--html", str(b)]) == 0
        capsys.readouterr()
        assert _scene(a) == _scene(b), cmd
    g = tmp_path / "g.html"
    assert main(["guide", "puma762", "--q0-deg", "30,-30,20,5,40,-15", "--to",
                 "300,200,400,300,200,500,400,200,400", "--json", "--view", "--html",
                 str(g)]) in (0, 2)
    assert _scene(g)["kind"] == "disp" and len(_scene(g)["steps"]) > 1
    assert opened == []


def test_control_html_flag(tmp_path, capsys):
    log, page = tmp_path / "log.jsonl", tmp_path / "run.html"
    assert main(["control", "--log", str(log), "--no-plot", "--json", "--view", "--html",
                 str(page)]) == 0
    report = __import__("json").loads(capsys.readouterr().out)
    s = _scene(page)
    assert s["kind"] == "log"
    assert "".join(st["state"] for st in s["steps"]) == report["states"]
