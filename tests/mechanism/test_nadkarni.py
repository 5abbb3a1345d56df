"""Nadkarni's Illustration 2 (Table A2-3 → published X*(i), X(i), U(i), ρn(i))."""

import numpy as np
import pytest

import kinestat
from kinestat.mechanism.nadkarni import mechanism_frames
from kinestat.serial.fk import joint_axes

D = np.deg2rad
ROWS = np.array([
    [0.00, D(90), 0.00, D(70)],
    [0.00, D(-90), 0.375, D(80)],
    [12.20, D(90), 0.375, D(40)],
    [0.00, D(-90), 0.00, D(0)],
    [9.50, D(90), 0.00, D(60)],
    [0.00, D(0), 5.90, D(30)],
    [0.00, D(0), 1.00, D(0)],
])
POINTS = [[0, 0, 0], [0, 0, 1], [1, 0, 0]]

# Published in Nadkarni 1977, Appendix II, Illustration 2 (to the printed precision).
# rho_n(3) is printed as 0.65; the value is 0.065 (see docs/seed-errata.md).
X_STAR = [[0, 0, 0], [0, 0, 0], [-11.95, 0, 2.488], [-11.90, 0.241, 2.771],
          [-21.255, 0.241, 4.42], [-21.255, 0.241, 4.42], [-24.315, 5.273, 4.059]]
X = [[0, 0, 0], [0.065, 0, 0.369], [-11.90, 0.241, 2.771], [-11.90, 0.241, 2.771],
     [-21.255, 0.241, 4.42], [-24.315, 5.273, 4.059], [-24.833, 6.126, 3.998]]
U = [[0, 0, 1], [0, -1, 0], [-0.985, 0, 0.174], [0.112, -0.766, 0.633], [-0.985, 0, 0.174],
     [0.171, 0.174, 0.970], [0.171, 0.174, 0.970]]
RHO = [[0, 0, 0], [0, 0, 0], [0.065, 0, 0.369], [-11.927, 0.426, 2.618], [0.115, 0.241, 0.652],
       [-21.374, 0.121, 3.747], [-24.433, 5.152, 3.386]]


def test_illustration2_reproduces_published_values():
    f = mechanism_frames(ROWS, POINTS)
    # printed to 2-3 decimals: half a unit of the last printed digit (+ rounding of inputs)
    np.testing.assert_allclose(f.origin_star, X_STAR, atol=6e-3)
    np.testing.assert_allclose(f.origin, X, atol=6e-3)
    np.testing.assert_allclose(f.axis, U, atol=6e-3)
    np.testing.assert_allclose(f.normal, RHO, atol=6e-3)


def test_chain_model_agrees_with_transm():
    m = kinestat.load("nadkarni-config1")
    f = mechanism_frames(ROWS, POINTS)
    u, rho = joint_axes(m, m.q_home)
    np.testing.assert_allclose(u, f.axis[:6], atol=1e-12)
    np.testing.assert_allclose(rho, f.normal[:6], atol=1e-12)
    T = kinestat.fk(m, m.q_home)
    np.testing.assert_allclose(T, f.x_star[6], atol=1e-12)  # the hand is x*(7)


def test_moving_joint1_rotates_about_the_fixed_axis(rng):
    """After a change of θ1, x*(1) turns about x*(0)'s z (Nadkarni eq. 2-13)."""
    m = kinestat.load("nadkarni-config2")
    q = m.q_home.copy()
    q[0] += 3.0  # prismatic r1
    q[3] += 0.4
    rows = np.asarray(m.extra_dict()["rows"])[:, :4].copy()
    rows[0, 0] += 3.0
    rows[3, 3] += 0.4
    f = mechanism_frames(rows, m.extra_dict()["frame_points"],
                         initial_rows=np.asarray(m.extra_dict()["rows"])[:, :4])
    np.testing.assert_allclose(kinestat.fk(m, q), f.x_star[6], atol=1e-12)


def test_collinear_frame_points_rejected():
    from kinestat.errors import InputError

    with pytest.raises(InputError, match="collinear"):
        mechanism_frames(ROWS, [[0, 0, 0], [0, 0, 1], [0, 0, 2]])
