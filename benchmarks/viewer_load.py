"""How fast viewer pages load in headless Chromium: a DISP run of about 1000 steps and a control
log of 200 cycles (the goal: each under 2 s from navigation to a drawn first frame).

The DISP run is illustration5 with ``--steps 1000``. The control log is a real simulated run
(``kinestat control --log``) whose cycle records are repeated, renumbered, up to 200 cycles (a
converging run takes about six). Reported per page: the HTML size, the time the page itself
measures from navigation start to its first rendered frame (``load_ms``: HTML and script parse,
scene JSON parse, building the scene, first render), and the wall time from navigation to the
load event seen over the DevTools protocol; best and median of ``--repeat`` loads.

Run: ``.venv/bin/python benchmarks/viewer_load.py [--repeat 5] [--json]``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

from kinestat.cli.main import main as kinestat_main
from kinestat.viz import headless
from kinestat.viz.html import extract_scene


def _control_log(d: Path, cycles: int) -> Path:
    src = d / "run" / "log.jsonl"
    assert kinestat_main(["control", "--log", str(src), "--no-plot", "--json"]) == 0
    recs = [json.loads(line) for line in src.read_text().splitlines() if line.strip()]
    start = [r for r in recs if r.get("type") == "start"]
    cyc = [r for r in recs if r.get("type") == "cycle"]
    end = [r for r in recs if r.get("type") == "end"]
    out = []
    for k in range(cycles):
        r = dict(cyc[k % len(cyc)])
        r["cycle"] = k + 1
        out.append(r)
    big = d / "log200.jsonl"
    big.write_text("".join(json.dumps(r) + "\n" for r in start + out + end))
    return big


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    if headless.find_browser() is None:
        print("no headless Chromium: run `make browser`", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        disp_html, log_html = d / "disp.html", d / "log.html"
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            assert kinestat_main(["view", "disp", "illustration5", "--steps", "1000",
                                  "--html", str(disp_html)]) == 0
            log = _control_log(d, 200)
            assert kinestat_main(["view", "log", str(log), "--html", str(log_html)]) == 0
        rows = []
        with headless.Browser() as b:
            for name, path in (("DISP run", disp_html), ("control log", log_html)):
                steps = len(extract_scene(path.read_text())["steps"])
                page_ms, wall_ms = [], []
                for _ in range(args.repeat):
                    r = b.load(path, screenshot=False)
                    if not r.status.get("ready") or r.console:
                        print(f"{name}: the page failed: {r.console}", file=sys.stderr)
                        return 1
                    page_ms.append(r.status["load_ms"])
                    wall_ms.append(1e3 * r.seconds)
                rows.append({"page": name, "steps": steps,
                             "html_mib": path.stat().st_size / 2**20,
                             "page_ms_best": min(page_ms),
                             "page_ms_median": statistics.median(page_ms),
                             "wall_ms_best": min(wall_ms),
                             "wall_ms_median": statistics.median(wall_ms),
                             "under_2s": bool(np.median(wall_ms) < 2000.0)})
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        print(f"{'page':12} {'steps':>6} {'HTML MiB':>9} {'page ms (best/median)':>22} "
              f"{'load event ms (best/median)':>28}")
        for r in rows:
            print(f"{r['page']:12} {r['steps']:6d} {r['html_mib']:9.2f} "
                  f"{r['page_ms_best']:10.0f} / {r['page_ms_median']:<9.0f} "
                  f"{r['wall_ms_best']:14.0f} / {r['wall_ms_median']:<9.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
