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

__all__ = ["Study", "spec_hash", "spec_json", "build_study", "STUDIES"]

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
