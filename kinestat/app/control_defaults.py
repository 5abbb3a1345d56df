"""The defaults of ``kinestat control``'s simulated run (the thesis's experiment, Vibhute
2011 §5.1), in a module without imports so that the command line shows them without loading the
cell."""

__all__ = ["TASKS", "DEFAULT_START", "DEFAULT_DIRECTION", "DEFAULT_PLANE_DISTANCE",
           "DEFAULT_PLANE_TILT_DEG"]

DEFAULT_START = "-400,800,-100"
"""The start tool point ``P_tool_F`` (mm, fixed frame) of the default run."""
DEFAULT_DIRECTION = "0.9713,0,-0.2375"
"""The thesis's force direction ``F_req`` (Vibhute §5.1, sign restored)."""
DEFAULT_PLANE_DISTANCE = 2.5
"""The default workpiece plane's distance ahead of the start tool point (mm)."""
DEFAULT_PLANE_TILT_DEG = 5.0
"""The default workpiece normal's tilt from −F_req (degrees)."""
TASKS = ("press", "follow")
"""``kinestat control --task``: press the tool on the workpiece (Vibhute ch. 5, the default) or
slide it along the workpiece holding the normal force (:mod:`kinestat.control.follow`)."""
