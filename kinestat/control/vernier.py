"""Robot axis counts and the vernier: joint angles from counts and back, and the search among
the count vectors next to an ideal one for the tool point nearest a target (Vibhute 2011 §4;
see :mod:`kinestat.control.controller`'s docstring for why: one count is ~0.02 mm at the tool,
0.2 N of force on the platform; the search resolves the target to ~0.1 µm).

Every arm takes the same search: all candidates through the arm's forward analysis
(:func:`vernier_costs`) and the cheapest (:func:`vernier_search`).
"""

from __future__ import annotations

import functools
import itertools
from typing import TYPE_CHECKING

import numpy as np

from kinestat.control.model import ControlModel
from kinestat.control.tuning import TUNING, Tuning
from kinestat.robots.puma762.axes import round_half_away

if TYPE_CHECKING:
    from kinestat.control.controller import Target

__all__ = ["vernier_offsets", "axis5_residual", "axis_counts_to_q",
           "q_to_axis_counts", "vernier_costs", "vernier_search"]


def axis_counts_to_q(model: ControlModel, counts) -> np.ndarray:
    """Joint angles (radians) from robot axis counts (``axis = counts · resolution``)."""
    deg = np.asarray(counts, dtype=float) * model.axis_deg_per_count
    return model.arm.q_from_axis(np.radians(deg))


def q_to_axis_counts(model: ControlModel, axis_rad) -> np.ndarray:
    return round_half_away(np.degrees(axis_rad) / model.axis_deg_per_count)


def axis5_residual(model: ControlModel, counts: np.ndarray, counts_now: np.ndarray) -> np.ndarray:
    """Axis-5 counts left over by the 4 → 5 compensation (physical − commanded target)."""
    kappa = model.coupling * (counts[..., 3] - counts_now[3])
    return round_half_away(-kappa) + kappa


@functools.lru_cache(maxsize=8)
def vernier_offsets(reach: tuple[int, int]) -> np.ndarray:
    """The vernier's candidate offsets (n, 6) of axis counts: ± ``reach[0]`` on axes 1-3, ±
    ``reach[1]`` on the wrist axes 4-5, axis 6 as is (:class:`~kinestat.control.tuning.Tuning`,
    ``vernier_counts``); read-only.

    >>> vernier_offsets((4, 1)).shape
    (6561, 6)
    """
    a, w = range(-reach[0], reach[0] + 1), range(-reach[1], reach[1] + 1)
    out = np.array([(i, j, k, d, e, 0) for i, j, k in itertools.product(a, repeat=3)
                    for d, e in itertools.product(w, repeat=2)], dtype=np.int64)
    out.setflags(write=False)
    return out


def vernier_costs(model: ControlModel, target: Target, c0, counts_now,
                  vernier: bool = True, tuning: Tuning = TUNING
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The candidates ``c0 +`` :func:`vernier_offsets` (or ``c0`` alone), their cost and
    offset along S6 (mm), every candidate through the arm's forward analysis (NumPy)."""
    c0 = np.asarray(c0)
    cand = c0 + vernier_offsets(tuning.vernier_counts) if vernier else c0[None, :]
    phys = cand.astype(float)
    phys[:, 4] += axis5_residual(model, cand, np.asarray(counts_now))
    fwd = model.arm.forward(axis_counts_to_q(model, phys), model.tool_point_6)
    d = fwd.tool_point - target.tool_point
    along = d @ target.s6
    lateral = np.linalg.norm(d - along[:, None] * target.s6, axis=1)
    tilt = np.arccos(np.clip(fwd.s6 @ target.s6, -1.0, 1.0))
    s_along, s_lat, s_tilt = tuning.vernier_scales
    cost = (along / s_along) ** 2 + (lateral / s_lat) ** 2 + (tilt / s_tilt) ** 2
    return cand, cost, along


def vernier_search(model: ControlModel, target: Target, c0: np.ndarray, counts_now,
                   vernier: bool, tuning: Tuning = TUNING) -> tuple[np.ndarray, float]:
    """The vernier: (counts, offset along S6 in mm) of the cheapest candidate of
    :func:`vernier_costs` (``c0`` itself without the vernier)."""
    cand, cost, along = vernier_costs(model, target, c0, counts_now, vernier, tuning)
    k = int(np.argmin(cost))
    return cand[k], float(along[k])
