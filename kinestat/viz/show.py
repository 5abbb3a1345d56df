"""Open a viewer page in the browser: what ``kinestat view`` without ``--html`` and the
``--view`` flag of ``platform fk``, ``screw``, ``disp``, ``guide`` and ``control`` do.

The page is written to a temporary HTML file (its path goes to stderr, so ``--json`` output
stays clean) and handed to the system's browser (:mod:`webbrowser`).
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


def show(scene: dict, *, open_browser: bool = True) -> Path:
    """Write ``scene``'s page to a temporary file, open it; returns the path."""
    fd, name = tempfile.mkstemp(prefix=f"kinestat-{scene.get('kind', 'view')}-", suffix=".html")
    os.close(fd)
    path = Path(name)
    write_text_atomic(path, render_html(scene))
    print(f"kinestat: 3D view written to {path}", file=sys.stderr)
    if open_browser and not webbrowser.open(path.resolve().as_uri()):
        print("kinestat: no browser found; open the file above", file=sys.stderr)
    return path


def show_platform_modes(platform, poses, legs=None) -> Path:
    """Every assembly mode side by side (``kinestat platform fk --view``)."""
    from kinestat.viz.scene import platform_scene  # lazy: keeps show's import light

    return show(platform_scene(platform, poses, legs=legs))


def show_screw(T1, T2, points1=None, points2=None) -> Path:
    """Both positions and the screw axis (``kinestat screw --view``)."""
    from kinestat.viz.scene import screw_scene  # lazy: keeps show's import light

    return show(screw_scene(T1, T2, points1=points1, points2=points2))


def show_guidance(result, title: str = "guidance run") -> Path:
    """A guidance run as an animation (``kinestat disp/guide --view``)."""
    from kinestat.viz.scene import guidance_scene  # lazy: keeps show's import light

    return show(guidance_scene(result, title=title))


def show_log(log_path) -> Path:
    """Replay a control run's cycle log (``kinestat control --view``)."""
    from kinestat.viz.cell_scene import cell_scene, read_cycle_log  # lazy: as above

    start, cycles, end = read_cycle_log(log_path)
    return show(cell_scene(start, cycles, end, title=f"control run {log_path}"))
