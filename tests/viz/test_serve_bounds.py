"""Issue 43: the viewer's server bounds every request (413 for a body, 431 for headers, 400
for a malformed one), answers every request and keeps serving."""

from __future__ import annotations

import json
import socket
import threading

import numpy as np
import pytest

import kinestat
from kinestat.viz.scene import model_scene, opening_q
from kinestat.viz.serve import MAX_BODY, MAX_HEADERS, make_server

ARM = kinestat.load("puma762")


@pytest.fixture(scope="module")
def server():
    srv = make_server(model_scene(ARM), model=ARM)
    t = threading.Thread(target=srv.serve_forever, daemon=True)
    t.start()
    yield srv.server_address[1]
    srv.shutdown()
    srv.server_close()


def _exchange(port: int, raw: bytes, timeout: float = 5.0) -> tuple[int, bytes]:
    """Send ``raw`` and read the answer until the server closes or the body is complete."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        try:
            s.sendall(raw)
        except OSError:  # the server answered and closed before reading everything
            pass
        data = b""
        while True:
            try:
                chunk = s.recv(65536)
            except (ConnectionResetError, TimeoutError):
                break
            if not chunk:
                break
            data += chunk
            head, sep, body = data.partition(b"\r\n\r\n")
            if sep and b"Content-Length:" in head:
                n = int(head.split(b"Content-Length:")[1].split(b"\r\n")[0])
                if len(body) >= n:
                    break
    assert data.startswith(b"HTTP/1."), data[:80]
    return int(data.split()[1]), data.partition(b"\r\n\r\n")[2]


def _post(port: int, body: bytes, timeout: float = 5.0) -> tuple[int, bytes]:
    return _exchange(port, b"POST /ik HTTP/1.1\r\nHost: x\r\nConnection: close\r\n"
                     + b"Content-Length: " + str(len(body)).encode() + b"\r\n\r\n" + body,
                     timeout)


@pytest.mark.parametrize("body", [b"null", b"[]", b"[1, 2]", b'"a string"', b"42",
                                  b"[" * 100_000 + b"]" * 100_000, b"{", b"\xff\xfe",
                                  b'{"q": ' + b"9" * 5000 + b"}"])
def test_a_malformed_ik_request_is_answered_400(server, body):
    code, ans = _post(server, body)
    assert code == 400 and json.loads(ans)["solutions"] == []


@pytest.mark.parametrize("body", [b'{"q": null}', b'{"q": "x", "target": {}}',
                                  b'{"q": [1, 2], "target": [0, 0, 0]}',
                                  b'{"q": [[1]], "target": [1e999, 0, 0]}'])
def test_wrong_fields_get_an_error_answer(server, body):
    code, ans = _post(server, body, timeout=300)
    assert code == 200 and json.loads(ans)["error"]


def test_a_large_body_is_refused_413_without_being_read(server):
    code, ans = _exchange(server, b"POST /ik HTTP/1.1\r\nHost: x\r\nContent-Length: "
                          + str(64 << 20).encode() + b"\r\n\r\n" + b"x" * 1000)
    assert code == 413 and str(MAX_BODY) in json.loads(ans)["error"]


@pytest.mark.parametrize("length", [b"-1", b"abc", b"1e3", b"\xc3\xa9"])
def test_a_bad_content_length_is_400(server, length):
    code, _ = _exchange(server, b"POST /ik HTTP/1.1\r\nHost: x\r\nContent-Length: " + length
                        + b"\r\n\r\n{}")
    assert code == 400


@pytest.mark.parametrize("head", [
    b"".join(b"X-H%d: %s\r\n" % (i, b"v" * 1000) for i in range(60)),  # 60 KB in all
    b"X-Long: " + b"v" * (MAX_HEADERS + 10) + b"\r\n",                   # one long line
    b"".join(b"X-%d: 1\r\n" % i for i in range(150)),                    # too many
])
def test_oversized_headers_are_431(server, head):
    code, _ = _exchange(server, b"GET / HTTP/1.1\r\nHost: x\r\n" + head + b"\r\n")
    assert code == 431


def test_the_server_keeps_serving_and_answers_ik(server):
    q0 = opening_q(ARM)  # the page's opening configuration, within the limits
    target = kinestat.fk(ARM, q0 + 0.1)[:3, 3]
    body = json.dumps({"q": q0.tolist(), "target": target.tolist()}).encode()
    code, ans = _post(server, body, timeout=300)  # the first IK compiles its kernels
    sols = json.loads(ans)["solutions"]
    assert code == 200 and sols
    for s in sols:  # each solution reaches the target (independent FK check)
        np.testing.assert_allclose(kinestat.fk(ARM, np.asarray(s))[:3, 3], target, atol=1e-6)
    code, page = _exchange(server, b"GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
    assert code == 200 and b"<html" in page.lower()
