"""What a study is: a pure description the engine can run chunk by chunk anywhere.

A :class:`Study` is built from a JSON-able ``spec`` (every input: the model or platform *text*,
grids, sample counts, seeds, limits), so a worker on another machine rebuilds the same study
from the spec alone. ``compute_chunk(i)`` is a pure function of ``(spec, i)``: it returns the
chunk's rows (flat NumPy columns) and its partial summary (JSON, see
:mod:`kinestat.studies.reduce`). ``reduce`` folds the partials, in chunk order, into the
summary. Nothing here knows about Dask; :mod:`kinestat.studies.engine` does the running.
"""

from __future__ import annotations

import hashlib
import importlib
import json
from abc import ABC, abstractmethod
from functools import lru_cache
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from kinestat.errors import InputError
from kinestat.studies import grids

__all__ = ["Study", "ChunkedStudy", "spec_hash", "spec_json", "build_study", "STUDIES"]

#: name -> "module:class" of the known studies (imported on first use)
STUDIES: dict[str, str] = {
    "workspace": "kinestat.studies.workspace:WorkspaceStudy",
    "platform-range": "kinestat.studies.platform_range:PlatformRangeStudy",
    "platform-design": "kinestat.studies.platform_design:PlatformDesignStudy",
    "tolerance": "kinestat.studies.tolerance:ToleranceStudy",
}


def spec_json(spec: dict) -> str:
    """Canonical JSON text of a spec (sorted keys): what identifies a study's inputs."""
    return json.dumps(spec, sort_keys=True, separators=(",", ":"))


def spec_hash(spec: dict) -> str:
    """SHA-256 (hex) of the canonical spec text."""
    return hashlib.sha256(spec_json(spec).encode()).hexdigest()


class Study(ABC):
    """A chunked study. Subclasses set ``name`` and implement the abstract methods."""

    name: ClassVar[str] = "study"

    def __init__(self, spec: dict) -> None:
        self.spec = spec

    @property
    @abstractmethod
    def n_chunks(self) -> int:
        """Number of chunks."""

    @property
    @abstractmethod
    def n_items(self) -> int:
        """Number of evaluations (configurations, poses, designs, samples) in the study."""

    @abstractmethod
    def compute_chunk(self, i: int) -> tuple[dict[str, np.ndarray], dict]:
        """Rows (flat columns of one length) and the partial summary of chunk ``i``."""

    @abstractmethod
    def reduce(self, partials: list[dict]) -> dict:
        """The summary from every chunk's partial summary, given in chunk order."""

    def plot(self, summary: dict, directory: Path) -> list[str]:
        """Write PNG plots of a complete study into ``directory``; returns the file names."""
        return []

    def describe(self) -> dict[str, Any]:
        """The inputs to echo in the summary (spec without bulky texts)."""
        return {k: v for k, v in self.spec.items() if not k.endswith("_text")}


class ChunkedStudy(Study):
    """A study of ``total`` evaluations in chunks of ``spec["chunk_size"]`` (set by
    :meth:`_set_items` in ``__init__``), with the inputs of a box for ``mode`` grid or samples.
    """

    total: int = 0
    chunk: int = 1
    #: bytes one evaluation may take while its chunk is computed (rows and intermediates: the
    #: measured peak, tracemalloc, rounded up about twice); the chunk size is checked against it
    ROW_BYTES: int = 16 << 10

    def row_bytes(self) -> int:
        return self.ROW_BYTES

    def _set_items(self, total: int, what: str = "evaluations") -> None:
        if total > grids.MAX_POINTS:
            raise InputError(f"{total:.3e} {what} is too many (at most {grids.MAX_POINTS:.3e})")
        self.total = int(total)
        self.chunk = int(self.spec["chunk_size"])
        self._chunks = grids.check_chunking(self.total, self.chunk, self.row_bytes(), what)

    @property
    def n_chunks(self) -> int:
        return self._chunks

    @property
    def n_items(self) -> int:
        return self.total

    def chunk_rows(self, i: int) -> tuple[int, int]:
        """Flat index range ``[start, stop)`` of chunk ``i``."""
        return grids.chunk_range(i, self.total, self.chunk)

    def uniform_inputs(self, i: int, lower, upper) -> np.ndarray:
        """Chunk ``i``'s random inputs ``(rows, n)``, uniform in the box ``[lower, upper]``
        (the chunk's own stream of ``spec["seed"]``)."""
        start, stop = self.chunk_rows(i)
        lo = np.asarray(lower, dtype=float)
        return grids.chunk_rng(self.spec["seed"], i).uniform(lo, upper, size=(stop - start,
                                                                                 lo.size))

    def box_inputs(self, i: int, lower, upper) -> np.ndarray:
        """Chunk ``i``'s inputs ``(rows, n)`` in the box: the tensor grid of ``spec["grid"]``
        values per axis, or uniform samples (``spec["mode"]``)."""
        if self.spec["mode"] == "grid":
            start, stop = self.chunk_rows(i)
            return grids.grid_points(start, stop, lower, upper, self.spec["grid"])
        return self.uniform_inputs(i, lower, upper)


def _load_class(name: str) -> type[Study]:

    mod, cls = STUDIES[name].split(":")
    return getattr(importlib.import_module(mod), cls)


@lru_cache(maxsize=8)
def _cached(name: str, text: str) -> Study:
    return _load_class(name)(json.loads(text))


def build_study(name: str, spec: dict | str) -> Study:
    """The study ``name`` for ``spec`` (cached per process: workers build each study once)."""
    text = spec if isinstance(spec, str) else spec_json(spec)
    return _cached(name, text)
