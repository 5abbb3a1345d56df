"""Deprecated import path: :mod:`kinestat.robots.puma762.params`."""

from __future__ import annotations

from kinestat.robots.puma762.params import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.params import __all__ as __all__
