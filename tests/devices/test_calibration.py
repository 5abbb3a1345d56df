"""Leg sensors: counts -> length / force maps and the calibration fitter."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.errors import InputError
from kinestat.hardware.leg_calibration import (
    COUNTS_PER_INCH,
    MM_PER_COUNT,
    THESIS_CALIBRATION,
    LegCalibration,
    counts_to_forces,
    counts_to_lengths,
    fit_leg_calibration,
    fit_polynomial,
    lengths_to_counts,
)
from kinestat.io.library import prototype

THESIS_LEGS = np.array([79.6804, 81.8285, 81.2669, 68.6500, 67.2037, 68.2854])  # main.cpp


def test_encoder_resolution():
    assert COUNTS_PER_INCH == 1000  # 250 lines per inch, quadrature x4
    assert MM_PER_COUNT == pytest.approx(0.0254)
    # the thesis's calibrated slopes are within 7 % of the nominal resolution
    slopes = -THESIS_CALIBRATION.length_coeffs[:, 1]
    assert np.all(np.abs(slopes / MM_PER_COUNT - 1) < 0.07)


def test_thesis_maps_zero_force_near_free_lengths():
    """With the restored signs, each leg's zero-force length is near its design free length and
    near main.cpp's example (an unloaded platform)."""
    cal = THESIS_CALIBRATION
    e0 = -cal.force_coeffs[:, 0] / cal.force_coeffs[:, 1]  # count at zero force, sensor order
    assert np.all(e0 > 0)
    l_zero = counts_to_lengths(e0, cal, platform_legs=None)
    p = prototype()
    order = cal.platform_order(p.leg_names)
    np.testing.assert_allclose(l_zero[order], p.free_lengths, atol=1.5)
    np.testing.assert_allclose(l_zero[order], THESIS_LEGS, atol=0.8)


def test_longer_leg_means_fewer_counts_and_more_tension():
    e = np.full(6, 480.0)
    L1, L2 = counts_to_lengths(e), counts_to_lengths(e - 10)
    F1, F2 = counts_to_forces(e), counts_to_forces(e - 10)
    assert np.all(L2 > L1) and np.all(F2 > F1)


def test_leg_order_mapping():
    e = np.arange(6) * 100.0
    sensor = counts_to_lengths(e, platform_legs=None)
    plat = counts_to_lengths(e)
    # platform O, P, Q, R, S, T are sensors 1, 3, 5, 6, 2, 4
    np.testing.assert_allclose(plat, sensor[[0, 2, 4, 5, 1, 3]])


def test_lengths_to_counts_inverts():
    e = np.array([[470.0, 480, 400, 490, 485, 475], [100, 200, 300, 400, 500, 600]])
    np.testing.assert_allclose(lengths_to_counts(counts_to_lengths(e)), e, atol=1e-9)
    cal = LegCalibration(length_coeffs=np.tile([90.0, -0.0254, 1e-7], (6, 1)),
                         force_coeffs=np.tile([14.0, -0.03], (6, 1)))
    np.testing.assert_allclose(lengths_to_counts(counts_to_lengths(e, cal), cal), e, atol=1e-6)


def test_fit_recovers_a_known_map_and_reports_residuals():
    rng = np.random.default_rng(0)
    e = np.linspace(0, 1000, 40)
    true = np.array([91.9, -0.0257])
    noise = rng.normal(scale=0.005, size=e.size)
    y = true[0] + true[1] * e + noise
    fit = fit_polynomial(e, y, degree=1)
    np.testing.assert_allclose(fit.coefficients, true, rtol=1e-3, atol=5e-3)
    np.testing.assert_allclose(fit.residuals, y - fit(e), atol=1e-12)
    # least squares: the residuals are orthogonal to the basis (normal equations)
    assert abs(fit.residuals.sum()) < 1e-9 and abs(fit.residuals @ e) < 1e-6
    assert fit.rms == pytest.approx(np.sqrt(np.mean(fit.residuals**2)))
    assert fit.max_abs == pytest.approx(np.max(np.abs(fit.residuals)))
    exact = fit_polynomial(e, 3.0 - 0.01 * e + 2e-6 * e**2, degree=2)
    np.testing.assert_allclose(exact.coefficients, [3.0, -0.01, 2e-6], rtol=1e-8, atol=1e-12)
    assert exact.max_abs < 1e-10


def test_fit_leg_calibration_round_trip():
    rng = np.random.default_rng(1)
    e = np.linspace(200, 800, 25)
    L = [(e, c[0] + c[1] * e) for c in THESIS_CALIBRATION.length_coeffs]
    F = [(e, c[0] + c[1] * e + rng.normal(scale=1e-3, size=e.size))
         for c in THESIS_CALIBRATION.force_coeffs]
    cal, lf, ff = fit_leg_calibration(L, F)
    np.testing.assert_allclose(cal.length_coeffs, THESIS_CALIBRATION.length_coeffs, atol=1e-9)
    np.testing.assert_allclose(cal.force_coeffs, THESIS_CALIBRATION.force_coeffs, atol=1e-2)
    assert all(f.max_abs < 1e-9 for f in lf) and all(f.rms < 3e-3 for f in ff)


@pytest.mark.parametrize("args", [
    ([1, 2], [1, 2, 3], 1), ([1, 1, 1], [1, 2, 3], 1), ([1, 2, np.nan], [1, 2, 3], 1),
    ([1, 2, 3], [1, 2, 3], -1), ([1, 2, 3], [1, 2, 3], 1.5),
])
def test_fit_rejects_bad_data(args):
    with pytest.raises(InputError):
        fit_polynomial(*args)


def test_bad_counts():
    with pytest.raises(InputError):
        counts_to_lengths([1, 2, 3])
    with pytest.raises(InputError):
        counts_to_forces([np.nan] * 6)
    with pytest.raises(InputError):
        counts_to_lengths([0] * 6, platform_legs=("A", "B", "C", "D", "E", "F"))
