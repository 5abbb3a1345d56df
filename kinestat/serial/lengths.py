"""The characteristic length of a serial chain — one function, two documented readings.

Lengths and angles are weighed against each other by dividing lengths by a length of the
mechanism. kinestat uses one function for it, :func:`characteristic_length`:

- without ``q``: the model's size, a constant of the model — the sum of the lengths of its
  constant translations ``|p(Ci)|`` plus the finite ranges of its prismatic joints. The numerical
  IK (:func:`kinestat.ik`) scales its errors and default position tolerance by it.
- with a configuration ``q``: the RMS distance from the end-frame origin to the joint-frame
  origins at ``q`` — the lever arm of the joints at that configuration. Resolved-rate guidance
  (Nadkarni's method, :mod:`kinestat.serial.guidance`) makes twists and Jacobians dimensionless
  with it.

Either is 1 for a degenerate chain whose value would be 0.
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.mechanism.chain import ChainModel
from kinestat.serial.fk import fk_frames

__all__ = ["characteristic_length"]


def characteristic_length(model: ChainModel, q=None) -> float | np.ndarray:
    """A characteristic length of ``model`` (its length unit); see the module docstring.

    ``q=None``: the model's size, ``Σ|p(Ci)|`` + finite prismatic ranges. ``q (n,)``: the RMS
    distance from the end-frame origin to the joint-frame origins ``F_0 … F_{n-1}`` at ``q``
    (a float); ``q (..., n)``: that length of each configuration, an array ``(...)``.

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> arm = from_standard_dh([[0.0, 0.0, 3.0, 0.0], [0.0, 0.0, 4.0, 0.0]])
    >>> characteristic_length(arm)
    7.0
    >>> round(characteristic_length(arm, [0.0, 0.0]), 9)  # RMS of the distances 7 and 4
    5.700877125
    >>> characteristic_length(arm, [[0.0, 0.0], [0.0, np.pi]]).round(6)  # one per row
    array([5.700877, 2.915476])
    """
    if q is None:
        L = float(np.sum(np.linalg.norm(model.constants[:, :3, 3], axis=-1)))
        for j in model.joints:
            if j.kind == "prismatic" and math.isfinite(j.lower) and math.isfinite(j.upper):
                L += j.upper - j.lower
        return L if L > 0.0 else 1.0
    q = model.check_q(q)
    F = fk_frames(model, q)
    d = F[..., :-1, :3, 3] - F[..., -1:, :3, 3]
    L = np.sqrt(np.mean(np.sum(d * d, axis=-1), axis=-1))
    L = np.where(L > 1e-9, L, 1.0)
    return float(L) if q.ndim == 1 else L
