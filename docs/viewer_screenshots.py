"""Make the screenshots of docs/viewer.md: each kind of `kinestat view` page, written with
``--html`` and photographed in headless Chromium (kinestat.viz.headless) at 1280x800, with the
browser tests' checks (kinestat.viz.headless.page_problems): the viewer finished, nothing on
the console, the canvas not blank, the scene inside the frame, the floor in view, nothing
spilling out of the side panel. A page failing them is not photographed (exit status 1).

Run: ``.venv/bin/python docs/viewer_screenshots.py [OUTDIR]`` (default docs/img). Needs a
Chromium (``make browser``) and example-robot-data (requirements/dev.txt) for the UR5. The
control run is simulated (``kinestat control --task follow``).
"""

from __future__ import annotations

import contextlib
import io
import sys
import tempfile
from pathlib import Path

from kinestat.cli.main import main as kinestat
from kinestat.viz import headless
from kinestat.viz.html import extract_scene

VIEWS = {
    "model": (["puma762", "--q-deg", "30,-40,30,10,50,0", "--frames"], None),
    "model-ur5": (["{ur5}", "--tip", "tool0", "--q-deg", "20,-70,100,-120,-90,30"], None),
    "model-rph": (["model", "{rph}", "--q", "0.6,150,-1.2", "--frames"], None),
    "platform": (["platform", "--legs", "81.47,81.27,80.97,68,67.8,68.1"], None),
    "screw": (["screw", "--points1", "0,0,0,0,0,1,1,0,0",
               "--points2", "2,1,0.5,2,1,1.5,2,2,0.5"], None),
    "disp": (["disp", "illustration4"], "middle"),
    "log": (["log", "{log}"], "last"),
}

RPH = """name = "rph-example"
notation = "standard_dh"
length_unit = "mm"
angle_unit = "deg"
[[joints]]
type = "revolute"
theta = 10.0
d = 300.0
a = 50.0
alpha = 90.0
[[joints]]
type = "prismatic"
theta = 0.0
d = 100.0
a = 200.0
alpha = -90.0
limits = [0.0, 400.0]
[[joints]]
type = "screw"
pitch = 20.0
theta = 30.0
d = 40.0
a = 120.0
alpha = 45.0
"""


def main(argv: list[str]) -> int:
    out = Path(argv[1] if len(argv) > 1 else Path(__file__).parent / "img")
    out.mkdir(parents=True, exist_ok=True)
    from importlib.metadata import distribution

    ur5 = Path(str(distribution("example-robot-data").locate_file(
        "cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf")))
    with tempfile.TemporaryDirectory() as tmp, headless.Browser(size=(1280, 800)) as b:
        d = Path(tmp)
        (d / "rph.toml").write_text(RPH, encoding="utf-8")
        log = d / "run" / "log.jsonl"
        with contextlib.redirect_stdout(io.StringIO()):
            assert kinestat(["control", "--task", "follow", "--travel", "15", "--log", str(log),
                             "--no-plot", "--json"]) == 0
        for name, (args, at) in VIEWS.items():
            page = d / f"{name}.html"
            args = [a.format(rph=d / "rph.toml", log=log, ur5=ur5) for a in args]
            with contextlib.redirect_stdout(io.StringIO()):
                assert kinestat(["view", *args, "--html", str(page)]) == 0
            n = len(extract_scene(page.read_text(encoding="utf-8"))["steps"])
            frag = {"middle": f"step={n // 2}", "last": f"step={n - 1}"}.get(at, "")
            r = b.load(page, fragment=frag, evaluate=headless.PANEL_OVERFLOW_JS)
            problems = headless.page_problems(r)
            if problems:
                print(f"{name}: {'; '.join(problems)}", file=sys.stderr)
                return 1
            png = out / f"viewer-{name}.png"
            png.write_bytes(r.png)
            print(f"{png}: canvas variance {headless.canvas_variance(r.png):.0f}, "
                  f"loaded in {r.status['load_ms']:.0f} ms")
        served(b, out)
    return 0


def served(b: headless.Browser, out: Path) -> None:
    """The served PUMA page after an IK request through the page (the gizmo's ball moved)."""
    import threading

    import numpy as np

    import kinestat
    from kinestat.viz.scene import model_scene
    from kinestat.viz.serve import make_server

    m = kinestat.load("puma762")
    q = np.radians([30, -40, 20, 10, 50, 0])
    target = (kinestat.fk(m, q)[:3, 3] + [-150.0, 100.0, 120.0]).tolist()
    srv = make_server(model_scene(m, q), model=m)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        js = ("(async () => { const v = window.kinestatViewer; "
              f"v.gizmo.object.position.set({target[0]}, {target[1]}, {target[2]}); "
              f"await v.ikTo({target}); return 1; }})()")
        r = b.load(f"http://127.0.0.1:{srv.server_address[1]}/", evaluate=js)
    finally:
        srv.shutdown()
        srv.server_close()
    png = out / "viewer-model-served.png"
    png.write_bytes(r.png)
    print(f"{png}: served page after IK, console {list(r.console)}")


if __name__ == "__main__":
    sys.exit(main(sys.argv))
