"""Platform leg sensors: encoder counts → leg length and leg force, and calibration fitting.

Each leg of the compliant platform carries a US Digital EM1 optical encoder reading a LIN
transmissive strip of 250 lines per inch (Vibhute 2011 §3.2.2, Figs. 3-7/3-8). Quadrature
decoding counts 4 edges per line: 1000 counts per inch, 0.0254 mm per count
(:data:`MM_PER_COUNT`). The thesis's calibrated slopes (``leg_to_T10.m``, 0.0255–0.0271 mm per
count) confirm that its code uses ×4 quadrature.

Calibration maps are polynomials in the count, per sensor leg (sensor legs are numbered 1..6 as
in the thesis's encoder stream; :data:`THESIS_SENSOR_LEGS` names the platform leg each one
measures, from ``leg_to_T10.m`` / ``eq_wrench.m``: sensor 1 = O, 2 = S, 3 = P, 4 = T, 5 = Q,
6 = R). Forces are **tensions** (positive when the leg is stretched), the convention of
:mod:`kinestat.parallel.statics`.

:data:`THESIS_CALIBRATION` holds ``leg_to_T10.m``'s linear maps with their signs restored (the
OCR of the seed dropped every minus sign):

* length ``l = b − a·e``: the count (read as a non-negative number, as the 16-bit stream
  delivers it) grows as the leg shortens. With ``+`` the zero-force lengths would be ~104 mm,
  far from the design free lengths (80.969 / 68.000 mm); with ``−`` they are 79.6, 81.7,
  81.2 mm (legs O, P, Q) and 67.3, 68.3, 68.8 mm (S, T, R) — and the example leg lengths of
  the thesis's main.cpp (79.68, 81.83, 81.27, 68.65, 67.20, 68.29) match these unloaded
  lengths.
* force ``F = c·e − d`` in the thesis is positive in **compression** (its ``W_eq`` must point
  along the tool's approach for ForceCorrection.m's "move along F6S to push harder" to work);
  our tension map is therefore ``d − c·e``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import polynomial as P

from kinestat.errors import InputError
from kinestat.spatial.validate import frozen

__all__ = [
    "ENCODER_LINES_PER_INCH",
    "QUADRATURE",
    "COUNTS_PER_INCH",
    "MM_PER_COUNT",
    "THESIS_SENSOR_LEGS",
    "LegCalibration",
    "THESIS_CALIBRATION",
    "CalibrationFit",
    "counts_to_lengths",
    "counts_to_forces",
    "lengths_to_counts",
    "fit_polynomial",
    "fit_leg_calibration",
]

#: US Digital LIN strip resolution (Vibhute 2011 §3.2.2).
ENCODER_LINES_PER_INCH = 250
#: Quadrature decoding: four counts per line.
QUADRATURE = 4
#: Counts per inch of leg travel.
COUNTS_PER_INCH = ENCODER_LINES_PER_INCH * QUADRATURE
#: Nominal leg travel per count, millimetres (25.4 / 1000 = 0.0254 mm).
MM_PER_COUNT = 25.4 / COUNTS_PER_INCH

#: Platform leg measured by sensor legs 1..6 (leg_to_T10.m and eq_wrench.m).
THESIS_SENSOR_LEGS: tuple[str, ...] = ("O", "S", "P", "T", "Q", "R")


@dataclass(frozen=True, eq=False)
class LegCalibration:
    """Per-sensor-leg polynomial maps from counts (ascending coefficients, one row per leg).

    Attributes:
        length_coeffs: (6, n) count → leg length, sensor legs 1..6.
        force_coeffs: (6, m) count → leg tension.
        leg_names: the platform leg measured by each sensor leg.
        index_counts: (6,) the count each sensor leg's encoder box sets when the leg passes
            its strip's index mark (Vibhute §3.2.2: the sensor "is supposed to zero its
            position" there); default zeros: the maps count from the index, as the thesis's
            do (its index lies at ``l = b``, the maps' constant term).
    """

    length_coeffs: np.ndarray
    force_coeffs: np.ndarray
    leg_names: tuple[str, ...] = THESIS_SENSOR_LEGS
    length_unit: str = "mm"
    force_unit: str = "N"
    index_counts: np.ndarray | None = None

    def __post_init__(self) -> None:
        for attr in ("length_coeffs", "force_coeffs"):
            a = np.array(getattr(self, attr), dtype=float)
            if a.ndim != 2 or a.shape[0] != 6 or a.shape[1] < 1:
                raise InputError(f"{attr} must have shape (6, n >= 1), got {a.shape}")
            if not np.all(np.isfinite(a)):
                raise InputError(f"{attr} contains NaN or infinity")
            object.__setattr__(self, attr, frozen(a, float))
        names = tuple(str(n) for n in self.leg_names)
        if len(names) != 6 or len(set(names)) != 6:
            raise InputError(f"leg_names must be six distinct names, got {names}")
        object.__setattr__(self, "leg_names", names)
        idx = np.zeros(6) if self.index_counts is None else np.array(self.index_counts, float)
        if idx.shape != (6,) or not np.all(np.isfinite(idx)):
            raise InputError(f"index_counts must be 6 finite counts, got {self.index_counts!r}")
        object.__setattr__(self, "index_counts", frozen(idx, float))

    def platform_order(self, platform_legs: Sequence[str]) -> np.ndarray:
        """Index array ``p``: ``values_platform = values_sensor[..., p]``."""
        try:
            return np.array([self.leg_names.index(n) for n in platform_legs])
        except ValueError:
            raise InputError(f"calibration legs {list(self.leg_names)} do not match the "
                             f"platform's legs {list(platform_legs)}") from None


#: ``leg_to_T10.m``'s maps (Vibhute 2011 App. D.7), signs restored; sensor legs 1..6.
THESIS_CALIBRATION = LegCalibration(
    length_coeffs=[[91.9216, -0.025771], [79.2948, -0.025455], [92.7287, -0.027115],
                   [80.5882, -0.025419], [93.5823, -0.025657], [81.2437, -0.026074]],
    force_coeffs=[[14.25, -0.029796], [13.407, -0.028449], [11.325, -0.027919],
                  [14.103, -0.029123], [13.12, -0.027136], [14.81, -0.030975]],
)


def _counts(counts) -> np.ndarray:
    c = np.asarray(counts, dtype=float)
    if c.shape[-1:] != (6,):
        raise InputError(f"counts must have trailing shape (6,), got {c.shape}")
    if not np.all(np.isfinite(c)):
        raise InputError("counts contain NaN or infinity")
    return c


def _polyval_rows(coeffs: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Evaluate row ``i`` of ``coeffs`` at ``x[..., i]`` (Horner)."""
    out = np.broadcast_to(coeffs[:, -1], x.shape).copy()
    for k in range(coeffs.shape[1] - 2, -1, -1):
        out = out * x + coeffs[:, k]
    return out


def counts_to_lengths(counts, calibration: LegCalibration = THESIS_CALIBRATION,
                      platform_legs: Sequence[str] | None = ("O", "P", "Q", "R", "S", "T")
                      ) -> np.ndarray:
    """Leg lengths (..., 6) from counts (..., 6) in sensor order 1..6.

    The result is in ``platform_legs`` order (default O, P, Q, R, S, T); ``None`` keeps the
    sensor order.
    """
    c = _counts(counts)
    out = _polyval_rows(calibration.length_coeffs, c)
    return out if platform_legs is None else out[..., calibration.platform_order(platform_legs)]


def counts_to_forces(counts, calibration: LegCalibration = THESIS_CALIBRATION,
                     platform_legs: Sequence[str] | None = ("O", "P", "Q", "R", "S", "T")
                     ) -> np.ndarray:
    """Leg tensions (..., 6) from counts (..., 6) in sensor order (result: ``platform_legs``)."""
    c = _counts(counts)
    out = _polyval_rows(calibration.force_coeffs, c)
    return out if platform_legs is None else out[..., calibration.platform_order(platform_legs)]


def lengths_to_counts(lengths, calibration: LegCalibration = THESIS_CALIBRATION,
                      platform_legs: Sequence[str] | None = ("O", "P", "Q", "R", "S", "T")
                      ) -> np.ndarray:
    """Counts (..., 6, sensor order, not rounded) that the sensors read at these leg lengths.

    Inverts the length maps (exact for linear maps, Newton for higher degree). ``lengths`` are
    in ``platform_legs`` order (``None``: sensor order). Used by the simulated sensor.
    """
    L = np.asarray(lengths, dtype=float)
    if L.shape[-1:] != (6,) or not np.all(np.isfinite(L)):
        raise InputError(f"lengths must be finite with trailing shape (6,), got {L.shape}")
    if platform_legs is not None:
        p = calibration.platform_order(platform_legs)
        Ls = np.empty_like(L)
        Ls[..., p] = L
        L = Ls
    a = calibration.length_coeffs
    if a.shape[1] < 2 or np.any(a[:, 1] == 0):
        raise InputError("the length calibration has no slope: counts cannot be recovered")
    e = (L - a[:, 0]) / a[:, 1]
    if a.shape[1] > 2:
        da = a[:, 1:] * np.arange(1, a.shape[1])
        for _ in range(30):
            r = _polyval_rows(a, e) - L
            d = _polyval_rows(da, e)
            e = e - r / np.where(d != 0, d, np.nan)
        if not np.all(np.isfinite(e)) or np.max(np.abs(_polyval_rows(a, e) - L)) > 1e-9 * (
                1 + np.max(np.abs(L))):
            raise InputError("cannot invert the polynomial length calibration at these lengths")
    return e


@dataclass(frozen=True)
class CalibrationFit:
    """A least-squares polynomial fit ``value ≈ Σ coefficients[k] counts^k``.

    ``residuals`` are measured − fitted, ``rms`` and ``max_abs`` summarise them.
    """

    coefficients: np.ndarray
    residuals: np.ndarray
    rms: float
    max_abs: float

    def __call__(self, counts) -> np.ndarray:
        return P.polyval(np.asarray(counts, dtype=float), self.coefficients)


def fit_polynomial(counts, values, degree: int = 1) -> CalibrationFit:
    """Least-squares fit of ``values`` (lengths or load-cell forces) against ``counts``.

    Fits in a scaled variable (well conditioned for raw counts in the thousands) and returns
    ascending coefficients in the raw count.
    """
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 0:
        raise InputError(f"degree must be a non-negative integer, got {degree!r}")
    x = np.asarray(counts, dtype=float).ravel()
    y = np.asarray(values, dtype=float).ravel()
    if x.shape != y.shape:
        raise InputError(f"counts and values differ in length ({x.size} vs {y.size})")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise InputError("calibration data contain NaN or infinity")
    if np.unique(x).size <= degree:
        raise InputError(f"a degree-{degree} fit needs at least {degree + 1} distinct counts, "
                         f"got {np.unique(x).size}")
    poly = np.polynomial.Polynomial.fit(x, y, degree)
    coef = poly.convert().coef
    coef = np.concatenate([coef, np.zeros(degree + 1 - coef.size)])
    res = y - P.polyval(x, coef)
    return CalibrationFit(coefficients=frozen(coef, float), residuals=frozen(res, float),
                          rms=float(np.sqrt(np.mean(res**2))), max_abs=float(np.max(np.abs(res))))


def fit_leg_calibration(length_data, force_data, *, length_degree: int = 1,
                        force_degree: int = 1,
                        leg_names: Sequence[str] = THESIS_SENSOR_LEGS
                        ) -> tuple[LegCalibration, list[CalibrationFit], list[CalibrationFit]]:
    """Fit a :class:`LegCalibration` from six legs' (counts, length) and (counts, tension) data.

    Args:
        length_data: six pairs ``(counts, lengths)`` (sensor legs 1..6), e.g. from a height
            gauge.
        force_data: six pairs ``(counts, tensions)`` from a load cell (tension positive;
            negate compression readings).

    Returns:
        ``(calibration, length_fits, force_fits)``: the fits carry residuals, rms and max.
    """
    if len(length_data) != 6 or len(force_data) != 6:
        raise InputError("need (counts, values) data for each of the six legs")
    lf = [fit_polynomial(c, v, length_degree) for c, v in length_data]
    ff = [fit_polynomial(c, v, force_degree) for c, v in force_data]
    cal = LegCalibration(length_coeffs=np.stack([f.coefficients for f in lf]),
                         force_coeffs=np.stack([f.coefficients for f in ff]),
                         leg_names=tuple(leg_names))
    return cal, lf, ff
