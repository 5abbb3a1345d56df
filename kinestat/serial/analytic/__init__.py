"""All inverse-kinematics solutions of 6-joint serial arms (closed forms and the general 6R).

Public entry points: :func:`ik_all` (with ``locked=`` for 7-joint arms), :func:`ik_self_motion`,
:class:`IKAllResult`, :func:`select_nearest`.
"""

from kinestat.serial.analytic.result import IKAllResult
from kinestat.serial.analytic.solve import METHODS, ik_all, ik_self_motion, method_for

__all__ = ["ik_all", "ik_self_motion", "SelfMotion", "IKAllResult", "Selection", "select_nearest",
           "wrap_to_limits", "METHODS", "method_for"]


def __getattr__(name: str):
    """``SelfMotion`` loads with :mod:`~kinestat.serial.analytic.locked`, the selection step's
    names with :mod:`~kinestat.serial.analytic.selection`, on first use (PEP 562: a first
    ``ik_all`` call does not pay for them)."""
    if name == "SelfMotion":
        from kinestat.serial.analytic.locked import SelfMotion  # lazy: first-call time

        return SelfMotion
    if name in ("Selection", "select_nearest", "wrap_to_limits"):
        from kinestat.serial.analytic import selection  # lazy: first-call time

        return getattr(selection, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
