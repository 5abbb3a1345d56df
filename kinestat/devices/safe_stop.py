"""Sending ``ST`` when something went wrong: on the link if it is up, else on a fresh one.

After a reply timeout, a protocol fault or a dropped link the client has closed its
connection (a late reply would otherwise be taken for the next one), but the controller may
still be moving the robot and accepting connections. :func:`send_stop` then reconnects ONCE,
within ``reconnect_timeout``, and sends ``ST`` there. It says exactly what happened:
``"ST sent to the Galil"``, ``"ST sent on a fresh connection (...)"`` or
``"ST could not be sent: <why>"``.
"""

from __future__ import annotations

from kinestat.devices.galil import GalilClient
from kinestat.errors import KinestatError

__all__ = ["RECONNECT_TIMEOUT", "send_stop"]

RECONNECT_TIMEOUT = 1.0
"""Bound (s) on the fresh connection and on its ``ST`` reply."""


def send_stop(client: GalilClient, *, reconnect_timeout: float = RECONNECT_TIMEOUT) -> str:
    """Send ``ST`` (best effort, bounded in time); return what was done, for the log."""
    if client.connected:
        try:
            client.stop()
            return "ST sent to the Galil"
        except KinestatError as exc:
            first = f"ST on the open link failed: {exc}"
    else:
        first = "the link was down"
    saved = client.timeout
    try:
        client.timeout = min(saved, float(reconnect_timeout))
        client.connect(timeout=client.timeout)
        client.stop()
    except KinestatError as exc:
        client.close()
        return f"ST could not be sent: {first}; a fresh connection failed too: {exc}"
    finally:
        client.timeout = saved
    return f"ST sent on a fresh connection ({first})"
