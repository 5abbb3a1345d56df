"""Leg laws derived from calibrations, and the TOML calibration files."""

from __future__ import annotations

import numpy as np
import pytest

from kinestat.errors import ParseError
from kinestat.hardware.leg_calibration import (
    THESIS_CALIBRATION,
    counts_to_forces,
    counts_to_lengths,
)
from kinestat.hardware.leg_law import (
    calibrated_platform,
    nominal_calibration,
    rescale_counts,
    tension_slopes,
    tensions_at_lengths,
    zero_force_counts,
    zero_force_lengths,
)
from kinestat.io.calibration_toml import loads_calibration
from kinestat.io.library import list_calibrations, load_calibration
from kinestat.parallel.legs import leg_lengths
from kinestat.parallel.platform import special_6_6
from kinestat.parallel.statics import spring_wrench, wrench_from_forces

PLATFORM = special_6_6()


def test_embedded_thesis_file_is_the_module_constant():
    assert "thesis-2011" in list_calibrations()
    c = load_calibration("thesis").calibration
    assert c.leg_names == THESIS_CALIBRATION.leg_names
    np.testing.assert_array_equal(c.length_coeffs, THESIS_CALIBRATION.length_coeffs)
    np.testing.assert_array_equal(c.force_coeffs, THESIS_CALIBRATION.force_coeffs)


def test_zero_force_counts_and_lengths():
    e0 = zero_force_counts(THESIS_CALIBRATION)
    np.testing.assert_allclose(counts_to_forces(e0, THESIS_CALIBRATION, None), 0, atol=1e-12)
    L0 = zero_force_lengths(THESIS_CALIBRATION, PLATFORM.leg_names)
    np.testing.assert_allclose(L0, counts_to_lengths(e0, THESIS_CALIBRATION, PLATFORM.leg_names))
    # within 1.5 mm of the design free lengths (the thesis's main.cpp example lengths)
    assert np.max(np.abs(L0 - PLATFORM.free_lengths)) < 1.5


def test_calibrated_platform_is_unloaded_at_home_and_has_the_maps_slopes():
    cp = calibrated_platform(PLATFORM, THESIS_CALIBRATION)
    np.testing.assert_allclose(leg_lengths(cp, cp.home_pose), cp.free_lengths, atol=1e-9)
    np.testing.assert_allclose(spring_wrench(cp, cp.home_pose), 0, atol=1e-9)
    L = cp.free_lengths + np.linspace(-2, 2, 6)
    h = 1e-4
    fd = (tensions_at_lengths(THESIS_CALIBRATION, L + h, cp.leg_names)
          - tensions_at_lengths(THESIS_CALIBRATION, L - h, cp.leg_names)) / (2 * h)
    np.testing.assert_allclose(tension_slopes(THESIS_CALIBRATION, L, cp.leg_names), fd,
                               rtol=1e-6)
    np.testing.assert_allclose(cp.stiffness, fd, rtol=1e-6)  # linear maps: constant slope
    # the linear calibrated springs reproduce the maps' forces exactly
    np.testing.assert_allclose(cp.stiffness * (L - cp.free_lengths),
                               tensions_at_lengths(THESIS_CALIBRATION, L, cp.leg_names),
                               atol=1e-9)


def test_nominal_model_reads_a_bias_on_the_unloaded_calibrated_platform():
    nominal = nominal_calibration(PLATFORM, THESIS_CALIBRATION)
    e0 = zero_force_counts(THESIS_CALIBRATION)
    L = counts_to_lengths(e0, THESIS_CALIBRATION, PLATFORM.leg_names)
    f = counts_to_forces(e0, nominal, PLATFORM.leg_names)
    np.testing.assert_allclose(f, PLATFORM.stiffness * (L - PLATFORM.free_lengths), atol=1e-9)
    cp = calibrated_platform(PLATFORM, THESIS_CALIBRATION)
    w = wrench_from_forces(PLATFORM, cp.home_pose, f)
    assert np.linalg.norm(w[:3]) > 2.0  # ~5 N of phantom force (docs/control.md)


def test_rescaled_counts_give_the_same_maps():
    s = np.array([1e-3, 2e-3, 1e-2, 0.5, 1.0, 3.0])
    fine = rescale_counts(THESIS_CALIBRATION, s)
    e = np.array([100.0, 400.0, 900.0, -50.0, 0.0, 1234.0])
    np.testing.assert_allclose(counts_to_lengths(e / s, fine, None),
                               counts_to_lengths(e, THESIS_CALIBRATION, None))
    np.testing.assert_allclose(counts_to_forces(e / s, fine, None),
                               counts_to_forces(e, THESIS_CALIBRATION, None))


def _legs_text(force_lines):
    out = ['length_unit = "mm"', 'force_unit = "N"']
    for (i, name), fl in zip(enumerate("OSPTQR"), force_lines, strict=True):
        a = THESIS_CALIBRATION.length_coeffs[i]
        out += ["[[legs]]", f"sensor = {i + 1}", f'leg = "{name}"',
                f"length = [{float(a[0])!r}, {float(a[1])!r}]", fl]
    return "\n".join(out)


def test_polynomial_law_fitted_from_data_in_a_file():
    rng = np.random.default_rng(3)
    true = [np.array([14.0 - i, -0.03, 2e-6 * (i + 1), -1e-9]) for i in range(6)]
    lines = []
    for c in true:
        x = np.sort(rng.uniform(0, 1000, 12))
        y = np.polynomial.polynomial.polyval(x, c)
        lines.append(f"force_counts = {x.tolist()}\nforces = {y.tolist()}\nforce_degree = 3")
    cal = loads_calibration(_legs_text(lines), "poly.toml").calibration
    e = rng.uniform(0, 1000, (5, 6))
    expect = np.stack([np.polynomial.polynomial.polyval(e[:, i], true[i]) for i in range(6)], 1)
    np.testing.assert_allclose(counts_to_forces(e, cal, None), expect, atol=1e-7)
    # the non-linear law still has a calibrated platform (springs linearised at zero force)
    cp = calibrated_platform(PLATFORM, cal)
    np.testing.assert_allclose(tensions_at_lengths(cal, cp.free_lengths, cp.leg_names), 0,
                               atol=1e-9)


def test_compression_sense_is_negated():
    lines = [f"force = [{-float(f[0])!r}, {-float(f[1])!r}]"
             for f in THESIS_CALIBRATION.force_coeffs]
    text = _legs_text(lines).replace('force_unit = "N"', 'force_unit = "N"\nforce_sense = '
                                     '"compression"')
    cal = loads_calibration(text, "c.toml").calibration
    np.testing.assert_allclose(cal.force_coeffs, THESIS_CALIBRATION.force_coeffs)


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace('force_unit = "N"', 'force_unit = "kN"'), "force_unit"),
    (lambda t: t.replace("sensor = 2", "sensor = 5"), "sensor order"),
    (lambda t: t.replace("length = [", "lengthx = [", 1), "unknown keys"),
    (lambda t: t[: t.rindex("[[legs]]")], "six"),
])
def test_bad_files_are_refused(edit, message):
    lines = [f"force = [{float(f[0])!r}, {float(f[1])!r}]" for f in THESIS_CALIBRATION.force_coeffs]
    with pytest.raises(ParseError, match=message):
        loads_calibration(edit(_legs_text(lines)), "bad.toml")
