"""PUMA 762 mechanism parameters, axis conventions and status codes (Vibhute 2011, Tables 2-1
to 2-3; Appendix D.2) — the one definition, read by the NumPy code and the compiled kernels."""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "A23",
    "S2",
    "S4",
    "S6",
    "ALPHA_DEG",
    "AXIS_OFFSET",
    "AXIS_LIMITS_DEG",
    "AXIS_LIMITS_MATLAB_DEG",
    "AXIS_LIMITS_TABLE_2_1_DEG",
    "N_BRANCHES",
    "STATUS_OK",
    "STATUS_INSIDE_CYLINDER",
    "STATUS_TOO_FAR",
    "STATUS_TOO_NEAR",
]
# -- mechanism parameters (Vibhute Tables 2-2 and 2-3, mm) ------------------------------------
A23 = 650.0
"""Link length a23 (mm)."""
S2 = 190.0
"""Joint offset S2 (mm): the shoulder offset, radius of the cylinder the wrist cannot enter."""
S4 = 600.0
"""Joint offset S4 (mm): the forearm."""
S6 = 125.0
"""Joint offset S6 (mm) chosen to close the loop (Table 2-3): frame 6 origin beyond the wrist."""

ALPHA_DEG = (90.0, 0.0, 270.0, 90.0, 90.0)
"""Twist angles α12, α23, α34, α45, α56 (degrees, Table 2-2)."""

# Exact cosines and sines of the twist angles (avoid cos(270°) = -1.8e-16).
_CA = (0.0, 1.0, 0.0, 0.0, 0.0)
_SA = (1.0, 0.0, -1.0, 1.0, 1.0)
_A = (0.0, A23, 0.0, 0.0, 0.0)  # a12, a23, a34, a45, a56
_S = (S2, 0.0, S4, 0.0, S6)  # S2, S3, S4, S5, S6

AXIS_OFFSET = np.array([math.pi, 0.0, 0.0, 0.0, 0.0, 0.0])
"""Axis angle − joint angle (radians): axis 1 = φ1 + 180° (Appendix D.2, Pos_A_KCorrection)."""
AXIS_OFFSET.setflags(write=False)

AXIS_LIMITS_MATLAB_DEG = np.array(
    [[-160.0, 160.0], [-110.0, 110.0], [-135.0, 135.0], [-266.0, 266.0], [-100.0, 100.0],
     [-266.0, 266.0]]
)
"""Axis limits "as per manufacturer" in puma_rev_analysis.m (Appendix D.2), degrees."""
AXIS_LIMITS_MATLAB_DEG.setflags(write=False)

AXIS_LIMITS_TABLE_2_1_DEG = np.array(
    [[-160.0, 160.0], [-110.0, 110.0], [-135.0, 135.0], [-266.0, 266.0], [-110.0, 110.0],
     [-266.0, 266.0]]
)
"""Table 2-1's software movement ranges (320, 220, 270, 532, 220, 532°) split symmetrically."""
AXIS_LIMITS_TABLE_2_1_DEG.setflags(write=False)

AXIS_LIMITS_DEG = AXIS_LIMITS_MATLAB_DEG
"""Default axis limits: the MATLAB ones, which are the tighter set (joint 5 ±100° rather than
Table 2-1's ±110°) and the ones the thesis's controller actually enforced."""

N_BRANCHES = 8
"""Branches of the reverse analysis: two φ1 × two θ3 × two θ5."""

#: reachability of a pose (:attr:`ReverseBatch.status`): reachable, or which step has no root
STATUS_OK = 0
STATUS_INSIDE_CYLINDER = 1
STATUS_TOO_FAR = 2
STATUS_TOO_NEAR = 3

_TWO_PI = 2.0 * math.pi


def _wrap(x):
    """Angles wrapped to [-π, π)."""
    return (np.asarray(x) + math.pi) % _TWO_PI - math.pi
