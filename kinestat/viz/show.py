"""Open a viewer page in the browser: what ``kinestat view`` without ``--html`` and the
``--view`` flag of ``platform fk``, ``screw``, ``disp``, ``guide`` and ``control`` do.

The page is written to a temporary HTML file (its path goes to stderr, so ``--json`` output
stays clean) and handed to the system's browser (:mod:`webbrowser`); with ``--html FILE`` it is
written to FILE and no browser is opened.
"""

from __future__ import annotations

import os
import sys
import tempfile
import webbrowser
from pathlib import Path

from kinestat.io.textfile import write_text_atomic
from kinestat.viz.html import render_html

__all__ = ["show", "show_platform_modes", "show_screw", "show_guidance", "show_log"]


def show(scene: dict, *, open_browser: bool = True, html: str | os.PathLike | None = None,
         meshes: str = "embed") -> Path:
    """Write ``scene``'s page to ``html`` (then no browser is opened) or to a temporary file
    that is opened; returns the path."""
    if html is not None:
        path = Path(html)
        write_text_atomic(path, render_html(scene, meshes=meshes))
        print(f"kinestat: 3D view written to {path}", file=sys.stderr)
        return path
    fd, name = tempfile.mkstemp(prefix=f"kinestat-{scene.get('kind', 'view')}-", suffix=".html")
    os.close(fd)
    path = Path(name)
    write_text_atomic(path, render_html(scene, meshes=meshes))
    print(f"kinestat: 3D view written to {path}", file=sys.stderr)
    if open_browser and not webbrowser.open(path.resolve().as_uri()):
        print("kinestat: no browser found; open the file above", file=sys.stderr)
    return path


def show_platform_modes(platform, poses, legs=None, html=None, physical: int = 0) -> Path:
    """Every assembly mode side by side (``kinestat platform fk --view``)."""
    from kinestat.viz.scene import platform_scene  # lazy: keeps show's import light

    return show(platform_scene(platform, poses, legs=legs, physical=physical), html=html)


def show_screw(T1, T2, points1=None, points2=None, html=None) -> Path:
    """Both positions and the screw axis (``kinestat screw --view``)."""
    from kinestat.viz.scene import screw_scene  # lazy: keeps show's import light

    return show(screw_scene(T1, T2, points1=points1, points2=points2), html=html)


def show_guidance(result, title: str = "guidance run", html=None) -> Path:
    """A guidance run as an animation (``kinestat disp/guide --view``)."""
    from kinestat.viz.scene import guidance_scene  # lazy: keeps show's import light

    return show(guidance_scene(result, title=title), html=html)


def show_log(log_path, html=None) -> Path:
    """Replay a control run's cycle log (``kinestat control --view``)."""
    from kinestat.viz.cell_scene import cell_scene, read_cycle_log  # lazy: as above

    start, cycles, end = read_cycle_log(log_path)
    return show(cell_scene(start, cycles, end, title=f"control run {log_path}"), html=html)
