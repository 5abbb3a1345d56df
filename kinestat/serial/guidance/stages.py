"""Building the stages of a run (Nadkarni ch. IV): one stage per target, command or move, each a
function of the hand pose at its start (so a stage continues where the last one ended).

Used by the DISP program (:mod:`kinestat.disp`) and ``kinestat guide`` alike.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal, Protocol

import numpy as np

from kinestat.errors import InputError
from kinestat.serial.guidance.planners import (
    StageSpec,
    command_path,
    general_motion,
    general_path,
    line_path,
    screw_path,
)
from kinestat.spatial.displacement import frame_from_triple

__all__ = ["PathType", "PATH_TYPES", "Command", "target_stages", "command_stages",
           "move_stages"]

PathType = Literal["screw", "line", "general"]
PATH_TYPES: tuple[str, ...] = ("screw", "line", "general")


class Command(Protocol):
    """An operator command (type IV): ``direction`` R, ``distance`` d, ``angle`` θ (rad),
    ``frame`` 'global' or 'hand' — e.g. :class:`kinestat.io.disp_deck.OperatorCommand`."""

    @property
    def direction(self) -> Sequence[float]: ...

    @property
    def distance(self) -> float: ...

    @property
    def angle(self) -> float: ...

    @property
    def frame(self) -> str: ...


def target_stages(kind: PathType, start_points, targets, *,
                  from_actual: bool = False) -> list[StageSpec]:
    """One stage per target (three points ``(3, 3)`` each): ``"screw"`` type II (eq. 4-19;
    ``from_actual``: each step aims from the actual hand at the next path pose, as DISP),
    ``"line"`` type III from ``start_points`` (eq. 4-20), ``"general"`` type I Example 4
    (eqs. 4-16, 4-17, re-planned every step).

    >>> P = [[10.0, -10, 20], [11, -10, 20], [10, -10, 19]]
    >>> len(target_stages("screw", None, [P, P]))
    2
    """
    if kind not in PATH_TYPES:
        raise InputError(f"path type must be one of {', '.join(PATH_TYPES)}, got {kind!r}")
    pts = [np.asarray(t, dtype=float) for t in targets]
    if kind == "line":
        P = [np.asarray(start_points, dtype=float), *pts]
        return [(lambda H, a=P[i - 1], b=P[i]: line_path(a, b)) for i in range(1, len(P))]
    frames = [frame_from_triple(t) for t in pts]
    if kind == "screw":
        return [(lambda H, T=T: screw_path(H, T, from_actual=from_actual)) for T in frames]
    return [(lambda H, T=T: general_path(H, T)) for T in frames]


def command_stages(commands: Sequence[Command]) -> list[StageSpec]:
    """One type IV stage per operator command (eqs. 4-21, 4-22), from the hand where the
    previous one ended."""
    return [(lambda H, c=c: command_path(H, c.direction, c.distance, c.angle, c.frame))
            for c in commands]


def move_stages(moves: Sequence[dict]) -> list[StageSpec]:
    """One type I stage (Examples 1–3) per move ``{axis, angle_deg, direction, distance}``."""
    return [(lambda H, m=m: general_motion(H, m["axis"], math.radians(m["angle_deg"]),
                                           m["direction"], m["distance"]))
            for m in moves]
