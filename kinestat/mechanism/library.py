"""Embedded models and ``load(name_or_path)``."""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

from kinestat.errors import InputError
from kinestat.mechanism.chain import ChainModel

__all__ = ["load", "list_models"]


def _models_dir():
    return resources.files("kinestat.data") / "models"


def list_models() -> list[str]:
    """Names of the embedded models."""
    return sorted(p.name[:-5] for p in _models_dir().iterdir() if p.name.endswith(".toml"))


def load(name_or_path: str | os.PathLike) -> ChainModel:
    """An embedded model by name (``"puma762"``, ``"puma560"``, ``"nadkarni-config1"``, ...)
    or a TOML model file by path."""
    from kinestat.io.model_toml import loads_model, read_model

    if isinstance(name_or_path, ChainModel):
        return name_or_path
    s = os.fspath(name_or_path)
    if s in list_models():
        res = _models_dir() / f"{s}.toml"
        return loads_model(res.read_text(encoding="utf-8"), source=f"<embedded {s}>")
    p = Path(s)
    if p.suffix == ".toml" or p.exists():
        if not p.exists():
            raise InputError(f"model file {s!r} does not exist")
        return read_model(p)
    raise InputError(
        f"unknown model {s!r}: not an embedded model ({', '.join(list_models())}) "
        "and not a TOML file path"
    )
