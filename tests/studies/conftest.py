"""Shared fixtures of the study tests: a planar 2-link model, an external Dask cluster."""

from __future__ import annotations

import math
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

L1, L2 = 1.0, 0.5



def _revolute(name: str, a: float) -> str:
    return (f'\n[[joints]]\nname = "{name}"\ntype = "revolute"\ntheta = 0.0\nd = 0.0\n'
            f"a = {a}\nalpha = 0.0\nlimits = [-180.0, 180.0]\n")


PLANAR_TOML = ('name = "planar2"\nnotation = "standard_dh"\nlength_unit = "m"\n'
               'angle_unit = "deg"\n' + _revolute("1", L1) + _revolute("2", L2))


@pytest.fixture
def planar_model(tmp_path) -> str:
    p = tmp_path / "planar2.toml"
    p.write_text(PLANAR_TOML)
    return str(p)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)


@pytest.fixture(scope="module")
def external_scheduler(tmp_path_factory):
    """``dask scheduler`` + one ``dask worker`` as real subprocesses on loopback.

    Yields the scheduler address; both processes are stopped (terminate, then kill) afterwards.
    """
    dask_bin = Path(sys.executable).parent / "dask"
    if not dask_bin.exists():
        pytest.skip("the dask command is not installed next to this Python")
    log = tmp_path_factory.mktemp("dask")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "DASK_DISTRIBUTED__WORKER__DAEMON": "False"}
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    procs = []
    try:
        procs.append(subprocess.Popen(
            [str(dask_bin), "scheduler", "--host", "127.0.0.1", "--port", str(port),
             "--no-dashboard"], env=env, stdout=subprocess.DEVNULL,
            stderr=open(log / "scheduler.log", "w")))  # noqa: SIM115
        deadline = time.monotonic() + 30
        while True:  # wait until the scheduler listens
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                if time.monotonic() > deadline or procs[0].poll() is not None:
                    pytest.fail("dask scheduler did not start: "
                                + (log / "scheduler.log").read_text()[-2000:])
                time.sleep(0.2)
        procs.append(subprocess.Popen(
            [str(dask_bin), "worker", addr, "--nworkers", "1", "--nthreads", "1",
             "--no-dashboard", "--host", "127.0.0.1", "--local-directory", str(log)],
            env=env, stdout=subprocess.DEVNULL,
            stderr=open(log / "worker.log", "w")))  # noqa: SIM115
        yield addr
    finally:
        for p in reversed(procs):
            _stop(p)


def assert_same_summary(a, b, rtol: float = 1e-12, path: str = "summary") -> None:
    """Counts (ints, bools, strings) equal; floats within ``rtol`` (relative, absolute near 0)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), f"{path}: keys differ"
        for k in a:
            assert_same_summary(a[k], b[k], rtol, f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: lengths differ"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same_summary(x, y, rtol, f"{path}[{i}]")
    elif isinstance(a, float) and not isinstance(b, bool):
        assert isinstance(b, (int, float)), f"{path}: {a!r} vs {b!r}"
        assert math.isclose(a, b, rel_tol=rtol, abs_tol=rtol), f"{path}: {a!r} vs {b!r}"
    else:
        assert a == b and type(a) is type(b), f"{path}: {a!r} vs {b!r}"
