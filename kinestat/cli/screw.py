"""``kinestat screw``: the screw axis of the displacement between two body positions."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer

from kinestat.cli._options import (
    POINTS3_METAVAR,
    POSE_FILE_METAVAR,
    check_output_file,
    command_help,
    flag,
    json_option,
    path_value,
    units,
)
from kinestat.cli._output import console, parse_floats, parse_pose, print_json, table
from kinestat.errors import InputError
from kinestat.spatial.displacement import (
    ScrewDisplacement,
    frame_from_triple,
    screw_from_points,
    screw_from_poses,
)


def _pose(value: str, name: str) -> np.ndarray:
    return parse_pose(value, name)


def _points(value: str, name: str) -> np.ndarray:
    pts = parse_floats(value, 9, name).reshape(3, 3)
    try:
        frame_from_triple(pts)
    except InputError as exc:  # coincident or collinear points: say which option
        raise InputError(f"--{name}: {exc}") from exc
    return pts


def screw_json(sc: ScrewDisplacement) -> dict:
    """The JSON record of one screw displacement."""
    return {
        "axis": sc.axis,
        "point": sc.point,
        "translation": sc.d,
        "angle_deg": sc.angle_deg,
        "pitch": sc.pitch,
        "pure_translation": sc.is_translation,
    }


def screw(
    pose1: str = typer.Option(None, "--pose1", help="First pose: a file (4x4 or 3x4 numbers, or "
                              "JSON such as kinestat fk --json writes) or 16 comma-separated "
                              "numbers, row by row.", metavar=POSE_FILE_METAVAR),
    pose2: str = typer.Option(None, "--pose2", help="Second pose, as --pose1.",
                              metavar=POSE_FILE_METAVAR),
    points1: str = typer.Option(None, "--points1", help="First position by three body points "
                                "x,y,z,x,y,z,x,y,z: origin, a point on +z, a point in the z-x "
                                "half plane with x > 0 (Nadkarni eqs. 3-1 to 3-3).",
                                metavar=POINTS3_METAVAR),
    points2: str = typer.Option(None, "--points2", help="Second position, as --points1.",
                                metavar=POINTS3_METAVAR),
    view: bool = flag(False, "--view", help="Also open a 3D view in the browser."),
    html: Path = typer.Option(None, "--html", parser=path_value,
                              metavar="FILE", help="With --view: write the "
                              "3D page to FILE (self-contained) instead of opening a browser."),
    as_json: bool = json_option(),
) -> None:
    """Screw axis of the displacement between two positions of a body (Nadkarni ch. III).

    Axis direction u (with u3 >= 0), the foot of the perpendicular from the origin to the axis,
    the rotation angle in (-180, 180] degrees, the translation along u and the pitch (inf for a
    pure translation).
    """
    by_pose = pose1 is not None or pose2 is not None
    by_points = points1 is not None or points2 is not None
    check_output_file(html, "--html")
    if by_pose == by_points:
        raise InputError("give either --pose1 and --pose2, or --points1 and --points2")
    if by_pose:
        if pose1 is None or pose2 is None:
            raise InputError("both --pose1 and --pose2 are needed")
        sc = screw_from_poses(_pose(pose1, "pose1"), _pose(pose2, "pose2"))
    else:
        if points1 is None or points2 is None:
            raise InputError("both --points1 and --points2 are needed")
        sc = screw_from_points(_points(points1, "points1"), _points(points2, "points2"))
    if view or html is not None:
        from kinestat.viz.show import show_screw  # lazy: viewer only with --view

        if by_pose:
            show_screw(_pose(pose1, "pose1"), _pose(pose2, "pose2"), html=html)
        else:
            P1, P2 = _points(points1, "points1"), _points(points2, "points2")
            show_screw(frame_from_triple(P1), frame_from_triple(P2), P1, P2, html=html)
    if as_json:
        print_json({**screw_json(sc), "units": units("the input's length unit")})
        return
    u, p = sc.axis, sc.point
    rows = [
        ["axis u", f"{u[0]:.6f}, {u[1]:.6f}, {u[2]:.6f}"],
        ["point on axis (foot from origin)", f"{p[0]:.6g}, {p[1]:.6g}, {p[2]:.6g}"],
        ["rotation (deg)", f"{float(sc.angle_deg):.6f}"],
        ["translation along u", f"{float(sc.d):.6g}"],
        ["pitch", "inf" if bool(sc.is_translation) else f"{float(sc.pitch):.6g}"],
        ["pure translation", "yes" if bool(sc.is_translation) else "no"],
    ]
    console.print(table("Screw displacement", ["quantity", "value"], rows))


def register(app: typer.Typer) -> None:
    """Add the ``screw`` command to the ``kinestat`` app."""
    app.command("screw", help=command_help(screw))(screw)
