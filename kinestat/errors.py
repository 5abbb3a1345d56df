"""The kinestat error hierarchy.

Every error kinestat raises on purpose derives from :class:`KinestatError`. Messages say what
was wrong, where, and what to do about it.
"""

from __future__ import annotations


class KinestatError(Exception):
    """Base class of every error kinestat raises on purpose."""


class InputError(KinestatError, ValueError):
    """An argument has the wrong shape, a NaN, an impossible value or an unknown name."""


class ParseError(InputError):
    """A file (a DISP deck, a TOML model, ...) could not be read.

    Carries where: the file, the line (1-based), the card or table, the field and the columns.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        line: int | None = None,
        card: str | None = None,
        field: str | None = None,
        columns: tuple[int, int] | None = None,
    ) -> None:
        self.file = file
        self.line = line
        self.card = card
        self.field = field
        self.columns = columns
        where = []
        if file is not None:
            where.append(str(file))
        if line is not None:
            where.append(f"line {line}")
        if card is not None:
            where.append(card)
        if field is not None:
            where.append(f"field {field}")
        if columns is not None:
            where.append(f"columns {columns[0]}-{columns[1]}")
        prefix = (", ".join(where) + ": ") if where else ""
        super().__init__(prefix + message)


class ModelError(InputError):
    """A mechanism or platform description is inconsistent (unknown joint kind, bad limits...)."""


class SingularityError(KinestatError):
    """A configuration is singular where a regular one is needed (Jacobian rank < 6...)."""


class UnreachableError(KinestatError):
    """A requested pose has no real solution; the message says which step failed."""


class JointLimitError(KinestatError):
    """A motion would leave the joint limits; carries the joint, the step and the limit."""

    def __init__(self, message: str, *, joint: int | None = None, step: int | None = None,
                 limit: float | None = None, value: float | None = None) -> None:
        self.joint = joint
        self.step = step
        self.limit = limit
        self.value = value
        super().__init__(message)


class SafetyStop(KinestatError):
    """The controller stopped the cell on purpose (envelope, stale data, device fault)."""


class DeviceError(KinestatError):
    """A device or protocol fault: a dropped link, a timeout, a rejected command."""


class ProtocolError(DeviceError):
    """A packet or reply did not follow the protocol (corrupt, out of sequence, unparseable)."""


class StopRequested(KeyboardInterrupt):
    """A termination signal (SIGTERM, SIGHUP) asked the program to stop: handled as Ctrl-C is.

    A ``KeyboardInterrupt`` (not an ``Exception``), so that no ``except Exception`` on the way
    swallows it; ``signal_name`` is e.g. ``"SIGTERM"``.
    """

    def __init__(self, signum: int, signal_name: str) -> None:
        self.signum = int(signum)
        self.signal_name = signal_name
        super().__init__(f"stopped by {signal_name}")


class ClusterError(KinestatError):
    """A study's compute cluster failed: the Dask scheduler unreachable, no workers joined."""


class KinestatWarning(UserWarning):
    """Something kinestat did that may not be what was meant (e.g. a URDF whose lengths look
    like millimetres); the CLI prints it as one line on stderr."""
