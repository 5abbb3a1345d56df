"""Constants of the Levenberg–Marquardt IK, shared by the NumPy reference
(:mod:`kinestat.serial._reference`) and the compiled kernels (:mod:`kinestat.serial._ik_kernels`)
— defined once so the two cannot drift (Numba freezes them at compile time)."""

from __future__ import annotations

from kinestat.spatial.tolerances import ORTHO_TOL

#: target poses: rotation part orthonormal with det +1 to this
TARGET_ORTHO_TOL = ORTHO_TOL
#: target poses: last row [0, 0, 0, 1] to this
TARGET_LAST_ROW_TOL = 1e-12
#: iterations between progress checks (a start stalls if the cost did not fall below
#: ``STALL_RATIO`` × the cost at the previous check)
CHECK_EVERY = 10
STALL_RATIO = 0.9
#: damping: start, floor, and the value beyond which a start counts as stalled
MU_START = 1e-3
MU_MIN = 1e-12
MU_STALL = 1e10
#: damping factors after an accepted / a rejected step
MU_DOWN = 3.0
MU_UP = 8.0
#: convergence: within ``WITHIN`` × the tolerances, polished until ``POLISHED`` × them
WITHIN = 0.5
POLISHED = 1e-3
