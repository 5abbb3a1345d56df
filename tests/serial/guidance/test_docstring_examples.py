"""The ``>>>`` examples in the docstrings of the guidance, DISP and deck modules run and print
what they say (so the documented behaviour cannot drift from the code)."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "kinestat.serial.guidance.planners",
    "kinestat.serial.guidance.step",
    "kinestat.serial.guidance.run",
    "kinestat.serial.guidance.stages",
    "kinestat.disp.deck",
    "kinestat.io.disp_deck.commands",
    "kinestat.io.disp_deck.reader",
    "kinestat.cli._guidance",
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    result = doctest.testmod(importlib.import_module(name),
                             optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
