"""The mobility of a mechanism by the Grübler–Kutzbach criterion, and of the compliant platform.

Vibhute 2011 eq. 1-1 (after Tsai): ``M = λ (n − j − 1) + Σ f_i``, with λ the freedoms of the
space (6 spatial, 3 planar), n the links including the fixed one, j the joints (binary: a joint
where k links meet counts k − 1 times) and f_i the freedoms joint i permits. The count holds
where the joints' constraints are independent; overconstrained linkages (Bennett's 4R) move
more than it says.

The platform's legs are two links each (cylinder and piston, a prismatic pair between them),
jointed to the base and the top: n = 2 + 12 = 14 and j = 18 whatever the layout. A 3-3
platform's concentric joint joins two legs and a platform, so it counts twice, as two of a
6-6's joints: the count does not tell the layouts apart, the leg chain does.

* ``SPS`` (balls at both ends, the 3-3 of the seed's Figure 1-5): M = 12, six of them each
  leg's idle spin about its own line;
* ``UPS`` (a universal joint at one end, the seed's special 6-6 "to eliminate the six
  additional rotational freedoms"): M = 6, the top's six freedoms.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

__all__ = ["JOINT_FREEDOMS", "LEG_CHAINS", "gruebler_kutzbach", "platform_structure",
           "platform_mobility"]

JOINT_FREEDOMS = {"R": 1, "P": 1, "H": 1, "C": 2, "U": 2, "S": 3, "E": 3}
"""Freedoms of the lower pairs and the universal joint: revolute, prismatic, helical,
cylindrical, universal (Hooke), spherical, planar (E)."""

LEG_CHAINS = ("UPS", "SPS")
"""The platform's leg chains, base end first: the thesis's build (``UPS``) first."""


def gruebler_kutzbach(links: int, joints: Iterable[str | int], space: int = 6) -> int:
    """``M = λ (n − j − 1) + Σ f_i`` for ``links`` links (the fixed one included) and binary
    ``joints`` given by type (:data:`JOINT_FREEDOMS`) or by their freedoms, in a space of
    ``space`` freedoms (6 spatial, 3 planar or spherical).

    >>> gruebler_kutzbach(4, "RRRR", space=3)          # planar four-bar
    1
    >>> gruebler_kutzbach(14, "S" * 6 + "P" * 6 + "U" * 6)   # the special 6-6, UPS legs
    6
    """
    f = [JOINT_FREEDOMS[j.upper()] if isinstance(j, str) else int(j) for j in joints]
    return int(space * (int(links) - len(f) - 1) + sum(f))


def _distinct(points: np.ndarray, tol: float) -> int:
    keep: list[np.ndarray] = []
    for p in points:
        if all(np.linalg.norm(p - q) > tol for q in keep):
            keep.append(p)
    return len(keep)


def platform_structure(platform) -> str:
    """``"3-3"`` (three concentric joint points on each plate), ``"special 6-6"`` (the
    Griffis–Duffy layout, :attr:`~kinestat.parallel.platform.Platform.layout`) or
    ``"general 6-6"``."""
    tol = 1e-6 * platform.scale
    if _distinct(platform.base_points, tol) == 3 and _distinct(platform.top_points, tol) == 3:
        return "3-3"
    return "special 6-6" if platform.layout is not None else "general 6-6"


def platform_mobility(platform) -> dict:
    """The platform's Grübler–Kutzbach count for each leg chain of :data:`LEG_CHAINS`.

    Returns ``{"structure", "space", "links", "joints", "formula", "chains": {chain:
    {"joint_counts", "mobility", "idle", "top"}}, "mobility", "chain"}``: ``idle`` freedoms
    spin a leg about its own line (one per leg with balls at both ends) and move nothing else,
    ``top = mobility − idle``; ``mobility``/``chain`` are the thesis's build (UPS).
    """
    legs = len(platform.leg_names)
    links = 2 + 2 * legs
    chains = {}
    for chain in LEG_CHAINS:
        joints = chain * legs
        m = gruebler_kutzbach(links, joints)
        idle = legs if chain == "SPS" else 0
        chains[chain] = {"joint_counts": {t: joints.count(t) for t in sorted(set(chain))},
                         "mobility": m, "idle": idle, "top": m - idle}
    return {"structure": platform_structure(platform), "space": 6, "links": links,
            "joints": 3 * legs, "formula": "M = λ(n − j − 1) + Σ f_i",
            "chains": chains, "chain": LEG_CHAINS[0],
            "mobility": chains[LEG_CHAINS[0]]["mobility"]}
