"""Chunked iteration over large batches — the one helper behind every ``iter_*`` streamer
(:func:`kinestat.serial.fk.iter_fk`, :func:`kinestat.serial.ik.iter_ik`,
:func:`kinestat.robots.puma762.reverse.iter_reverse_batch_pose`) and the NumPy references' bounded
temporaries."""

from __future__ import annotations

from collections.abc import Iterator

from kinestat.errors import InputError

__all__ = ["CHUNK_ROWS", "chunk_slices"]

#: rows per chunk for the NumPy references and the ``iter_*`` streamers (bounded temporaries)
CHUNK_ROWS = 1 << 15


def chunk_slices(n_rows: int, chunk_rows: int = CHUNK_ROWS) -> Iterator[slice]:
    """Consecutive ``slice`` s of at most ``chunk_rows`` rows covering ``range(n_rows)``.

    >>> list(chunk_slices(5, 2))
    [slice(0, 2, None), slice(2, 4, None), slice(4, 5, None)]
    >>> list(chunk_slices(0, 2))
    []
    """
    if chunk_rows < 1:
        raise InputError(f"chunk_rows must be at least 1, got {chunk_rows}")
    for start in range(0, n_rows, chunk_rows):
        yield slice(start, min(start + chunk_rows, n_rows))
