"""Ceilings of the device layer, in a module without imports so that the command line can show
and check them without loading the drivers (docs/reliability.md, "Bounds")."""

__all__ = ["MAX_SAMPLES"]

MAX_SAMPLES = 1000
"""Most sensor packets averaged per measurement (5 s of the 200 Hz stream)."""
