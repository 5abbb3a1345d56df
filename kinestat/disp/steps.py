"""DISP's step count when IT = 0 (Nadkarni 1977, App. I: "if IT = 0, DISP decides the value of
IT on its own"): an **inferred** rule, not stated in the thesis (docs/disp-decks.md, "IT = 0").

Every analysis type steps the hand by eq. 4-11a's two parameters, a rotation δθ and a
translation δr: type II and IV screws rotate θ/k and advance d/k along their axis (eqs. 4-19,
4-21), type III splits the same screw displacement into k (SPLITM), type I (Example 4) rotates
θ/k about u_ω while its origin advances D/k along u_v (eqs. 4-16, 4-17). The rule keeps both per
step near a bound and rounds to the nearest count::

    k = max(1, round(max(θ / DISP_STEP_DEG, T / (DISP_STEP_HAND × hand size))))

with θ the stage's rotation (degrees), T its translation parameter (|d| of the screw for types
II, III and IV, the origin's straight line D for type I) and the hand size DISP's unit: its
hand points are one length unit apart. The two constants are fitted to the published counts of
Illustrations 5, 6 and 7 (27; 9 and 4; 35); see the docs for the evidence and the fit's
freedom. Illustration 4's "Total 22" counts every solve (:func:`total_steps`), not path
steps; no rule of this kind gives its path steps (at most 21) with the other counts
(``scripts/disp_it_rule_search.py``, ``scripts/disp_ill4_total_checks.py``). ``kinestat
disp`` also splits a counted step whose joint increments exceed :data:`DISP_STEP_DEG` into
sub-steps (``GuidanceOptions.counted_substep_deg``).
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.serial.guidance.planners import GeneralPath, Path
from kinestat.serial.guidance.run import GuidanceResult
from kinestat.spatial.displacement import screw_from_poses

__all__ = ["DISP_STEP_DEG", "DISP_STEP_HAND", "stage_motion", "disp_step_count", "total_steps"]

#: Rotation per step (degrees) the inferred rule aims at; published counts allow
#: (3.333, 3.396].
DISP_STEP_DEG = 3.36

#: Translation per step, in hand sizes (DISP's hand points are one length unit apart); the
#: published counts allow (0.4992, 0.5136].
DISP_STEP_HAND = 0.505


def stage_motion(path: Path) -> tuple[float, float]:
    """``(θ in degrees, T)`` of a stage as DISP knew them at its start: the rotation of the whole
    displacement and its translation parameter (|d| along the screw axis; for a type I path
    the length D of the origin's straight line)."""
    start = np.asarray(path.pose_at(0.0), dtype=float)
    sc = screw_from_poses(start, np.asarray(path.end, dtype=float))
    theta = 0.0 if bool(sc.is_translation) else abs(math.degrees(float(sc.theta)))
    if isinstance(path, GeneralPath):
        return theta, abs(float(path.r))
    return theta, abs(float(sc.d))


def disp_step_count(path: Path, hand_size: float = 1.0) -> int:
    """The inferred IT = 0 count of one stage (module docstring).

    >>> from kinestat.serial.guidance.planners import command_path
    >>> from kinestat.spatial.transforms import trans
    >>> H = trans([15.0, -25.0, 12.0])
    >>> disp_step_count(command_path(H, [0, 0, 1], 4.0, math.radians(-30.0)))
    9
    """
    theta, T = stage_motion(path)
    x = max(theta / DISP_STEP_DEG, T / (DISP_STEP_HAND * hand_size))
    return max(1, math.floor(x + 0.5))


def total_steps(result: GuidanceResult) -> int:
    """Every solve of eq. 4-11 in a run: the rows after the initial one (path steps and
    correction rows) plus the extra sub-steps. That is what Nadkarni's captions count: Table
    A2-9's "Total 38 steps" are 27 path steps, 10 extra sub-steps and 1 correction
    (docs/seed-errata.md G1). A perturbation at a singularity is not a solve."""
    return int(np.asarray(result.q).shape[0]) - 1 + int(result.substeps)
