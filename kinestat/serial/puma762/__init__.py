"""Deprecated import path: the PUMA 762's closed form is :mod:`kinestat.robots.puma762.closed_form`
(the robot is one package, :mod:`kinestat.robots.puma762`). Every name stays importable here."""

from __future__ import annotations

from kinestat.robots.puma762.closed_form import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.closed_form import _A, _CA, _S, _SA  # noqa: F401 (read by tests)
from kinestat.robots.puma762.closed_form import __all__ as __all__
