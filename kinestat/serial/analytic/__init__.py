"""All inverse-kinematics solutions of 6-joint serial arms (closed forms and the general 6R).

Public entry points: :func:`ik_all`, :class:`IKAllResult`, :func:`select_nearest`.
"""

from kinestat.serial.analytic.result import IKAllResult, Selection, select_nearest, wrap_to_limits
from kinestat.serial.analytic.solve import METHODS, ik_all, method_for

__all__ = ["ik_all", "IKAllResult", "Selection", "select_nearest", "wrap_to_limits", "METHODS",
           "method_for"]
