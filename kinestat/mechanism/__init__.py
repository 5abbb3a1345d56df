"""Mechanisms: joints, the immutable serial chain model, notations, DH from axes. Never reads files.

- :mod:`~kinestat.mechanism.joints` — revolute, prismatic and screw joints, DISP's pitch rule.
- :mod:`~kinestat.mechanism.chain` — the immutable :class:`ChainModel` and its builders from
  standard DH, modified DH and Nadkarni's notation.
- :mod:`~kinestat.mechanism.nadkarni` — Nadkarni's mechanism frames (TRANSM) and hand points.
- :mod:`~kinestat.mechanism.dh_from_axes` — a standard DH table from the joint axes.

Loading models from files or by name is :mod:`kinestat.io.library` (``kinestat.load``).
"""

from __future__ import annotations

from kinestat.mechanism.chain import ChainModel, from_modified_dh, from_nadkarni, from_standard_dh
from kinestat.mechanism.dh_from_axes import DHFromAxes, dh_from_axes
from kinestat.mechanism.joints import Joint
from kinestat.mechanism.nadkarni import MechanismFrames, hand_points, mechanism_frames

__all__ = [
    "ChainModel",
    "DHFromAxes",
    "Joint",
    "MechanismFrames",
    "dh_from_axes",
    "from_modified_dh",
    "from_nadkarni",
    "from_standard_dh",
    "hand_points",
    "mechanism_frames",
]
