"""Deprecated import path: the PUMA 762's closed form is :mod:`kinestat.robots.puma762.closed_form`
(the robot is one package, :mod:`kinestat.robots.puma762`). Every name stays importable here."""

from __future__ import annotations

import kinestat.serial.puma762.forward
import kinestat.serial.puma762.params
import kinestat.serial.puma762.reverse
import kinestat.serial.puma762.selection  # noqa: F401
from kinestat.robots.puma762 import closed_form as _closed_form
from kinestat.robots.puma762.closed_form import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.closed_form import _A, _CA, _S, _SA  # noqa: F401 (read by tests)
from kinestat.robots.puma762.closed_form import __all__ as __all__

# loading the submodules above bound their names here: ``forward`` and ``reverse`` are the
# functions, as they always were
forward, reverse = _closed_form.forward, _closed_form.reverse
