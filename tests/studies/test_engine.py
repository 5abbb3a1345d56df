"""Same answers everywhere: local cluster, external scheduler + worker, plain reference;
interrupt and resume; partial output is never a result."""

from __future__ import annotations

import json

import pytest

from kinestat.errors import InputError
from kinestat.studies.base import build_study
from kinestat.studies.engine import run_reference, run_study
from kinestat.studies.platform_design import platform_design_spec
from kinestat.studies.platform_range import platform_range_spec
from kinestat.studies.tolerance import tolerance_spec
from kinestat.studies.workspace import workspace_spec

from .conftest import assert_same_summary


def _studies():
    return {
        "workspace": workspace_spec("puma762", grid=4, chunk_size=1000),
        "platform-range": platform_range_spec(grid=3, chunk_size=200),
        "platform-design": platform_design_spec(values={"height": "50,60,70"}, poses=32,
                                                chunk_size=2),
        "tolerance": tolerance_spec(samples=60, chunk_size=20),
    }


@pytest.fixture(scope="module")
def references():
    return {name: run_reference(build_study(name, spec)) for name, spec in _studies().items()}


def test_local_threads_cluster_equals_reference(tmp_path, references):
    for name, spec in _studies().items():
        res = run_study(build_study(name, spec), tmp_path / name, workers=2, processes=False,
                        progress=False, plots=False)
        assert res.complete and res.chunks_computed == res.chunks_total
        assert_same_summary(res.summary, references[name])


def test_external_scheduler_equals_reference(tmp_path, references, external_scheduler):
    for name, spec in _studies().items():
        res = run_study(build_study(name, spec), tmp_path / name, scheduler=external_scheduler,
                        progress=False, plots=False, timeout_s=60)
        assert res.complete
        assert_same_summary(res.summary, references[name])
        # what is on disk is the same summary
        doc = json.loads((tmp_path / name / "summary.json").read_text())
        assert doc["complete"] is True
        assert_same_summary(doc["summary"], references[name], rtol=0.0)


def test_interrupt_and_resume_equals_uninterrupted(tmp_path):
    study = build_study("workspace", workspace_spec("puma762", grid=4, chunk_size=500))
    assert study.n_chunks == 9
    full = run_study(study, tmp_path / "full", workers=1, processes=False, progress=False,
                     plots=False)
    out = tmp_path / "staged"
    first = run_study(study, out, workers=1, processes=False, progress=False, plots=False,
                      max_chunks=4)
    assert not first.complete and first.summary is None and first.chunks_computed == 4
    assert not (out / "summary.json").exists()  # partial output is never a result
    assert json.loads((out / "manifest.json").read_text())["complete"] is False
    assert len(list((out / "chunks").glob("part-*.json"))) == 4
    # an interrupted write leaves only a temporary file: it does not count as a chunk
    (out / "chunks" / ".part-000005.json.123.tmp").write_text("{")
    second = run_study(study, out, workers=2, processes=False, progress=False, plots=False)
    assert second.complete and second.chunks_reused == 4 and second.chunks_computed == 5
    assert second.summary == full.summary  # bitwise: the reduction order is fixed
    assert json.loads((out / "manifest.json").read_text())["complete"] is True
    # a lost chunk is recomputed, nothing else
    (out / "chunks" / "part-000002.json").unlink()
    (out / "summary.json").unlink()
    third = run_study(study, out, workers=1, processes=False, progress=False, plots=False)
    assert third.chunks_computed == 1 and third.summary == full.summary
    # the rows are one Parquet dataset
    import pyarrow.parquet as pq

    table = pq.read_table(out / "rows", columns=["reach"])
    assert table.num_rows == 4 ** 6
    assert max(table.column("reach").to_pylist()) == full.summary["reach_max"]


def test_other_spec_in_same_directory_is_refused(tmp_path):
    a = build_study("workspace", workspace_spec("puma762", grid=2))
    b = build_study("workspace", workspace_spec("puma762", grid=3))
    run_study(a, tmp_path / "x", workers=1, processes=False, progress=False, plots=False)
    with pytest.raises(InputError, match="different study"):
        run_study(b, tmp_path / "x", workers=1, processes=False, progress=False, plots=False)
    (tmp_path / "y").mkdir()
    (tmp_path / "y" / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="not a kinestat study"):
        run_study(a, tmp_path / "y", workers=1, processes=False, progress=False, plots=False)


def test_killed_run_resumes_to_the_same_summary(tmp_path):
    """SIGKILL a real `kinestat sweep` mid-run, then resume: the result equals the reference."""
    import os
    import signal
    import subprocess
    import sys
    import time

    from .conftest import ROOT

    out = tmp_path / "killed"
    spec = workspace_spec("puma762", grid=5, chunk_size=150)
    study = build_study("workspace", spec)
    cmd = [sys.executable, "-m", "kinestat.cli.main", "sweep", "workspace", "--grid", "5",
           "--chunk-size", "150", "--threads", "--workers", "1", "--no-plots", "--quiet",
           "--output", str(out)]
    proc = subprocess.Popen(cmd, env={**os.environ, "PYTHONPATH": str(ROOT)},
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while len(list(out.glob("chunks/part-*.json"))) < 3:
            assert proc.poll() is None, "the run ended before it could be killed"
            assert time.monotonic() < deadline, "no chunk written within 60 s"
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=30)
    done = len(list(out.glob("chunks/part-*.json")))
    assert 3 <= done < study.n_chunks
    assert not (out / "summary.json").exists()
    res = run_study(study, out, workers=1, processes=False, progress=False, plots=False)
    assert res.complete and res.chunks_reused == done
    assert res.summary == run_reference(study)


def test_every_study_plots_png(tmp_path, references):
    for name, spec in _studies().items():
        files = build_study(name, spec).plot(references[name], tmp_path / name)
        assert files
        for f in files:
            assert (tmp_path / name / f).read_bytes()[:4] == b"\x89PNG"
