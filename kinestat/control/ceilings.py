"""Ceilings of the control loop, in a module without imports so that the command line can show
and check them without loading the controller (docs/reliability.md, "Bounds")."""

__all__ = ["MAX_ITERATIONS"]

MAX_ITERATIONS = 1000
"""Most measurement cycles a run may be given (each is a move and a measurement, seconds on the
real cell; the default is 60 and the thesis's runs take under 10)."""
