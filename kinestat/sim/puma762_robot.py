"""Deprecated import path: the PUMA 762's physical layout (index marks, pots' ready positions) is
:mod:`kinestat.robots.puma762.layout`."""

from __future__ import annotations

from kinestat.robots.puma762.layout import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.layout import __all__ as __all__
