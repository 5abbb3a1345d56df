"""Checking a listening address before binding it: loopback unless remote access is asked for.

Shared by the servers that let whoever connects act: the Galil simulator
(:class:`kinestat.sim.galil_server.GalilSimServer`, motion commands) and the viewer
(:func:`kinestat.viz.serve.make_server`, IK answered by Python). The host is resolved ONCE and
the checked address is the one to bind, so a name cannot pass the loopback check and then bind
all interfaces. Layer 5 (io: the network side of files and sockets), so that viz (3) and sim (4)
both use this one implementation.
"""

from __future__ import annotations

import ipaddress
import socket

from kinestat.errors import InputError

__all__ = ["resolve_bind_address", "check_bind_address"]


def resolve_bind_address(host: str, port: int, allow_remote: bool, *,
                         what: str = "the Galil simulator",
                         exposure: str = "it accepts motion commands from anyone who can reach it"
                         ) -> tuple[socket.AddressFamily, tuple]:
    """Resolve ``host`` ONCE and check the address that will be bound: ``(family, sockaddr)``.

    A non-loopback address (``0.0.0.0``, ``::``, ``""``, a LAN address, a name resolving to
    one) is refused unless ``allow_remote`` is the bool True. ``allow_remote`` must be a real
    bool (``"false"`` is refused, not taken as true). ``what`` names the server and
    ``exposure`` says what a remote client could do, for the message. Bind exactly the
    ``sockaddr`` returned.

    >>> resolve_bind_address("127.0.0.1", 0, False)[1]
    ('127.0.0.1', 0)
    """
    if not isinstance(allow_remote, bool):
        raise InputError(f"allow_remote must be True or False, got {allow_remote!r} "
                         f"({type(allow_remote).__name__})")
    server = what.removeprefix("the ")
    if not isinstance(host, str):
        raise InputError(f"{server} bind address must be a string, got {host!r}")
    try:
        infos = socket.getaddrinfo(host or None, port, type=socket.SOCK_STREAM,
                                   proto=socket.IPPROTO_TCP, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as exc:
        raise InputError(f"cannot resolve {server} bind address {host!r}: {exc}") from exc
    family, _, _, _, sockaddr = infos[0]
    addr = str(sockaddr[0])
    if not allow_remote and not ipaddress.ip_address(addr.split("%")[0]).is_loopback:
        shown = host or "all interfaces"
        raise InputError(f"refusing to bind {what} to {shown!r} ({addr}): not a loopback "
                         f"address, and {exposure}. Use 127.0.0.1, or pass allow_remote=True "
                         "/ --allow-remote deliberately")
    return family, sockaddr


def check_bind_address(host: str, allow_remote: bool, **names: str) -> None:
    """Refuse a non-loopback bind address unless ``allow_remote`` (raises InputError); see
    :func:`resolve_bind_address`, which also returns what to bind."""
    resolve_bind_address(host, 0, allow_remote, **names)
