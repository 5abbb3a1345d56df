"""Checks of :func:`kinestat.serial.ik.ik` shared by test_ik.py and test_ik_kernels.py."""

import numpy as np

import kinestat
from kinestat.mechanism.chain import from_standard_dh
from kinestat.serial.ik import ik


def check_limits_respected_or_ignored():
    """Planar 2R arm, elbow limited to [0.1, 0.5]: a target made with elbow 1.0 has both its
    solutions (elbow ±1.0) outside the limits; ignoring the limits reaches it. Returns the
    result without limits."""
    m = from_standard_dh([[0, 0, 1.0, 0], [0, 0, 1.0, 0]], limits=[(-3, 3), (0.1, 0.5)],
                         name="2R", length_unit="m")
    target = kinestat.fk(m, [0.3, 1.0])
    r = ik(m, target, q0=[0.0, 0.3], restarts=3)
    assert not r.success and np.all(m.within_limits(r.q))
    r2 = ik(m, target, q0=[0.0, 0.3], respect_limits=False)
    assert r2.success and np.allclose(np.abs(r2.q[1]), 1.0, atol=1e-8)
    return r2
