"""Matching Galil DMC replies to their commands (one reply per command, nothing else).

A DMC answers every command with exactly one reply: ``:`` (acknowledged, no data), data then
``\\r\\n:`` (a query: ``TP``, ``MG``, ``TC``...) or ``?`` (rejected). A stale reply left in the
socket (after a timeout, an unsolicited message) shifts every later reply by one: a query then
takes the previous command's acknowledgement, or its data, as its answer. The client therefore
(:class:`kinestat.devices.galil.GalilClient`)

* drains the socket before each command — anything pending is a protocol fault;
* reads exactly one reply (up to the first ``:`` or ``?``) — bytes after it are a fault;
* checks the reply's kind against the command (:func:`match_reply`): data where a query was
  sent, a bare ``:`` where none was. Anything else raises
  :class:`~kinestat.errors.ProtocolError`.

A reply's data may therefore not contain ``:`` or ``?`` (none of the numeric replies the
client reads does; a string message with them is refused rather than guessed at).
"""

from __future__ import annotations

from kinestat.errors import ProtocolError

__all__ = ["QUERY_COMMANDS", "expects_data", "split_reply", "match_reply"]

QUERY_COMMANDS = frozenset({"TP", "MG", "TC", "RP", "TE", "TV", "TS", "TI", "TB", "QR", "LM",
                            "MT", "ID", "RV", "SC", "TD", "TT", "TH", "TZ", "LS", "LL"})
"""DMC commands whose reply carries data before the ``:`` (any command with ``?`` too)."""


def expects_data(cmd: str) -> bool:
    """True when ``cmd`` is a query (its reply carries data), e.g. ``TP``, ``MG _TPA``,
    ``SP ?``.

    >>> expects_data("MG _TPD"), expects_data("PA 1,2"), expects_data("SP ?,?")
    (True, False, True)
    """
    c = cmd.strip().upper()
    return c[:2] in QUERY_COMMANDS or "?" in c


def split_reply(buf: bytes) -> tuple[bytes, bytes] | None:
    """The first complete reply in ``buf`` (up to and including the first ``:`` or ``?``) and
    what follows it; None while the reply is incomplete.

    >>> split_reply(b" 12.0000\\r\\n:")
    (b' 12.0000\\r\\n:', b'')
    >>> split_reply(b": 5.0000\\r\\n:")
    (b':', b' 5.0000\\r\\n:')
    """
    ends = [i for i in (buf.find(b":"), buf.find(b"?")) if i >= 0]
    if not ends:
        return None
    k = min(ends) + 1
    return buf[:k], buf[k:]


def match_reply(cmd: str, reply: bytes, where: str = "the Galil") -> str:
    """The data of ``reply`` to ``cmd`` (``""`` for an acknowledgement, ``"?"`` for a
    rejection); :class:`ProtocolError` if the reply's kind does not fit the command.

    >>> match_reply("MG _TPA", b" 1234.0000\\r\\n:")
    '1234.0000'
    >>> match_reply("BG", b":")
    ''
    """
    text = reply.decode("ascii", errors="replace")
    data = text[:-1].strip()
    if text.endswith("?"):
        if data:
            raise ProtocolError(f"{where}: unexpected {data!r} before the '?' answering {cmd!r} "
                                "(a stale or unsolicited reply); the link is out of step")
        return "?"
    if expects_data(cmd) and not data:
        raise ProtocolError(f"{where}: {cmd!r} is a query but the reply carries no data "
                            f"({text!r}: a stale acknowledgement?); the link is out of step")
    if not expects_data(cmd) and data:
        raise ProtocolError(f"{where}: {cmd!r} takes a bare ':' but the reply is {text!r} "
                            "(a stale or unsolicited reply); the link is out of step")
    return data
