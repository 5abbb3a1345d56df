"""The simulated contact's solvers (kinestat.sim.contact)."""

import numpy as np


def test_the_damped_slide_converges_where_plain_newton_diverges():
    # arctan's Newton iteration diverges from |x| > 1.39; the backtracking fallback of the
    # sliding contact must still reach the root (a property of the solver, no cell needed)
    from kinestat.sim._slide import damped_slide
    from kinestat.sim.contact import SLIDE_CONVERGED

    c = np.array([0.3, -0.2])

    def resid(d, X):
        return np.arctan(d - c), X

    d, x = 3.0 + c, 3.0 + c
    for _ in range(5):  # plain Newton: the step grows
        d = d - np.arctan(d - c) * (1.0 + (d - c) ** 2)
    assert np.max(np.abs(d - c)) > 10.0
    d2, X = damped_slide(resid, x.copy(), np.eye(4), SLIDE_CONVERGED)
    assert np.max(np.abs(np.arctan(d2 - c))) <= SLIDE_CONVERGED
    assert np.allclose(d2, c, atol=1e-9) and np.array_equal(X, np.eye(4))
