"""Deprecated import path: :mod:`kinestat.robots.puma762.selection`."""

from __future__ import annotations

from kinestat.robots.puma762.selection import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.selection import __all__ as __all__
