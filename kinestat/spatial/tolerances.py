"""Numerical tolerances shared by the NumPy code and its compiled (Numba) twins — defined once.

Kernels read these module constants at compile time (Numba freezes module globals), so a
reference function and its kernel can never disagree about a threshold.
"""

from __future__ import annotations

__all__ = ["ORTHO_TOL", "LAST_ROW_TOL", "UNIT_TOL"]

#: a pose's rotation part is accepted when ``max|R Rᵀ − I| <= ORTHO_TOL`` and
#: ``|det R − 1| <= ORTHO_TOL`` (input typed with ~7 digits passes)
ORTHO_TOL = 1e-6

#: the last row of a pose must equal ``[0, 0, 0, 1]`` to within this (exact by default)
LAST_ROW_TOL = 0.0

#: a direction is accepted as a unit vector when ``||u| − 1| <= UNIT_TOL``
UNIT_TOL = 1e-6
