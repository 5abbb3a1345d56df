"""Closed forms typed from the sources, independent of kinestat, shared by several test modules."""

import numpy as np


def dh_matrix(theta, d, a, alpha):
    """The lecture notes' H_i^{i-1}, written out element by element (independent of kinestat)."""
    ct, st_, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([
        [ct, -st_ * ca, st_ * sa, a * ct],
        [st_, ct * ca, -ct * sa, a * st_],
        [0, sa, ca, d],
        [0, 0, 0, 1.0],
    ])
