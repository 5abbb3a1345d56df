"""Deprecated import path: :mod:`kinestat.robots.puma762.reverse`."""

from __future__ import annotations

from kinestat.robots.puma762.reverse import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.reverse import __all__ as __all__
