"""Mechanisms: joints, the immutable serial chain model, notations, DH from axes. Never reads files.

- :mod:`~kinestat.mechanism.joints` — revolute, prismatic and screw joints, DISP's pitch rule.
- :mod:`~kinestat.mechanism.chain` — the immutable :class:`ChainModel` and its builders from
  standard DH, modified DH and Nadkarni's notation.
- :mod:`~kinestat.mechanism.nadkarni` — Nadkarni's mechanism frames (TRANSM) and hand points.
- :mod:`~kinestat.mechanism.dh_from_axes` — a standard DH table from the joint axes.

Loading models from files or by name is :mod:`kinestat.io.library` (``kinestat.load``).
"""

from __future__ import annotations

import lazy_loader

# the public names load with their module on first use (PEP 562, lazy_loader)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=None,
    submod_attrs={
        'chain': ['ChainModel', 'from_modified_dh', 'from_nadkarni', 'from_standard_dh'],
        'dh_from_axes': ['DHFromAxes', 'dh_from_axes'],
        'joints': ['Joint'],
        'nadkarni': ['MechanismFrames', 'hand_points', 'mechanism_frames'],
    },
)
