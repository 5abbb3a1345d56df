"""The JSON-lines cycle log."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinestat.control.log import CycleLog, jsonable, read_log
from kinestat.errors import InputError


def test_every_record_is_on_disk_as_soon_as_it_is_written(tmp_path):
    path = tmp_path / "runs" / "log.jsonl"
    log = CycleLog(path)
    log.write({"type": "start", "a": np.arange(3), "x": np.float64(1.5)})
    # readable by another reader before the log is closed
    assert read_log(path) == [{"type": "start", "a": [0, 1, 2], "x": 1.5}]
    log.write({"type": "cycle", "v": np.nan, "w": -np.inf, "b": np.bool_(True)})
    lines = path.read_text().splitlines()
    assert len(lines) == 2 and json.loads(lines[1]) == {"type": "cycle", "v": "nan",
                                                       "w": "-inf", "b": True}
    log.close()
    with pytest.raises(InputError, match="closed"):
        log.write({})


def test_jsonable_and_errors(tmp_path):
    assert jsonable({1: (np.int64(2), [np.float32(0.5)])}) == {"1": [2, [0.5]]}
    bad = tmp_path / "bad.jsonl"
    bad.write_text('{"ok": 1}\nnot json\n')
    with pytest.raises(InputError, match="line 2"):
        read_log(bad)
    with pytest.raises(InputError):
        read_log(tmp_path / "missing.jsonl")
    (tmp_path / "file").write_text("")
    with pytest.raises(InputError, match="cannot write"):
        CycleLog(tmp_path / "file" / "log.jsonl")
