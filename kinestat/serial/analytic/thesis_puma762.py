"""Deprecated import path: :mod:`kinestat.robots.puma762.analytic` (the PUMA 762's closed form
as the ``"puma762"`` method of :func:`kinestat.ik_all`)."""

from __future__ import annotations

from kinestat.robots.puma762.analytic import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.analytic import __all__ as __all__
