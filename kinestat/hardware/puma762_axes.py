"""Deprecated import path: the PUMA 762's axis conventions are :mod:`kinestat.robots.puma762.axes`
(encoder scales, joint-1 offset, the axis 4 -> 5 coupling, the thesis's tool point)."""

from __future__ import annotations

from kinestat.robots.puma762.axes import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.axes import __all__ as __all__
