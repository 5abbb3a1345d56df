"""A study's output directory: manifest, per-chunk results written atomically, final summary.

Layout::

    DIR/manifest.json              study, spec, spec hash, chunk count, "complete" flag
    DIR/manifest.sha256            the manifest's checksums of the chunk files (sha256sum format)
    DIR/rows/part-000042.parquet   the chunk's rows (DIR/rows is one Parquet dataset)
    DIR/chunks/part-000042.json    the chunk's partial summary; its presence marks the chunk done
    DIR/summary.json               written only when every chunk is done ("complete": true)
    DIR/plots/*.png                plots of the complete study

Every file is written to a temporary name in its directory and renamed into place, so a killed
run leaves whole files or none; then the SHA-256 of the chunk's files is appended to
``manifest.sha256`` (one write, synced: ``sha256sum -c manifest.sha256`` checks a directory by
hand). A rerun with the same spec skips the chunks whose files are listed there and match;
a chunk whose ``.json`` is missing from the list or differs from it (a damaged disk, a file
edited or truncated, a run killed between the rename and the checksum) is reported and
recomputed (:attr:`StudyStore.damaged`). A different spec in the same directory is refused.
``summary.json`` never exists for an incomplete study, so partial output cannot be taken for a
result.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

from kinestat.errors import InputError

__all__ = ["StudyStore", "write_atomic"]

MANIFEST = "manifest.json"
CHECKSUMS = "manifest.sha256"
SUMMARY = "summary.json"
FORMAT = "kinestat-study/2"


def write_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same directory + rename."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _json_bytes(obj) -> bytes:
    return (json.dumps(obj, indent=1, allow_nan=False) + "\n").encode()


class StudyStore:
    """The output directory of one study (see the module docstring)."""

    def __init__(self, root: Path, study: str, spec: dict, spec_hash: str, n_chunks: int):
        self.root = Path(root)
        self.study, self.spec, self.hash, self.n_chunks = study, spec, spec_hash, n_chunks
        self.chunks = self.root / "chunks"
        self.rows = self.root / "rows"
        self.damaged: list[int] = []  # chunks found damaged by done_chunks(), to recompute

    # -- opening ---------------------------------------------------------------------------
    def check(self) -> set[int]:
        """Check (reading only) that the directory is new, empty or holds this very study;
        returns the chunks already done."""
        self._check()
        return self.done_chunks()

    def open(self) -> None:
        """Create the directory (with its manifest) unless it holds this study already."""
        if not self._check():
            self.root.mkdir(parents=True, exist_ok=True)
            self._write_manifest(complete=False)

    def _check(self) -> bool:
        """True if the directory holds this study; False if it is new or empty."""
        man = self.root / MANIFEST
        if man.exists():
            try:
                old = json.loads(man.read_bytes())
            except (OSError, ValueError, RecursionError) as exc:
                raise InputError(f"--output {self.root}: unreadable {MANIFEST} ({exc}); "
                                 "choose another directory") from None
            if not isinstance(old, dict):
                raise InputError(f"--output {self.root}: {MANIFEST} is not a study manifest; "
                                 "choose another directory")
            if old.get("spec_hash") != self.hash or old.get("study") != self.study:
                raise InputError(
                    f"--output {self.root} holds a different study ({old.get('study')!r}, "
                    f"spec {str(old.get('spec_hash'))[:12]}); its inputs differ from this run's "
                    "— choose another --output or delete that directory")
            return True
        if self.root.exists() and not self.root.is_dir():
            raise InputError(f"--output {self.root} is a file; give a directory")
        if self.root.exists() and any(self.root.iterdir()):
            raise InputError(f"--output {self.root} exists and is not a kinestat study "
                             "directory (no manifest.json); choose an empty or new directory")
        return False

    def _write_manifest(self, complete: bool) -> None:
        write_atomic(self.root / MANIFEST, _json_bytes({
            "format": FORMAT, "study": self.study, "spec_hash": self.hash,
            "chunks": self.n_chunks, "complete": complete, "spec": self.spec}))

    # -- chunks ----------------------------------------------------------------------------
    def _part(self, i: int, ext: str) -> Path:
        return (self.rows if ext == "parquet" else self.chunks) / f"part-{i:06d}.{ext}"

    def _checksums(self) -> dict[str, str]:
        """``manifest.sha256`` as {relative path: hex}; a torn or foreign line is skipped (its
        chunk then counts as unverified)."""
        sums: dict[str, str] = {}
        try:
            text = (self.root / CHECKSUMS).read_bytes().decode("ascii", "replace")
        except OSError:
            return sums
        for line in text.splitlines():
            digest, sep, name = line.partition("  ")
            if sep and len(digest) == 64 and all(c in "0123456789abcdef" for c in digest):
                sums[name] = digest
        return sums

    def _intact(self, i: int, sums: dict[str, str]) -> bool:
        for ext in ("json", "parquet"):
            p = self._part(i, ext)
            name = p.relative_to(self.root).as_posix()
            if name not in sums:
                if ext == "json":
                    return False
                continue  # a chunk without rows (--no-arrays)
            try:
                if hashlib.sha256(p.read_bytes()).hexdigest() != sums[name]:
                    return False
            except OSError:
                return False
        return True

    def done_chunks(self) -> set[int]:
        """Chunks whose files are on disk and match their checksums; the others found are
        listed in :attr:`damaged` (they are recomputed)."""
        done: set[int] = set()
        self.damaged = []
        if not self.chunks.is_dir():
            return done
        sums = self._checksums()
        for p in self.chunks.glob("part-*.json"):
            try:
                i = int(p.stem.split("-")[1])
            except (IndexError, ValueError):
                continue
            if 0 <= i < self.n_chunks:
                (done.add if self._intact(i, sums) else self.damaged.append)(i)
        self.damaged.sort()
        return done

    def write_chunk(self, i: int, columns: dict[str, np.ndarray], partial: dict) -> None:
        """Rows (Parquet) first, then the partial summary that marks chunk ``i`` done, then
        their checksums."""
        files: list[tuple[Path, bytes]] = []
        if columns:
            import pyarrow as pa  # lazy: only studies write Parquet
            import pyarrow.parquet as pq  # lazy: pyarrow only when rows are written

            table = pa.table({k: np.ascontiguousarray(v) for k, v in columns.items()})
            sink = pa.BufferOutputStream()
            pq.write_table(table, sink, compression="zstd")
            files.append((self._part(i, "parquet"), sink.getvalue().to_pybytes()))
        files.append((self._part(i, "json"), _json_bytes(
            {"chunk": i, "spec_hash": self.hash, "partial": partial})))
        for path, data in files:
            write_atomic(path, data)
        lines = "".join(f"{hashlib.sha256(data).hexdigest()}  "
                        f"{path.relative_to(self.root).as_posix()}\n" for path, data in files)
        fd = os.open(self.root / CHECKSUMS, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, lines.encode("ascii"))
            os.fsync(fd)
        finally:
            os.close(fd)

    def read_partials(self) -> list[dict]:
        """Partial summaries of chunks 0..n-1, in order (all must be done)."""
        out = []
        for i in range(self.n_chunks):
            try:
                doc = json.loads(self._part(i, "json").read_bytes())
            except (OSError, ValueError) as exc:
                raise InputError(f"{self._part(i, 'json')} is unreadable ({exc}); run the "
                                 "command again to recompute it") from None
            if not isinstance(doc, dict) or "partial" not in doc:
                raise InputError(f"{self._part(i, 'json')} is not a chunk's summary; run the "
                                 "command again to recompute it")
            if doc.get("spec_hash") != self.hash or doc.get("chunk") != i:
                raise InputError(f"{self._part(i, 'json')} belongs to another study; delete "
                                 f"{self.root} and run again")
            out.append(doc["partial"])
        return out

    # -- completion ------------------------------------------------------------------------
    def write_summary(self, document: dict) -> Path:
        """Write ``summary.json`` and mark the manifest complete."""
        path = self.root / SUMMARY
        write_atomic(path, _json_bytes(document))
        self._write_manifest(complete=True)
        return path

    def is_complete(self) -> bool:
        return (self.root / SUMMARY).exists()
