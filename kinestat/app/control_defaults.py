"""The defaults of ``kinestat control``'s simulated run (the thesis's experiment, Vibhute
2011 §5.1) under their command-line names: :mod:`kinestat.control.defaults` holds them."""

from kinestat.control.defaults import PLANTS, RUN_DEFAULTS, TASKS

__all__ = ["TASKS", "PLANTS", "DEFAULT_START", "DEFAULT_DIRECTION", "DEFAULT_PLANE_DISTANCE",
           "DEFAULT_PLANE_TILT_DEG"]

DEFAULT_START = RUN_DEFAULTS.start
DEFAULT_DIRECTION = RUN_DEFAULTS.direction
DEFAULT_PLANE_DISTANCE = RUN_DEFAULTS.plane_distance
DEFAULT_PLANE_TILT_DEG = RUN_DEFAULTS.plane_tilt_deg
