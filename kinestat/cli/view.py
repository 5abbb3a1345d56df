"""``kinestat view``: an interactive 3D page of a model, the platform, a screw, a DISP run or a
control run, written as one self-contained HTML file (``--html FILE``) or served on loopback
(``--serve``). Without either, the page is written to a temporary file and opened.

See docs/viewer.md for the scene format and what each page shows.
"""

from __future__ import annotations

import webbrowser
from pathlib import Path

import numpy as np
import typer
from typer.core import TyperGroup

from kinestat.cli._model import (
    MODEL_HELP,
    base_option,
    length_unit_option,
    load_model,
    scale_option,
    tip_option,
)
from kinestat.cli._options import (
    LEGS_METAVAR,
    POINTS3_METAVAR,
    POSE_FILE_METAVAR,
    POSE_METAVAR,
    Q_METAVAR,
    STEPS_METAVAR,
    WRENCH_METAVAR,
    check_output_file,
    flag,
    name_value,
    path_value,
)
from kinestat.cli._output import console, parse_floats, parse_pose
from kinestat.errors import InputError
from kinestat.io.textfile import write_text_atomic


class _ViewGroup(TyperGroup):
    """``kinestat view MODEL …`` is ``kinestat view model MODEL …``: a first word that names no
    view is taken as the model."""

    def resolve_command(self, ctx, args):
        if args and not args[0].startswith("-") and args[0] not in self.commands:
            return "model", self.commands["model"], args
        return super().resolve_command(ctx, args)


view_app = typer.Typer(
    name="view",
    help="3D views in the browser: MODEL (or model MODEL), platform, screw, disp, log (or "
    "--log FILE).",
    invoke_without_command=True,
    cls=_ViewGroup,
)

HTML_HELP = "Write the page to this HTML file (self-contained, opens offline)."
SERVE_HELP = "Serve the page on HOST:PORT until interrupted (IK answered by the server)."


def register(app: typer.Typer) -> None:
    app.add_typer(view_app, name="view")


class _Out:
    """The output options every view command takes."""

    def __init__(self, html: Path | None, serve: bool, host: str, port: int, no_open: bool,
                 allow_remote: bool = False):
        self.html, self.serve, self.host, self.port, self.no_open = html, serve, host, port, no_open
        self.allow_remote = allow_remote


def _out_options(html: Path | None, serve: bool, host: str, port: int, no_open: bool,
                 allow_remote: bool = False) -> _Out:
    if html is not None and serve:
        raise InputError("give either --html FILE or --serve, not both")
    if not 0 <= port <= 65535:
        raise InputError(f"--port must be 0..65535, got {port}")
    if allow_remote and not serve:
        raise InputError("--allow-remote goes with --serve")
    check_output_file(html, "--html")
    return _Out(html, serve, host, port, no_open, allow_remote)


def _emit(scene: dict, out: _Out, model=None, meshes: str = "embed") -> None:
    # lazy: the viewer (three.js page, HTTP server) loads only when a view is asked for
    from kinestat.viz.html import render_html

    if out.serve:
        # lazy: the HTTP server and IK only with --serve
        from kinestat.viz.serve import make_server

        if meshes == "none" and scene.get("meshes"):
            scene = {**scene, "meshes": [], "mesh_messages": [
                *scene.get("mesh_messages", []), "meshes not drawn (--meshes none)"]}
        srv = make_server(scene, host=out.host, port=out.port, model=model,
                          allow_remote=out.allow_remote)
        host, port = srv.server_address[:2]
        url = f"http://{host}:{port}/"
        console.print(f"kinestat view: serving {url} (Ctrl-C stops)")
        console.file.flush()  # the address must reach a pipe before serving blocks
        if not out.no_open:
            webbrowser.open(url)
        try:
            srv.serve_forever()
        finally:
            srv.server_close()
        return
    if out.html is None:
        from kinestat.viz.show import show  # lazy: as above

        show(scene, open_browser=not out.no_open, meshes=meshes)
        return
    write_text_atomic(out.html, render_html(scene, meshes=meshes))
    console.print(f"wrote {out.html}")


# The output options, repeated on every command (Typer has no shared option groups).
def _html_opt():
    return typer.Option(None, "--html", parser=path_value, help=HTML_HELP, metavar="FILE")


def _serve_opt():
    return flag(False, "--serve", help=SERVE_HELP)


def _host_opt():
    return typer.Option("127.0.0.1", "--host", help="Address to serve on (default loopback).",
                        metavar="HOST")


def _allow_remote_opt():
    return flag(False, "--allow-remote", help="With --serve: allow a non-loopback --host (the "
                "server answers IK to anyone who can reach it).")


def _port_opt():
    return typer.Option(0, "--port", help="Port to serve on (0: a free one, printed).",
                        metavar="PORT")


def _no_open_opt():
    return flag(False, "--no-open", help="Do not open a browser.")


@view_app.callback()
def view_root(
    ctx: typer.Context,
    log: Path = typer.Option(None, "--log", parser=path_value,
                             help="Replay a control run's cycle log "
                             "(same as `kinestat view log FILE`).", metavar="FILE"),
    html: Path = _html_opt(), serve: bool = _serve_opt(), host: str = _host_opt(),
    allow_remote: bool = _allow_remote_opt(), port: int = _port_opt(),
    no_open: bool = _no_open_opt(),
) -> None:
    """3D views in the browser (three.js): model, platform, screw, disp, log."""
    if ctx.invoked_subcommand is not None:
        if log is not None or html is not None or serve or port != 0 or no_open \
                or host != "127.0.0.1" or allow_remote:
            raise InputError(f"put the options after the view's name, e.g. kinestat view "
                             f"{ctx.invoked_subcommand} … --html FILE (--log goes alone)")
        return
    if log is None:
        raise InputError("give a view (model, platform, screw, disp, log) or --log FILE; "
                         "see kinestat view --help")
    view_log(log, None, html, serve, host, allow_remote, port, no_open)


@view_app.command("model")
def view_model(
    model: str = typer.Argument(..., parser=name_value, help=MODEL_HELP),
    q: str = typer.Option(None, "--q", help="Joint values shown first (radians / length).",
                         metavar=Q_METAVAR),
    q_deg: str = typer.Option(None, "--q-deg", help="Joint values, rotating joints in degrees.",
                              metavar=Q_METAVAR),
    frames: bool = flag(False, "--frames", help="Show every joint frame."),
    meshes: str = typer.Option("embed", "--meshes", metavar="embed|link|none", help="A URDF "
                               "model's visual meshes (STL, DAE, OBJ): in the page (one offline "
                               "file), linked to the files, or none (the stick figure)."),
    tip: str = tip_option(),
    base: str = base_option(),
    scale: float = scale_option(),
    length_unit: str = length_unit_option(),
    html: Path = _html_opt(), serve: bool = _serve_opt(), host: str = _host_opt(),
    allow_remote: bool = _allow_remote_opt(), port: int = _port_opt(),
    no_open: bool = _no_open_opt(),
) -> None:
    """A serial model with joint sliders (FK in the page); IK of a target with --serve."""
    # lazy: scenes load only for a view
    from kinestat.viz.scene import check_within_limits, model_scene

    out = _out_options(html, serve, host, port, no_open, allow_remote)
    m = load_model(model, tip, base, scale, length_unit)
    if q is not None and q_deg is not None:
        raise InputError("give at most one of --q and --q-deg")
    vals = None
    if q is not None:
        vals = parse_floats(q, m.n, "q")
    elif q_deg is not None:
        vals = parse_floats(q_deg, m.n, "q-deg")
        vals = np.where(m.prismatic, vals, np.deg2rad(vals))
    if vals is not None:
        check_within_limits(m, vals, "--q" if q is not None else "--q-deg")
    if meshes not in ("embed", "link", "none"):
        raise InputError(f"--meshes must be embed, link or none, got {meshes!r}")
    visuals = None
    if Path(model).suffix.lower() == ".urdf" and Path(model).is_file():
        from kinestat.viz.meshes import urdf_meshes  # lazy: only for a URDF

        visuals = urdf_meshes(model, m, base=base, scale=scale, length_unit=length_unit)
    _emit(model_scene(m, vals, show_frames=frames, meshes=visuals), out, model=m,
          meshes=meshes)


@view_app.command("platform")
def view_platform(
    legs: str = typer.Option(None, "--legs", help="Six leg lengths: show every assembly mode.",
                             metavar=LEGS_METAVAR),
    pose: str = typer.Option(None, "--pose", help="One pose instead ('home', a file or 16 "
                             "numbers).", metavar=POSE_METAVAR),
    wrench: str = typer.Option(None, "--wrench", help="Legs carry j^-1 w instead of their "
                               "spring forces: fx,fy,fz,mx,my,mz (moment about O0).",
                               metavar=WRENCH_METAVAR),
    platform: str = typer.Option(None, "--platform", parser=name_value,
                                 help="TOML platform file (default: the "
                                 "embedded 2011 prototype).", metavar="FILE"),
    html: Path = _html_opt(), serve: bool = _serve_opt(), host: str = _host_opt(),
    allow_remote: bool = _allow_remote_opt(), port: int = _port_opt(),
    no_open: bool = _no_open_opt(),
) -> None:
    """The platform: plates, legs coloured by force (red tension, blue compression), the
    wrench and its axis; with --legs every assembly mode side by side, the physical one marked."""
    from kinestat.viz.scene import platform_scene  # lazy: scenes load only for a view

    out = _out_options(html, serve, host, port, no_open, allow_remote)
    p, poses, L = _platform_poses(legs, pose, platform)
    w = None if wrench is None else parse_floats(wrench, 6, "wrench")
    _emit(platform_scene(p, poses, legs=L, wrench=w), out)


def _platform_poses(legs, pose, platform):
    # lazy: the platform and its FK load only for this view
    from kinestat.io.library import prototype
    from kinestat.io.platform_toml import read_platform
    from kinestat.parallel.fk import fk_list, fk_numeric
    from kinestat.parallel.legs import as_pose

    p = prototype() if platform is None else read_platform(platform)
    if legs is not None and pose is not None:
        raise InputError("give at most one of --legs and --pose")
    if legs is not None:
        L = parse_floats(legs, 6, "legs")
        if np.any(L <= 0):
            raise InputError("--legs: leg lengths must be positive")
        poses = fk_list(p, L) if p.layout is not None else [fk_numeric(p, L)]
        return p, poses, L
    if pose is None or pose.strip().lower() == "home":
        return p, [p.home_pose.copy()], None
    return p, [as_pose(parse_pose(pose, "pose"), "--pose")], None


@view_app.command("screw")
def view_screw(
    points1: str = typer.Option(None, "--points1", help="First position by three body points "
                                "x,y,z,x,y,z,x,y,z (origin, +z, z-x half plane).",
                                metavar=POINTS3_METAVAR),
    points2: str = typer.Option(None, "--points2", help="Second position, as --points1.",
                                metavar=POINTS3_METAVAR),
    pose1: str = typer.Option(None, "--pose1", help="First pose (file or 16 numbers).",
                              metavar=POSE_FILE_METAVAR),
    pose2: str = typer.Option(None, "--pose2", help="Second pose, as --pose1.",
                              metavar=POSE_FILE_METAVAR),
    html: Path = _html_opt(), serve: bool = _serve_opt(), host: str = _host_opt(),
    allow_remote: bool = _allow_remote_opt(), port: int = _port_opt(),
    no_open: bool = _no_open_opt(),
) -> None:
    """Both body positions, the screw axis, the rotation about and translation along it."""
    # lazy: scenes load only for a view
    from kinestat.spatial.displacement import frame_from_triple
    from kinestat.viz.scene import screw_scene

    out = _out_options(html, serve, host, port, no_open, allow_remote)
    by_points = points1 is not None or points2 is not None
    if by_points == (pose1 is not None or pose2 is not None):
        raise InputError("give either --points1 and --points2, or --pose1 and --pose2")
    if by_points:
        if points1 is None or points2 is None:
            raise InputError("both --points1 and --points2 are needed")
        P1 = parse_floats(points1, 9, "points1").reshape(3, 3)
        P2 = parse_floats(points2, 9, "points2").reshape(3, 3)
        scene = screw_scene(frame_from_triple(P1), frame_from_triple(P2), points1=P1,
                            points2=P2)
    else:
        if pose1 is None or pose2 is None:
            raise InputError("both --pose1 and --pose2 are needed")
        scene = screw_scene(parse_pose(pose1, "pose1"), parse_pose(pose2, "pose2"))
    _emit(scene, out)


@view_app.command("disp")
def view_disp(
    deck: str = typer.Argument(..., parser=name_value,
                               help="A DISP deck file or an embedded deck name."),
    steps: str = typer.Option(None, "--steps", help="Step count N, or N1,N2,… per stage.",
                              metavar=STEPS_METAVAR),
    disp_1977: bool = flag(False, "--disp-1977", help="The 1977 program's step rule."),
    html: Path = _html_opt(), serve: bool = _serve_opt(), host: str = _host_opt(),
    allow_remote: bool = _allow_remote_opt(), port: int = _port_opt(),
    no_open: bool = _no_open_opt(),
) -> None:
    """Animate a DISP deck's guidance run: the arm step by step, the hand path, events."""
    from kinestat.viz.scene import guidance_scene  # lazy: scenes load only for a view

    out = _out_options(html, serve, host, port, no_open, allow_remote)
    result, title = disp_result(deck, steps, disp_1977)
    _emit(guidance_scene(result, title=title), out)


def disp_result(deck: str, steps: str | None = None, disp_1977: bool = False):
    """The guidance result of a deck (MS 0, 4, 5, 6) and a title; InputError otherwise."""
    # lazy: the DISP program is only needed by this view
    from kinestat.cli._guidance import parse_steps
    from kinestat.disp import disp_options, run_deck
    from kinestat.io.disp_deck import embedded_deck, list_embedded_decks, read_deck

    if Path(deck).exists():
        d = read_deck(Path(deck))
    elif deck.strip().lower().removesuffix(".dat") in list_embedded_decks():
        d = embedded_deck(deck.strip().lower().removesuffix(".dat"))
    else:
        raise InputError(f"DECK {deck!r} is neither a file nor an embedded deck; embedded "
                         f"decks: {', '.join(list_embedded_decks())}")
    opts = disp_options(disp_1977=disp_1977, ms=d.ms)  # DISP's defaults, as `kinestat disp`
    run = run_deck(d, steps=parse_steps(steps), options=opts)
    if run.result is None:
        raise InputError(f"deck {deck!r} (MS = {d.ms}) has no guidance run to animate; "
                         "MS 0, 4, 5 and 6 guide the hand")
    return run.result, f"DISP MS = {d.ms}: {d.source}"


@view_app.command("log")
def view_log(
    log: Path = typer.Argument(..., parser=path_value,
                               help="A control run's cycle log (RUN/log.jsonl) or its "
                               "folder RUN."),
    platform: str = typer.Option(None, "--platform", parser=name_value,
                                 help="TOML platform file of the run "
                                 "(default: the embedded 2011 prototype).", metavar="FILE"),
    html: Path = _html_opt(), serve: bool = _serve_opt(), host: str = _host_opt(),
    allow_remote: bool = _allow_remote_opt(), port: int = _port_opt(),
    no_open: bool = _no_open_opt(),
) -> None:
    """Replay a control run: robot, platform, tool, workpiece, measured and true forces, the
    state a–e per cycle, with a timeline slider."""
    from kinestat.viz.cell_scene import cell_scene, read_cycle_log  # lazy: only for this view

    out = _out_options(html, serve, host, port, no_open, allow_remote)
    p = None
    if platform is not None:
        from kinestat.io.platform_toml import read_platform  # lazy: only with --platform

        p = read_platform(platform)
    start, cycles, end = read_cycle_log(log)
    _emit(cell_scene(start, cycles, end, platform=p, title=f"control run {log}"), out)
