"""The viewer's server binds loopback unless remote access is asked for with a real bool, and
binds exactly the address it checked (the guard shared with the Galil simulator)."""

from __future__ import annotations

import socket

import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.errors import InputError
from kinestat.io import netbind
from kinestat.sim import galil_server
from kinestat.viz.scene import model_scene
from kinestat.viz.serve import make_server

ARM = kinestat.load("nadkarni-config2")


def _scene():
    return model_scene(ARM, ARM.q_home)


def test_one_guard_shared_with_the_simulator():
    assert galil_server.resolve_bind_address is netbind.resolve_bind_address
    assert galil_server.check_bind_address is netbind.check_bind_address


@pytest.mark.parametrize("host", ["0.0.0.0", "", "::", "192.168.0.84"])
def test_viewer_refuses_non_loopback_unless_allowed(host):
    with pytest.raises(InputError, match="refusing to bind the viewer.*allow"):
        make_server(_scene(), host=host)


@pytest.mark.parametrize("flag", ["false", "yes", 1, None])
def test_allow_remote_must_be_a_real_bool(flag):
    with pytest.raises(InputError, match="allow_remote must be True or False"):
        make_server(_scene(), host="0.0.0.0", allow_remote=flag)


@pytest.mark.parametrize("host", ["127.0.0.1", "localhost"])
def test_viewer_binds_the_checked_loopback_address(host):
    family, sockaddr = netbind.resolve_bind_address(host, 0, False)
    srv = make_server(_scene(), host=host)
    try:
        assert srv.socket.family == family
        assert srv.server_address[0] == sockaddr[0]
        assert srv.server_address[1] > 0
    finally:
        srv.server_close()


def test_allow_remote_binds_all_interfaces_deliberately():
    srv = make_server(_scene(), host="0.0.0.0", allow_remote=True)
    try:
        assert srv.server_address[0] == "0.0.0.0" and srv.socket.family == socket.AF_INET
    finally:
        srv.server_close()


def test_cli_refuses_in_one_line(capsys):
    assert main(["view", "model", "nadkarni-config2", "--serve", "--host", "0.0.0.0",
                 "--no-open"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("kinestat: error: refusing to bind the viewer")
    assert "--allow-remote" in err[0]


def test_cli_allow_remote_needs_serve(tmp_path, capsys):
    assert main(["view", "model", "nadkarni-config2", "--html", str(tmp_path / "m.html"),
                 "--allow-remote"]) == 2
    assert "--allow-remote goes with --serve" in capsys.readouterr().err
    assert not (tmp_path / "m.html").exists()
