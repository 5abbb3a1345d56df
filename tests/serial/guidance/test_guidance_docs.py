"""The examples of docs/guidance.md run and print what the guide says."""

from __future__ import annotations

import doctest
from pathlib import Path


def test_guidance_guide_examples_run():
    guide = Path(__file__).resolve().parents[3] / "docs" / "guidance.md"
    result = doctest.testfile(str(guide), module_relative=False,
                              optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 15 and result.failed == 0
