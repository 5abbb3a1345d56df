"""Old home of the leg calibration maps, kept because docs/platform.md documents this path.

The maps now live in :mod:`kinestat.hardware.leg_calibration` (a hardware convention shared by
control, devices and sim); import from there in new code.
"""

from kinestat.hardware.leg_calibration import *  # noqa: F403 - documented re-export
