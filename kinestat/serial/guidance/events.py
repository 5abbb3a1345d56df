"""Typed events of a guidance run (Nadkarni ch. IV, "Singularities" 1) and 2)).

Every event is a frozen dataclass with the global 1-based ``step`` (0 = before the first step)
and the 1-based ``stage`` (None before the first stage). ``kind`` names it in records; an event
also reads like the plain record it becomes in JSON (``ev["kind"]``, ``ev["cond"]``, ...,
:meth:`GuidanceEvent.as_dict`). An event that stops a run knows the error it stands for
(:meth:`GuidanceEvent.error`), so nothing maps kinds back to exceptions by string.

=====================  ==================================================================
kind                   event
=====================  ==================================================================
``singular``           :class:`Singularity` — [A] singular; ``action`` says what was done
                       (``perturbed``, ``damped``, ``stopped``)
``joint_limit``        :class:`JointLimitStop` — a joint would pass a limit: stopped
``least_squares``      :class:`LeastSquaresStep` — n ≠ 6: the step's residual
``not_converged``      :class:`NotConverged` — the closed-loop correction failed: stopped
``settle``             :class:`SettleStep` — a correction step straight at the stage target
``target_not_reached`` :class:`TargetNotReached` — settling failed: stopped
``numerical``          :class:`NumericalFailure` — a step's numbers failed (an SVD that did
                       not converge, joints that are not finite): stopped
=====================  ==================================================================
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from kinestat.errors import (
    JointLimitError,
    KinestatError,
    SingularityError,
    UnreachableError,
)

__all__ = [
    "GuidanceEvent",
    "Singularity",
    "JointLimitStop",
    "LeastSquaresStep",
    "NotConverged",
    "SettleStep",
    "TargetNotReached",
    "NumericalFailure",
    "newton_failure",
    "newton_stalled",
]


@dataclass(frozen=True, eq=False)
class GuidanceEvent:
    """Base of all events: ``step`` (global, 1-based) and ``stage`` (1-based or None)."""

    kind: ClassVar[str] = "event"
    stops: ClassVar[bool] = False

    step: int
    stage: int | None

    def as_dict(self) -> dict[str, Any]:
        """The plain record (JSON contract): ``step``, ``stage`` (when set), ``kind``, then the
        event's own fields; fields that are None are left out."""
        out: dict[str, Any] = {"step": self.step}
        if self.stage is not None:
            out["stage"] = self.stage
        out["kind"] = self.kind
        for f in dataclasses.fields(self)[2:]:
            v = getattr(self, f.name)
            if v is not None:
                out[f.name] = v
        return out

    def __getitem__(self, key: str) -> Any:
        return self.as_dict()[key]

    def get(self, key: str, default: Any = None) -> Any:
        return self.as_dict().get(key, default)

    def __contains__(self, key: object) -> bool:
        return key in self.as_dict()

    def error(self, message: str) -> KinestatError:
        """The exception this event stands for when it stopped the run."""
        return KinestatError(message)


@dataclass(frozen=True, eq=False)
class Singularity(GuidanceEvent):
    """[A] (the Jacobian) is singular at the start of a step: condition number ``cond`` of the
    dimensionless Jacobian above the limit. ``action``: ``perturbed`` (small joint increments,
    ``joint_increments``, new configuration ``q``, hand shift), ``damped`` (damped least
    squares with ``damping``) or ``stopped``."""

    kind: ClassVar[str] = "singular"

    sigma_min: float = 0.0
    cond: float = 0.0
    joint_increments: np.ndarray | None = None
    tries: int | None = None
    cond_after: float | None = None
    action: str = "stopped"
    q: np.ndarray | None = None
    hand_shift: float | None = None
    hand_rotation_deg: float | None = None
    damping: float | None = None
    method: str | None = None

    def error(self, message: str) -> KinestatError:
        return SingularityError(message)


@dataclass(frozen=True, eq=False)
class JointLimitStop(GuidanceEvent):
    """Joint ``joint`` (1-based) would pass its ``limit`` side (``limit_value`` in display
    units: deg or length) with ``value``: the run stops with the configuration before."""

    kind: ClassVar[str] = "joint_limit"
    stops: ClassVar[bool] = True

    joint: int = 0
    limit: str = "upper"
    limit_value: float = 0.0
    value: float = 0.0
    unit: str = "deg"
    action: str = "stopped"

    def error(self, message: str) -> KinestatError:
        return JointLimitError(message, joint=self.joint, step=self.step,
                               limit=self.limit_value, value=self.value)


@dataclass(frozen=True, eq=False)
class LeastSquaresStep(GuidanceEvent):
    """n ≠ 6: ``J δq = B`` solved in the least-squares sense with a nonzero ``residual``."""

    kind: ClassVar[str] = "least_squares"

    residual: float = 0.0


@dataclass(frozen=True, eq=False)
class _Unreached(GuidanceEvent):
    """Base of the events that stop a run short of its pose: raised as ``UnreachableError``."""

    stops: ClassVar[bool] = True

    def error(self, message: str) -> KinestatError:
        return UnreachableError(message)


@dataclass(frozen=True, eq=False)
class NotConverged(_Unreached):
    """The closed-loop Newton correction did not reach the ideal pose of the step:
    ``reason`` ``singular`` (the Jacobian where it ended is singular, condition number
    ``cond``), ``out_of_reach`` (the error stopped decreasing with a regular Jacobian) or
    ``diverged`` (the error grew)."""

    kind: ClassVar[str] = "not_converged"

    position_error: float = 0.0
    angle_error_deg: float = 0.0
    iterations: int = 0
    reason: str = ""
    cond: float = 0.0
    action: str = "stopped"


@dataclass(frozen=True, eq=False)
class SettleStep(GuidanceEvent):
    """A correction step straight at the stage target (eq. 4-19 with k = 1), taken from a hand
    that was ``position_error`` / ``angle_error_deg`` away."""

    kind: ClassVar[str] = "settle"

    position_error: float = 0.0
    angle_error_deg: float = 0.0


@dataclass(frozen=True, eq=False)
class TargetNotReached(_Unreached):
    """Settling gave up: the stage target is out of reach or beyond a singularity."""

    kind: ClassVar[str] = "target_not_reached"

    position_error: float = 0.0
    angle_error_deg: float = 0.0
    action: str = "stopped"


@dataclass(frozen=True, eq=False)
class NumericalFailure(GuidanceEvent):
    """A step's numerics failed (``reason``: e.g. the SVD did not converge, the joints are not
    finite): the run stops with the configuration of the step before."""

    kind: ClassVar[str] = "numerical"
    stops: ClassVar[bool] = True

    reason: str = ""


def newton_stalled(history: list[float], window: int = 6) -> bool:
    """True when the last ``window`` Newton iterations did not halve the error."""
    return len(history) > window and history[-1] > 0.5 * history[-1 - window]


def newton_failure(cond: float, cond_limit: float, history: list[float]) -> tuple[str, str]:
    """Why a closed-loop correction failed: ``(reason, explanation)`` from the Jacobian's
    condition number where it ended and the course of the error."""
    if cond > cond_limit:
        return "singular", (f"the Jacobian there is singular (condition number {cond:.3g} > "
                            f"{cond_limit:g}): the path crosses a singularity")
    if len(history) > 1 and history[-1] >= history[0]:
        return "diverged", (f"the error grew from the first iteration with a regular Jacobian "
                            f"(condition number {cond:.3g}): the step is too large for Newton "
                            "from where it started; give more steps")
    return "out_of_reach", (f"the error stopped decreasing with a regular Jacobian (condition "
                            f"number {cond:.3g}): the path pose is out of the mechanism's "
                            "reach there (the path leaves the workspace)")
