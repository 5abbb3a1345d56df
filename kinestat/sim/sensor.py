"""The simulated leg sensors: true leg lengths -> encoder counts (quantised, with noise).

The platform's legs carry linear encoders (Vibhute 2011 §3.2.2); :class:`Sensor` inverts their
calibration (:mod:`kinestat.hardware.leg_calibration`) to produce the counts a leg length
gives, with optional Gaussian noise and rounding to whole counts. :func:`ideal_calibration`
is an encoder without practical quantisation (1 nm per count).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinestat.errors import InputError
from kinestat.hardware.leg_calibration import THESIS_CALIBRATION, LegCalibration, lengths_to_counts
from kinestat.parallel.platform import Platform

__all__ = ["IDEAL_RESOLUTION", "ideal_calibration", "Sensor", "ideal_sensor"]


IDEAL_RESOLUTION = 1e-6
"""Length per count of the "ideal" sensor (mm): 1 nm, far below anything that matters here
(2.6e-6 N of spring force), yet still whole counts on the wire."""


def ideal_calibration(reference: LegCalibration = THESIS_CALIBRATION,
                      resolution: float = IDEAL_RESOLUTION) -> LegCalibration:
    """A linear length calibration with ``resolution`` mm per count and the same zero-count
    lengths (and sense) as ``reference``: an encoder without practical quantisation.

    The force maps are scaled to the same counts (force per count × resolution / slope).
    """
    if not (math.isfinite(resolution) and resolution > 0):
        raise InputError(f"sensor resolution must be a positive number of mm, got {resolution!r}")
    a = reference.length_coeffs
    if a.shape[1] != 2:
        raise InputError("ideal_calibration needs a linear reference calibration")
    sign = np.sign(a[:, 1])
    length = np.stack([a[:, 0], sign * resolution], axis=1)
    fc = reference.force_coeffs
    force = fc.copy()
    if fc.shape[1] == 2:
        force[:, 1] = fc[:, 1] * resolution / np.abs(a[:, 1])
    return LegCalibration(length_coeffs=length, force_coeffs=force,
                          leg_names=reference.leg_names,
                          index_counts=reference.index_counts * np.abs(a[:, 1]) / resolution)


@dataclass(frozen=True, eq=False)
class Sensor:
    """The platform's leg encoders: true leg lengths → counts (sensor legs 1..6).

    ``calibration`` maps counts to lengths (its inverse gives the counts a length produces);
    by default the thesis's maps (leg_to_T10.m: 0.0255–0.0271 mm per count). ``noise`` is
    the standard deviation of Gaussian noise added to each length before quantisation (mm).
    ``quantize=False`` returns fractional counts (the emitter rounds them on the wire; use
    :func:`ideal_calibration` for a sensor without practical quantisation).
    """

    calibration: LegCalibration = THESIS_CALIBRATION
    noise: float = 0.0
    quantize: bool = True

    def __post_init__(self) -> None:
        if not (math.isfinite(float(self.noise)) and self.noise >= 0):
            raise InputError(f"sensor noise must be a number of mm >= 0, got {self.noise!r}")

    def counts(self, platform: Platform, lengths, rng: np.random.Generator | None = None
               ) -> np.ndarray:
        """Counts (6,) in sensor order for leg ``lengths`` in the platform's leg order."""
        L = np.asarray(lengths, dtype=float)
        if self.noise > 0:
            gen = rng if rng is not None else np.random.default_rng()
            L = L + gen.normal(0.0, self.noise, size=L.shape)
        c = lengths_to_counts(L, self.calibration, platform.leg_names)
        return np.rint(c) if self.quantize else c


def ideal_sensor() -> Sensor:
    """A sensor with 1 nm counts and no noise (see :func:`ideal_calibration`)."""
    return Sensor(calibration=ideal_calibration())
