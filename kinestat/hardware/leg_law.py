"""Leg laws from calibrations: what a leg's calibration says about its spring.

A :class:`~kinestat.hardware.leg_calibration.LegCalibration` maps a leg's encoder count ``e`` to
its length ``l(e)`` and its tension ``F(e)`` (polynomials, sensor legs 1..6). Composed, they are
the leg's force law in length, ``F(l) = F(e(l))``, with ``e(l)`` the inverse of the length map.
This module derives from a calibration the quantities the controller and the simulator need:

* :func:`zero_force_counts` / :func:`zero_force_lengths`: where the leg carries no load — the
  calibrated free lengths (the thesis's maps: 79.60, 81.73, 81.18 mm for legs O, P, Q and 68.78,
  67.30, 68.28 mm for R, S, T, against the design's 80.969 / 68.000 mm);
* :func:`tensions_at_lengths` and :func:`tension_slopes`: ``F(l)`` and ``dF/dl`` (N/mm) at given
  lengths (the thesis's maps: 1.03–1.19 N/mm, against the design's 2.627 N/mm);
* :func:`calibrated_platform`: the platform whose linear springs are the law linearised at its
  zero-force lengths, with the home pose where the calibrated legs are unloaded (exact for
  linear maps; for polynomial maps measurement uses the polynomial, the platform's springs serve
  the stiffness predictions);
* :func:`nominal_calibration`: the design model as a calibration — the platform's springs
  ``k (l − l0)`` on a given length map;
* :func:`rescale_counts`: the same calibration on finer counts (the simulator's ideal sensor).

At the thesis maps' zero-force counts, the nominal model reads |F| = 4.995 N and a moment of
366 N·mm about the platform base's origin O0 on an unloaded platform (tests/hardware).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from kinestat.errors import InputError
from kinestat.hardware.leg_calibration import (
    LegCalibration,
    _polyval_rows,
    counts_to_forces,
    lengths_to_counts,
)
from kinestat.parallel.fk import fk_tracking
from kinestat.parallel.platform import Platform

__all__ = [
    "zero_force_counts",
    "zero_force_lengths",
    "tensions_at_lengths",
    "tension_slopes",
    "calibrated_platform",
    "nominal_calibration",
    "rescale_counts",
]


def _deriv(coeffs: np.ndarray) -> np.ndarray:
    """Row-wise derivative of ascending polynomial coefficients (a zero row for constants)."""
    if coeffs.shape[1] < 2:
        return np.zeros((coeffs.shape[0], 1))
    return coeffs[:, 1:] * np.arange(1, coeffs.shape[1])


def zero_force_counts(calibration: LegCalibration) -> np.ndarray:
    """Counts (6,), sensor order, at which each leg's force map is zero (Newton from the
    linear root; raises InputError when a leg's map has no usable root).

    >>> from kinestat.hardware.leg_calibration import THESIS_CALIBRATION
    >>> round(float(zero_force_counts(THESIS_CALIBRATION)[0]), 2)  # 14.25 / 0.029796
    478.25
    """
    f = calibration.force_coeffs
    if f.shape[1] < 2 or np.any(f[:, 1] == 0):
        raise InputError("the force calibration has no slope at zero counts: no zero-force "
                         "count can be found")
    e = -f[:, 0] / f[:, 1]
    df = _deriv(f)
    for _ in range(50):
        d = _polyval_rows(df, e)
        step = _polyval_rows(f, e) / np.where(d != 0, d, np.nan)
        e = e - step
        if np.all(np.abs(step) < 1e-12 * (1 + np.abs(e))):
            break
    if not np.all(np.isfinite(e)) or np.max(np.abs(_polyval_rows(f, e))) > 1e-9:
        raise InputError("a leg's force calibration has no zero-force count near its linear "
                         "root")
    return e


def zero_force_lengths(calibration: LegCalibration, platform_legs=("O", "P", "Q", "R", "S", "T")
                       ) -> np.ndarray:
    """Leg lengths (6,) where the calibrated legs carry no force, in ``platform_legs`` order
    (``None``: sensor order)."""
    e = zero_force_counts(calibration)
    L = _polyval_rows(calibration.length_coeffs, e)
    return L if platform_legs is None else L[calibration.platform_order(platform_legs)]


def tensions_at_lengths(calibration: LegCalibration, lengths,
                        platform_legs=("O", "P", "Q", "R", "S", "T")) -> np.ndarray:
    """The calibrated leg tensions ``F(e(l))`` (N) at leg ``lengths`` (mm), both in
    ``platform_legs`` order."""
    e = lengths_to_counts(lengths, calibration, platform_legs)
    return counts_to_forces(e, calibration, platform_legs)


def tension_slopes(calibration: LegCalibration, lengths,
                   platform_legs=("O", "P", "Q", "R", "S", "T")) -> np.ndarray:
    """``dF/dl`` (N/mm) of each calibrated leg at ``lengths`` (chain rule through the counts)."""
    e = lengths_to_counts(lengths, calibration, platform_legs)  # sensor order
    k = (_polyval_rows(_deriv(calibration.force_coeffs), e)
         / _polyval_rows(_deriv(calibration.length_coeffs), e))
    p = None if platform_legs is None else calibration.platform_order(platform_legs)
    return k if p is None else k[..., p]


def calibrated_platform(platform: Platform, calibration: LegCalibration) -> Platform:
    """``platform``'s geometry with the calibrated legs: free lengths at the zero-force counts,
    stiffness ``dF/dl`` there, home pose where those legs are unloaded (tracking FK from the
    design home). Raises InputError when the calibrated springs are not positive.
    """
    l0 = zero_force_lengths(calibration, platform.leg_names)
    k = tension_slopes(calibration, l0, platform.leg_names)
    if np.any(~np.isfinite(k)) or np.any(k <= 0):
        raise InputError(f"the calibration's leg springs must be positive at their zero-force "
                         f"lengths, got dF/dl = {np.round(k, 4).tolist()} N/mm")
    home = fk_tracking(platform, l0, platform.home_pose)
    return replace(platform, stiffness=k, free_lengths=l0, home_pose=home)


def nominal_calibration(platform: Platform, length_calibration: LegCalibration) -> LegCalibration:
    """The design springs as a calibration: ``length_calibration``'s length maps and the force
    maps ``k (l(e) − l0)`` of ``platform`` (its stiffness and free lengths)."""
    p = length_calibration.platform_order(platform.leg_names)
    k = np.empty(6)
    l0 = np.empty(6)
    k[p] = platform.stiffness
    l0[p] = platform.free_lengths
    a = length_calibration.length_coeffs
    force = k[:, None] * a
    force[:, 0] -= k * l0
    return LegCalibration(length_coeffs=a, force_coeffs=force,
                          leg_names=length_calibration.leg_names,
                          index_counts=length_calibration.index_counts)


def rescale_counts(calibration: LegCalibration, factor) -> LegCalibration:
    """The same maps on finer (or coarser) counts ``e' = e / factor``: coefficients of degree
    ``k`` scale by ``factor**k`` (``factor``: one positive number or six, sensor order); the
    index marks stay where they are (``index_counts / factor``)."""
    s = np.broadcast_to(np.asarray(factor, dtype=float), (6,))
    if not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise InputError(f"count scale factors must be positive, got {np.asarray(factor)}")

    def scaled(c: np.ndarray) -> np.ndarray:
        return c * s[:, None] ** np.arange(c.shape[1])

    return LegCalibration(length_coeffs=scaled(calibration.length_coeffs),
                          force_coeffs=scaled(calibration.force_coeffs),
                          leg_names=calibration.leg_names,
                          index_counts=calibration.index_counts / s)
