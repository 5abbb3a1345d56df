"""Deprecated import path: :mod:`kinestat.robots.puma762.forward`."""

from __future__ import annotations

from kinestat.robots.puma762.forward import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.forward import __all__ as __all__
