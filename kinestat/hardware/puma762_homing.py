"""Deprecated import path: the PUMA 762's homing offsets are
:mod:`kinestat.robots.puma762.homing`."""

from __future__ import annotations

from kinestat.robots.puma762.homing import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.homing import __all__ as __all__
