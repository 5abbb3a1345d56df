"""The analytic IK methods a robot brings to :func:`kinestat.ik_all`, registered by the robot.

The generic dispatch (:mod:`kinestat.serial.analytic.solve`) knows geometry classes (spherical
wrist, three parallel axes, the general 6R); a robot with a closed form of its own registers it
here under a method name with the test of the geometry it applies to, and
``ik_all(model, T, method=NAME)`` runs it. This module names no robot: the built-in robots
register themselves when :mod:`kinestat.robots` is imported (``kinestat.load`` does).

>>> import kinestat
>>> m = kinestat.load("puma762")
>>> "puma762" in registered(), get("puma762").applies(m)
(True, True)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["IKMethod", "register", "registered", "get"]


@dataclass(frozen=True)
class IKMethod:
    """A robot's analytic IK method.

    ``name`` the ``method=`` value; ``applies(model) -> bool`` whether the model has the robot's
    geometry; ``solve(model, T, *, tol, backend) -> IKAllResult`` every solution for poses of
    the end frame ``T (N, 4, 4)`` (the model's length unit); ``geometry`` what ``applies``
    checks, in words (for the error when it does not apply).
    """

    name: str
    applies: Callable[[Any], bool]
    solve: Callable[..., Any]
    geometry: str


_METHODS: dict[str, IKMethod] = {}


def register(method: IKMethod) -> None:
    """Make ``method`` available to :func:`kinestat.ik_all` as ``method=method.name`` (a second
    registration under the same name replaces the first)."""
    _METHODS[method.name] = method


def registered() -> tuple[str, ...]:
    """The names of the registered methods, in the order of registration."""
    return tuple(_METHODS)


def get(name: str) -> IKMethod | None:
    """The method registered as ``name``, or None."""
    return _METHODS.get(name)
