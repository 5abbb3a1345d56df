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
from kinestat.hardware.puma762_axes import AXIS4_TO_5_COUPLING, THESIS_TOOL_POINT_6
from kinestat.io.library import list_calibrations, load_calibration
from kinestat.io.platform_toml import read_platform
from kinestat.parallel.platform import Platform, special_6_6
from kinestat.sim.contact import centred_mount
from kinestat.sim.sensor import IDEAL_RESOLUTION

__all__ = ["NamedCalibration", "resolve_platform", "resolve_calibration", "ideal_counts",
           "calibrated_model"]


@dataclass(frozen=True, eq=False)
class NamedCalibration:
    """A leg calibration with the name reports give it."""

    name: str
    calibration: LegCalibration


def resolve_platform(path: str | os.PathLike | None) -> Platform:
    """The platform file at ``path`` (:mod:`kinestat.io.platform_toml`), or the special 6-6
    prototype when None."""
    return special_6_6() if path is None else read_platform(path)


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
                     tool_point_6=THESIS_TOOL_POINT_6,
                     coupling: float = AXIS4_TO_5_COUPLING) -> ControlModel:
    """The controller's model: ``platform`` centred on the flange with the calibrated springs,
    the tool at ``tool_point_6`` when the calibrated legs are unloaded, forces from the
    calibration's maps."""
    return ControlModel(platform=calibrated_platform(platform, cal.calibration),
                        mount=centred_mount(platform), tool_point_6=tool_point_6,
                        calibration=cal.calibration, coupling=coupling,
                        force_source="calibration", calibration_name=cal.name)
