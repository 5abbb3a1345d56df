"""Which platform and which leg laws a ``kinestat control`` run uses (composition helpers).

Three named leg laws, each a :class:`~kinestat.hardware.leg_calibration.LegCalibration`
(counts → length, counts → tension):

* ``thesis`` — the 2011 prototype's maps (embedded ``thesis-2011.toml``, Vibhute App. D.7 with
  the signs restored);
* ``nominal`` — the design springs ``k (l − l0)`` of the platform on the thesis's length maps
  (what the controller assumed before calibrations: ~5 N of phantom force on the unloaded
  calibrated legs);
* a TOML file (:mod:`kinestat.io.calibration_toml`), linear or polynomial.

The controller's model uses the calibration's force maps (``force_source="calibration"``) and
the platform with the calibrated springs for its predictions; the simulated cell's legs follow
the TRUE law (``--sim-legs``), and its sensor produces counts through the truth's length maps.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinestat.control.model import ControlModel
from kinestat.errors import InputError
from kinestat.hardware.leg_calibration import LegCalibration
from kinestat.hardware.leg_law import calibrated_platform, nominal_calibration, rescale_counts
from kinestat.io.library import list_calibrations, load_calibration
from kinestat.io.platform_toml import (
    PlatformMount,
    read_mount_file,
    read_platform,
    read_platform_mount,
)
from kinestat.parallel.platform import Platform, special_6_6
from kinestat.robots.puma762.axes import AXIS4_TO_5_COUPLING, THESIS_TOOL_POINT_6
from kinestat.sim.contact import centred_mount
from kinestat.sim.sensor import IDEAL_RESOLUTION
from kinestat.spatial.validate import as_pose

__all__ = ["NamedCalibration", "resolve_platform", "resolve_mount", "resolve_calibration",
           "ideal_counts", "calibrated_model", "MOUNT_ORTHO_TOL"]


@dataclass(frozen=True, eq=False)
class NamedCalibration:
    """A leg calibration with the name reports give it."""

    name: str
    calibration: LegCalibration


def resolve_platform(path: str | os.PathLike | None) -> Platform:
    """The platform file at ``path`` (:mod:`kinestat.io.platform_toml`), or the special 6-6
    prototype when None."""
    return special_6_6() if path is None else read_platform(path)


MOUNT_ORTHO_TOL = 1e-3
"""Largest ``max|R Rᵀ − I|`` of a given mount's rotation: a pose typed to four decimals
(e.g. 0.7071) passes and is made exactly orthonormal (its nearest rotation)."""

MountSpec = str | os.PathLike | np.ndarray | None
"""``--mount``: None (the ``--platform`` file's ``[mount]``, else centred), ``"centred"``, a TOML
file (a platform file's ``[mount]`` or a pose file) or a 4x4 ``6_BT``."""


def resolve_mount(spec: MountSpec, platform: Platform,
                  platform_path: str | os.PathLike | None = None) -> tuple[np.ndarray, str]:
    """``6_BT`` (the platform's base frame in frame 6, mm) of a run and where it came from.

    None takes the ``platform_path`` file's ``[mount]`` table, or the centred mount
    (:func:`~kinestat.sim.contact.centred_mount`, the base triangle's centroid on S6) when
    there is none; ``"centred"`` the centred mount; a path a TOML file's mount (a platform
    file's ``[mount]``, offset and turn applied to that file's platform, or a pose file); an
    array the 4x4 pose itself."""
    if spec is None:
        m = None if platform_path is None else read_platform_mount(platform_path)[1]
        if m is None:
            return centred_mount(platform), "centred"
        return _mount_pose(m, platform, f"[mount] of {os.fspath(platform_path)}"), \
            os.fspath(platform_path)
    if isinstance(spec, str) and spec in ("centred", "centered"):
        return centred_mount(platform), "centred"
    if isinstance(spec, (str, os.PathLike)):
        owner, m = read_mount_file(spec)
        return _mount_pose(m, platform if owner is None else owner,
                           f"--mount {os.fspath(spec)}"), os.fspath(spec)
    return _mount_pose(PlatformMount(pose=np.asarray(spec, dtype=float)), platform,
                       "--mount"), "pose"


def _mount_pose(m: PlatformMount, platform: Platform, what: str) -> np.ndarray:
    """The 4x4 of a mount: offset and turn about S6 from the centred mount, or the pose checked
    rigid to :data:`MOUNT_ORTHO_TOL` and made exactly so."""
    if m.pose is None:
        return centred_mount(platform, offset=m.offset, turn=np.radians(m.turn_deg))
    T = as_pose(m.pose, what, tol=MOUNT_ORTHO_TOL, single=True).copy()
    U, _, Vt = np.linalg.svd(T[:3, :3])
    T[:3, :3] = U @ Vt
    T[3] = (0.0, 0.0, 0.0, 1.0)
    return T


CALIBRATION_NAMES = ("thesis", "nominal")
"""The names ``--calibration`` and ``--sim-legs`` accept besides the embedded calibrations
(:func:`kinestat.io.library.list_calibrations`) and TOML file paths."""


def resolve_calibration(spec: str | os.PathLike, platform: Platform, *,
                        option: str = "--calibration") -> NamedCalibration:
    """``"thesis"``, ``"nominal"`` (the platform's design springs on the thesis's length maps)
    or a calibration file / embedded name; an unknown name is refused naming ``option`` and
    every accepted name."""
    s = os.fspath(spec)
    known = (*CALIBRATION_NAMES, *list_calibrations())
    if s not in known and Path(s).suffix != ".toml" and not Path(s).exists():
        raise InputError(f"{option}: unknown calibration {s!r}: expected one of "
                         f"{', '.join(known)} or a TOML calibration file path")
    thesis = load_calibration("thesis")
    if s == "nominal":
        return NamedCalibration("nominal", nominal_calibration(platform, thesis.calibration))
    f = thesis if s == "thesis" else load_calibration(s)
    return NamedCalibration(f.name, f.calibration)


def ideal_counts(truth: LegCalibration, *others: LegCalibration,
                 resolution: float = IDEAL_RESOLUTION) -> tuple[LegCalibration, ...]:
    """``truth`` and ``others`` on counts of ``resolution`` mm of the truth's legs (an encoder
    without practical quantisation), the same factor for all so that the counts keep their
    meaning."""
    slope = np.abs(truth.length_coeffs[:, 1]) if truth.length_coeffs.shape[1] > 1 else None
    if slope is None or np.any(slope == 0):
        raise InputError("the ideal sensor needs length maps with a slope")
    factor = resolution / slope
    return tuple(rescale_counts(c, factor) for c in (truth, *others))


def calibrated_model(platform: Platform, cal: NamedCalibration, *,
                     tool_point_6=THESIS_TOOL_POINT_6, mount: np.ndarray | None = None,
                     coupling: float = AXIS4_TO_5_COUPLING) -> ControlModel:
    """The controller's model: ``platform`` on the flange at ``mount`` (``6_BT``; default
    centred) with the calibrated springs, the tool at ``tool_point_6`` when the calibrated legs
    are unloaded, forces from the calibration's maps."""
    return ControlModel(platform=calibrated_platform(platform, cal.calibration),
                        mount=centred_mount(platform) if mount is None else mount,
                        tool_point_6=tool_point_6,
                        calibration=cal.calibration, coupling=coupling,
                        force_source="calibration", calibration_name=cal.name)
