"""Render a viewer scene (:mod:`kinestat.viz.scene`) as one self-contained HTML page.

The page (template ``kinestat/data/viewer/page.html``) inlines three.js (vendored in
``kinestat/data/viewer/``, MIT licence), the viewer script, the scene JSON
(``<script type="application/json" id="kinestat-scene">``) and the embedded meshes
(``id="kinestat-meshes"``, base64 by key), so the file opens offline from disk and the served
page is the very same document.
"""

from __future__ import annotations

import base64
import json
import re
from functools import cache
from importlib import resources
from pathlib import Path

from kinestat.errors import InputError

__all__ = ["scene_json", "render_html", "extract_scene", "THREE_VERSION"]

#: the three.js release vendored in kinestat/data/viewer/vendor/three.min.js
THREE_VERSION = "0.187.0"



@cache
def _asset(*parts: str) -> str:
    return resources.files("kinestat.data").joinpath("viewer", *parts).read_text(encoding="utf-8")


def scene_json(scene: dict) -> str:
    """The scene as JSON safe inside a ``<script>`` element (no ``</``, no NaN)."""
    text = json.dumps(scene, allow_nan=False, separators=(",", ":"))
    return text.replace("<", "\\u003c")


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def _with_meshes(scene: dict, mode: str) -> tuple[dict, dict]:
    """The scene as the page gets it, and the embedded mesh files (base64 by key): ``embed``
    puts every file in the page (one offline file), ``link`` points at the files (``url``),
    ``none`` drops the meshes (the stick figure alone)."""
    if mode not in ("embed", "link", "none"):
        raise InputError(f"--meshes must be embed, link or none, got {mode!r}")
    records = scene.get("meshes") or []
    if not records:
        return scene, {}
    if mode == "none":
        return {**scene, "meshes": [], "mesh_messages": [*scene.get("mesh_messages", []),
                                                         "meshes not drawn (--meshes none)"]}, {}
    out, data = [], {}
    for k, m in enumerate(records):
        m = {key: v for key, v in m.items() if key != "path"}
        if mode == "link":
            m["url"] = Path(records[k]["path"]).resolve().as_uri()
        else:
            try:
                raw = Path(records[k]["path"]).read_bytes()
            except OSError as exc:
                raise InputError(f"cannot read the mesh {records[k]['path']!r}: {exc}") from exc
            m["data"] = f"m{k}"
            data[f"m{k}"] = base64.b64encode(raw).decode("ascii")
        out.append(m)
    return {**scene, "meshes": out}, data


def render_html(scene: dict, *, meshes: str = "embed") -> str:
    """The self-contained page showing ``scene``; ``meshes`` as :func:`_with_meshes`."""
    scene, data = _with_meshes(scene, meshes)
    parts = {
        "__MESHES__": scene_json(data),
        "__THREE__": THREE_VERSION,
        "__TITLE__": _escape(f"kinestat: {scene.get('title', 'viewer')}"),
        "__SCENE__": scene_json(scene),
        "__THREEJS__": _asset("vendor", "three.min.js").replace("</script", "<\\/script"),
        "__VIEWER__": _asset("viewer.js"),
    }
    # one pass over the template: inserted text is never scanned for placeholders
    return re.sub(r"__(THREE|TITLE|SCENE|MESHES|THREEJS|VIEWER)__", lambda m: parts[m.group(0)],
                  _asset("page.html"))


def extract_scene(html: str) -> dict:
    """The scene JSON embedded in a viewer page (the inverse of :func:`render_html`)."""
    start_tag = '<script type="application/json" id="kinestat-scene">'
    i = html.index(start_tag) + len(start_tag)
    j = html.index("</script>", i)
    return json.loads(html[i:j])
