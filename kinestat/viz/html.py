"""Render a viewer scene (:mod:`kinestat.viz.scene`) as one self-contained HTML page.

The page inlines three.js (vendored in ``kinestat/data/viewer/``, MIT licence), the viewer
script and the scene JSON (``<script type="application/json" id="kinestat-scene">``), so the
file opens offline from disk and the served page is the very same document.
"""

from __future__ import annotations

import json
import re
from functools import cache
from importlib import resources

__all__ = ["scene_json", "render_html", "extract_scene", "THREE_VERSION"]

#: the three.js release vendored in kinestat/data/viewer/vendor/three.min.js
THREE_VERSION = "0.187.0"

_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<link rel="icon" href="data:,">
<meta name="generator" content="kinestat viewer (three.js __THREE__)">
<title>__TITLE__</title>
<style>
html, body { margin: 0; height: 100%; font: 13px system-ui, sans-serif; color: #222; }
#view { position: absolute; inset: 0 330px 0 0; }
#side { position: absolute; top: 0; right: 0; bottom: 0; width: 330px; overflow: auto;
  box-sizing: border-box; padding: 10px; background: #fff; border-left: 1px solid #ccc; }
#side h1 { font-size: 15px; margin: 0 0 6px; }
#side pre { font-size: 11px; white-space: pre-wrap; margin: 6px 0; }
#sliders label { display: grid; grid-template-columns: 60px 1fr 70px; align-items: center; }
.swatch { display: inline-block; width: 11px; height: 11px; margin-right: 6px;
  border: 1px solid #555; vertical-align: middle; }
#legend div { margin: 2px 0; }
#player { margin: 6px 0; }
#timeline { width: 100%; }
</style>
</head>
<body>
<div id="view"></div>
<div id="side">
<h1 id="title"></h1>
<label><input type="checkbox" id="show-frames"> joint frames</label>
<div id="player" hidden><button id="play">play</button> <span id="step-label"></span>
<input type="range" id="timeline" min="0" max="0" step="1" value="0"></div>
<div id="sliders"></div>
<div id="ik" hidden><div>IK: drag the orange ball, or type a target</div>
<input id="ik-target" size="28" placeholder="x,y,z target of the end">
<button id="ik-go">IK</button><div id="ik-out"></div><select id="ik-pick" hidden></select></div>
<pre id="pose"></pre>
<pre id="info"></pre>
<div id="legend"></div>
<pre id="kinestat-status" hidden></pre>
</div>
<script type="application/json" id="kinestat-scene">__SCENE__</script>
<script>__THREEJS__</script>
<script>__VIEWER__</script>
</body>
</html>
"""


@cache
def _asset(*parts: str) -> str:
    return resources.files("kinestat.data").joinpath("viewer", *parts).read_text(encoding="utf-8")


def scene_json(scene: dict) -> str:
    """The scene as JSON safe inside a ``<script>`` element (no ``</``, no NaN)."""
    text = json.dumps(scene, allow_nan=False, separators=(",", ":"))
    return text.replace("<", "\\u003c")


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def render_html(scene: dict, *, meshes: str = "embed") -> str:
    """The self-contained page showing ``scene``."""
    parts = {
        "__THREE__": THREE_VERSION,
        "__TITLE__": _escape(f"kinestat: {scene.get('title', 'viewer')}"),
        "__SCENE__": scene_json(scene),
        "__THREEJS__": _asset("vendor", "three.min.js").replace("</script", "<\\/script"),
        "__VIEWER__": _asset("viewer.js"),
    }
    # one pass over the template: inserted text is never scanned for placeholders
    return re.sub(r"__(THREE|TITLE|SCENE|THREEJS|VIEWER)__", lambda m: parts[m.group(0)], _PAGE)


def extract_scene(html: str) -> dict:
    """The scene JSON embedded in a viewer page (the inverse of :func:`render_html`)."""
    start_tag = '<script type="application/json" id="kinestat-scene">'
    i = html.index(start_tag) + len(start_tag)
    j = html.index("</script>", i)
    return json.loads(html[i:j])
