"""Issue 43: a damaged chunk (a flipped byte, a truncated file, a chunk written without its
checksum) is detected by the manifest's checksums, reported and recomputed: the summary equals
the reference, never a traceback."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from kinestat.studies.base import build_study
from kinestat.studies.engine import run_reference, run_study
from kinestat.studies.store import CHECKSUMS
from kinestat.studies.workspace import workspace_spec

from .conftest import assert_same_summary

SPEC = workspace_spec("puma762", grid=4, chunk_size=500)  # 4096 configurations, 9 chunks


def _run(out, **kw):
    return run_study(build_study("workspace", SPEC), out, workers=1, processes=False,
                     progress=False, plots=False, **kw)


def _flip(path, at=-10):
    data = bytearray(path.read_bytes())
    data[at] ^= 0x01
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("damage", ["json-flip", "json-truncated", "json-garbage",
                                    "parquet-flip", "no-checksum", "torn-checksum-line"])
def test_a_damaged_chunk_is_recomputed_to_the_reference_summary(tmp_path, damage):
    out = tmp_path / "w"
    first = _run(out, max_chunks=4)
    assert first.chunks_computed == 4 and not first.complete
    part = out / "chunks" / "part-000002.json"
    if damage == "json-flip":
        _flip(part)
    elif damage == "json-truncated":
        part.write_bytes(part.read_bytes()[:20])
    elif damage == "json-garbage":
        part.write_bytes(b"\xff\xfe" + os.urandom(50))
    elif damage == "parquet-flip":
        _flip(out / "rows" / "part-000002.parquet", at=len(b"PAR1") + 40)
    elif damage == "no-checksum":  # killed between the rename and the checksum
        lines = (out / CHECKSUMS).read_text().splitlines()
        (out / CHECKSUMS).write_text("".join(ln + "\n" for ln in lines
                                             if "part-000002.json" not in ln))
    else:  # the last checksum line torn by a crash: its chunk counts as unverified
        text = (out / CHECKSUMS).read_text()
        (out / CHECKSUMS).write_text(text[:-30])
    res = _run(out)
    assert res.complete and res.chunks_damaged == 1
    assert res.chunks_computed == res.chunks_total - 3  # the damaged one and the 5 left
    assert_same_summary(res.summary, run_reference(build_study("workspace", SPEC)))


def test_sigint_ends_the_sweep_with_one_line_and_it_resumes(tmp_path):
    out = tmp_path / "w"
    env = dict(os.environ, PYTHONPATH=os.getcwd())
    cmd = [sys.executable, "-m", "kinestat.cli.main", "sweep", "workspace", "--samples",
           "3000000", "--chunk-size", "20000", "--output", str(out), "--workers", "1",
           "--threads", "--quiet"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, preexec_fn=lambda: signal.signal(signal.SIGINT,
                                                                      signal.SIG_DFL))
    t0 = time.monotonic()
    while not list((out / "chunks").glob("part-*.json")):
        assert proc.poll() is None and time.monotonic() - t0 < 180, proc.communicate()
        time.sleep(0.2)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    lines = err.strip().splitlines()
    assert proc.returncode == 130 and len(lines) == 1, err
    assert lines[0].startswith("kinestat: interrupted: workspace: ") and "resume" in lines[0]
    assert "Traceback" not in err
