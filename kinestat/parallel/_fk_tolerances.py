"""Tolerances of the special 6-6 all-mode forward kinematics, shared by the NumPy path
(:mod:`kinestat.parallel.fk33`) and the compiled kernels (:mod:`kinestat.parallel._fk_kernels`)
— defined once so the two cannot drift (Numba freezes them at compile time)."""

from __future__ import annotations

__all__ = ["COMBO_TOL", "IMAG_TOL", "SIG_TOL"]

#: a partner-angle combination is kept when its residual is at most this (or it is the best)
COMBO_TOL = 1e-3
#: a polynomial root counts as real (and non-negative in w) to this, relative to 1 + |z|
IMAG_TOL = 1e-3
#: two modes are the same when their pose signatures are closer than this
SIG_TOL = 1e-6
