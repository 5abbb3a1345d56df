"""The twist Jacobian against finite differences of forward kinematics."""

import numpy as np
import pytest

import kinestat
from kinestat.mechanism.chain import from_standard_dh


def numerical_twist_jacobian(model, q, eps=1e-6):
    """Central differences: twist [w; v_O] from dT T^-1 (independent of kinestat's Jacobian)."""
    n = len(q)
    J = np.zeros((6, n))
    T = kinestat.fk(model, q)
    Tinv = np.linalg.inv(T)
    for j in range(n):
        dq = np.zeros(n)
        dq[j] = eps
        dT = (kinestat.fk(model, q + dq) - kinestat.fk(model, q - dq)) / (2 * eps)
        X = dT @ Tinv  # [[w]x, v_O; 0 0]
        J[:3, j] = [X[2, 1], X[0, 2], X[1, 0]]
        J[3:, j] = X[:3, 3]
    return J


@pytest.mark.parametrize("name", ["puma762", "puma560", "nadkarni-config1", "nadkarni-config2"])
def test_jacobian_matches_finite_differences(name, rng):
    m = kinestat.load(name)
    for _ in range(10):
        q = m.q_home + rng.uniform(-1, 1, m.n)
        scale = max(1.0, np.abs(kinestat.fk(m, q)[:3, 3]).max())
        np.testing.assert_allclose(kinestat.jacobian(m, q), numerical_twist_jacobian(m, q),
                                   atol=1e-6 * scale)


def test_screw_joint_column(rng):
    m = from_standard_dh([[0.3, 0.1, 0.7, 0.4], [0, 0, 1, 0], [0, 0.5, 0, 1.0]],
                         ["revolute", "screw", "prismatic"], pitches=[0, 0.25, 0])
    q = rng.uniform(-1, 1, 3)
    np.testing.assert_allclose(kinestat.jacobian(m, q), numerical_twist_jacobian(m, q), atol=1e-7)


def test_batched(rng):
    m = kinestat.load("puma762")
    q = rng.uniform(-1, 1, (5, 6))
    J = kinestat.jacobian(m, q)
    assert J.shape == (5, 6, 6)
    np.testing.assert_allclose(J[3], kinestat.jacobian(m, q[3]))
