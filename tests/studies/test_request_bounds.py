"""Issue 43: every sweep request is bounded before anything is allocated or started, and a
scheduler address that is not a Dask scheduler is refused within --timeout."""

from __future__ import annotations

import http.server
import os
import socket
import threading
import time

import pytest

from kinestat.cli.main import main
from kinestat.errors import ClusterError, InputError
from kinestat.studies import grids
from kinestat.studies.engine import probe_scheduler


def _error(capsys, argv) -> str:
    code = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("kinestat: error:"), err
    return err[0]


def test_two_to_the_62_samples_in_one_chunk_is_refused_before_allocating(capsys, tmp_path):
    """The campaign's MemoryError: the count is checked against the chunk limit and memory."""
    t0 = time.monotonic()
    msg = _error(capsys, ["sweep", "workspace", "--samples", str(2**62), "--max-chunks", "1",
                          "--output", str(tmp_path / "w"), "--quiet"])
    assert "chunks" in msg and "--chunk-size" in msg
    assert time.monotonic() - t0 < 30 and not (tmp_path / "w").exists()


def test_a_chunk_larger_than_memory_allows_is_refused(capsys, tmp_path):
    msg = _error(capsys, ["sweep", "workspace", "--samples", str(10**13), "--chunk-size",
                          str(10**12), "--output", str(tmp_path / "w")])
    assert "GiB" in msg and "give --chunk-size" in msg
    largest = grids.memory_budget() // (2 << 10)
    assert f"give --chunk-size {largest} or less" in msg


def test_check_chunking_bounds_by_independent_arithmetic():
    budget = grids.memory_budget()
    assert grids.check_chunking(10, 4, 100, "x") == 3
    assert grids.check_chunking(budget // 1000, budget // 1000, 1000, "x") == 1
    with pytest.raises(InputError, match="GiB"):
        grids.check_chunking(budget // 1000 + 1, budget // 1000 + 1, 1000, "x")
    with pytest.raises(InputError, match="chunks"):
        grids.check_chunking(grids.MAX_CHUNKS + 1, 1, 8, "x")


@pytest.mark.parametrize(("option", "value", "what"), [
    ("--timeout", "nan", "--timeout must be a finite"), ("--timeout", "inf", "--timeout"),
    ("--timeout", "0", "--timeout"), ("--chunk-size", "0", "--chunk-size must be at least 1"),
    ("--chunk-size", "-5", "--chunk-size"),
])
def test_bad_run_options_are_one_clear_error(capsys, tmp_path, option, value, what):
    msg = _error(capsys, ["sweep", "workspace", "--samples", "100", option, value,
                          "--output", str(tmp_path / "w")])
    assert what in msg


# ------------------------------------------------------------------ not a Dask scheduler


def _listener(on_accept):
    lst = socket.socket()
    lst.bind(("127.0.0.1", 0))
    lst.listen(4)
    held = []

    def run():
        while True:
            try:
                c, _ = lst.accept()
            except OSError:
                return
            held.append(c)
            on_accept(c)

    threading.Thread(target=run, daemon=True).start()
    return lst, f"tcp://127.0.0.1:{lst.getsockname()[1]}"


@pytest.mark.parametrize(("kind", "match"), [
    ("silent", "no Dask handshake within 0.5 s"),
    ("garbage", "not a Dask scheduler's handshake"),
    ("garbage-long", "not a Dask scheduler's handshake"),
])
def test_a_listener_that_is_not_dask_is_refused_within_the_timeout(kind, match):
    send = {"silent": lambda c: None,
            "garbage": lambda c: c.sendall(os.urandom(40)),
            "garbage-long": lambda c: c.sendall(b"\x10" + b"\x00" * 7 + b"x" * 16)}[kind]
    lst, addr = _listener(send)
    t0 = time.monotonic()
    with pytest.raises(ClusterError, match=match):
        probe_scheduler(addr, 0.5)
    assert time.monotonic() - t0 < 1.5
    lst.close()


def test_an_http_server_is_refused_within_the_timeout(capsys, tmp_path):
    srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0),
                                          http.server.BaseHTTPRequestHandler)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        t0 = time.monotonic()
        msg = _error(capsys, ["sweep", "workspace", "--samples", "100", "--timeout", "1",
                              "--scheduler", f"tcp://127.0.0.1:{srv.server_address[1]}",
                              "--output", str(tmp_path / "w")])
        assert "no Dask handshake within 1 s" in msg and time.monotonic() - t0 < 10
        assert not (tmp_path / "w").exists()
    finally:
        srv.shutdown()


@pytest.mark.parametrize(("argv", "what"), [
    (["platform-range", "--max-deflection", "inf"], "--max-deflection must be a finite"),
    (["platform-range", "--max-load", "nan"], "--max-load must be a finite"),
    (["platform-range", "--max-load", "0"], "--max-load"),
    (["platform-design", "--max-deflection", "-1", "--height", "50,60"], "--max-deflection"),
    (["platform-range", "--range-mm", "1,1,inf"], "--range-mm"),
])
def test_platform_limits_must_be_finite_and_positive(capsys, tmp_path, argv, what):
    """``--max-deflection inf`` ended in a traceback (exit 1) writing the spec as JSON."""
    msg = _error(capsys, ["sweep", *argv, "--samples", "10", "--output", str(tmp_path / "w")])
    assert what in msg and not (tmp_path / "w").exists()
