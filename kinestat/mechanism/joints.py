"""Joints of a serial chain: revolute, prismatic and screw (helical).

Every joint moves along/about the local z axis of the frame that precedes it
(DESIGN.md, "One internal chain model"):

- revolute:  ``Z(q) = Rz(q)``
- prismatic: ``Z(q) = Tz(q)``
- screw:     ``Z(q) = Rz(q) · Tz(h q)`` with pitch ``h`` in length per radian (Nadkarni eq. 2-14,
  ``δr = h δθ``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum
from typing import Literal

from kinestat.errors import ModelError

__all__ = ["Joint", "JointKind", "JointKindName", "JOINT_KINDS", "PRISMATIC_PITCH_THRESHOLD",
           "kind_from_pitch"]

#: the joint kinds as written in model files and on :attr:`Joint.kind`
JointKindName = Literal["revolute", "prismatic", "screw"]

JOINT_KINDS: tuple[JointKindName, ...] = ("revolute", "prismatic", "screw")


class JointKind(IntEnum):
    """Joint kind codes shared by the NumPy code and the compiled kernels (which compare plain
    ints: ``kind == PRISMATIC`` with ``PRISMATIC = int(JointKind.PRISMATIC)``).

    >>> JointKind.from_name("screw")
    <JointKind.SCREW: 2>
    >>> JointKind.PRISMATIC.label
    'prismatic'
    """

    REVOLUTE = 0
    PRISMATIC = 1
    SCREW = 2

    @classmethod
    def from_name(cls, name: str) -> JointKind:
        """The code of a kind name (``"revolute"``, ``"prismatic"``, ``"screw"``)."""
        return cls[name.upper()]

    @property
    def label(self) -> JointKindName:
        """The kind's name as in model files."""
        return JOINT_KINDS[self.value]

#: DISP's rule (Nadkarni App. I, SET FOUR): a joint whose pitch exceeds 1e5 is prismatic.
PRISMATIC_PITCH_THRESHOLD = 1e5


def kind_from_pitch(pitch: float) -> str:
    """Joint kind from a DISP pitch: > 1e5 prismatic, 0 revolute, otherwise screw.

    >>> kind_from_pitch(0.0), kind_from_pitch(0.2), kind_from_pitch(1e6)
    ('revolute', 'screw', 'prismatic')
    """
    if not math.isfinite(pitch):
        raise ModelError(f"joint pitch must be finite, got {pitch!r}")
    if pitch > PRISMATIC_PITCH_THRESHOLD:
        return "prismatic"
    if pitch == 0.0:
        return "revolute"
    return "screw"


@dataclass(frozen=True)
class Joint:
    """One single-degree-of-freedom joint.

    ``lower``/``upper`` are limits on the joint value q (radians for revolute and screw joints,
    length for prismatic ones); infinite when the joint is unlimited.

    >>> Joint('screw', pitch=0.5, name='lead').rotates, Joint('prismatic', pitch=3.0).pitch
    (True, 0.0)
    """

    kind: JointKindName = "revolute"
    pitch: float = 0.0
    lower: float = -math.inf
    upper: float = math.inf
    name: str = ""

    def __post_init__(self) -> None:
        if self.kind not in JOINT_KINDS:
            raise ModelError(
                f"unknown joint kind {self.kind!r} for joint {self.name or '?'}; "
                f"expected one of {', '.join(JOINT_KINDS)}"
            )
        if not math.isfinite(self.pitch):
            raise ModelError(f"joint {self.name or '?'}: pitch must be finite")
        if self.kind == "revolute" and self.pitch != 0.0:
            object.__setattr__(self, "kind", "screw")
        if self.kind != "screw" and self.kind != "revolute":
            object.__setattr__(self, "pitch", 0.0)
        if math.isnan(self.lower) or math.isnan(self.upper) or self.lower > self.upper:
            raise ModelError(
                f"joint {self.name or '?'}: limits [{self.lower}, {self.upper}] are not an interval"
            )

    @property
    def code(self) -> JointKind:
        """The kind as a :class:`JointKind` code."""
        return JointKind.from_name(self.kind)

    @property
    def rotates(self) -> bool:
        """True for revolute and screw joints (their value is an angle)."""
        return self.kind != "prismatic"
