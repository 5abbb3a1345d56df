"""The 2011 prototype platform's design specification: Vibhute 2011 Table 3-1.

One definition for everything that holds the platform to it: the safety envelope of the control
loop (:mod:`kinestat.control.envelope`) and the design and range studies
(:mod:`kinestat.studies`). The motion ranges are read as ± from the unloaded pose of the top
relative to the base, one component at a time (docs/seed-errata-vibhute.md, "The kinestatic
control procedure", K11; the OCR lost the degree signs).
"""

__all__ = ["MAX_DEFLECTION", "MAX_LOAD", "MOTION_RANGE_MM", "MOTION_RANGE_DEG", "MOTION_RANGE"]

MAX_DEFLECTION = 5.0
"""Largest leg deflection |l − l0|, mm (Vibhute Table 3-1)."""
MAX_LOAD = 50.0
"""Largest load on the platform, N (Vibhute Table 3-1)."""
MOTION_RANGE_MM = (3.5, 3.5, 4.0)
"""Translation ranges of the top relative to the base along x, y, z, mm (Table 3-1)."""
MOTION_RANGE_DEG = (4.0, 4.0, 6.0)
"""Rotation ranges of the top relative to the base about x, y, z, degrees (Table 3-1)."""
MOTION_RANGE = MOTION_RANGE_MM + MOTION_RANGE_DEG
"""The six ranges in the order x, y, z (mm), rotation about x, y, z (degrees)."""
