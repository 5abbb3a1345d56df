"""Model loading: the embedded models and platform, and ``load(name_or_path)``.

The embedded data stays in :mod:`kinestat.data` (``models/*.toml``, ``platforms/*.toml``); this
module is the one place that reads it, so the model layers (:mod:`kinestat.mechanism`,
:mod:`kinestat.parallel`) never read files. Importing it registers the built-in robots' analytic
IK methods (:mod:`kinestat.robots`), so that a loaded model can use them by name.

>>> from kinestat.io.library import list_models, load, prototype
>>> "puma762" in list_models()
True
>>> load("puma762").n
6
>>> prototype().leg_names
('O', 'P', 'Q', 'R', 'S', 'T')
"""

from __future__ import annotations

import os
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

from kinestat.errors import InputError
from kinestat.io.model_toml import loads_model, read_model
from kinestat.io.platform_toml import loads_platform
from kinestat.mechanism.chain import ChainModel
from kinestat.parallel.platform import Platform
from kinestat.robots import puma762 as _puma762  # noqa: F401 (registers the robots' IK methods)

if TYPE_CHECKING:
    from kinestat.io.calibration_toml import CalibrationFile

__all__ = ["load", "list_models", "prototype", "list_calibrations", "load_calibration",
           "embedded_text"]


def _data(*parts: str):
    """A file or folder of the embedded data (``kinestat/data``)."""
    return resources.files("kinestat.data").joinpath(*parts)


def embedded_text(*parts: str) -> str:
    """The text of an embedded data file, e.g. ``embedded_text("platforms",
    "prototype-2011.toml")`` (for tools that pass a file's text on, such as the studies'
    workers).

    >>> embedded_text("platforms", "prototype-2011.toml").count("length_unit")
    1
    """
    return _data(*parts).read_text(encoding="utf-8")


def _embedded_names(folder: str) -> list[str]:
    """The names (without ``.toml``) of the embedded files in ``kinestat/data/<folder>``."""
    return sorted(p.name[:-5] for p in _data(folder).iterdir() if p.name.endswith(".toml"))


def _embedded_or_file(s: str, kind: str, folder: str, loads, read):
    """Embedded file ``s`` of ``folder`` through ``loads``, or the TOML file at path ``s``
    through ``read``; None when ``s`` is neither (the caller says what it knows)."""
    if s in _embedded_names(folder):
        return loads(embedded_text(folder, f"{s}.toml"), source=f"<embedded {s}>")
    p = Path(s)
    if p.suffix == ".toml" or p.exists():
        if not p.exists():
            raise InputError(f"{kind} file {s!r} does not exist")
        return read(p)
    return None


def list_models() -> list[str]:
    """Names of the embedded models, sorted.

    >>> list_models()[:2]
    ['nadkarni-config1', 'nadkarni-config2']
    """
    return _embedded_names("models")


def load(name_or_path: str | os.PathLike | ChainModel, *, tip: str | None = None,
         base: str | None = None, scale: float | None = None,
         length_unit: str | None = None) -> ChainModel:
    """An embedded model by name (``"puma762"``, ``"puma560"``, ``"nadkarni-config1"``, ...),
    a TOML model file or a URDF file (``.urdf``) by path; a :class:`ChainModel` is returned as
    it is.

    For a URDF (docs/urdf.md): the chain from link ``base`` (default: the root) to link ``tip``
    (default: the only chain's end), lengths in ``length_unit`` (default metres, URDF's unit)
    or the file's numbers times ``scale`` (see :func:`kinestat.io.urdf.from_urdf`). These
    options belong to URDF files; with another model they are an InputError.

    >>> m = load("puma560")
    >>> m.n, m.length_unit
    (6, 'm')
    """
    urdf_opts = {"tip": tip, "base": base, "scale": scale, "length_unit": length_unit}
    if isinstance(name_or_path, ChainModel):
        s = None
    else:
        s = os.fspath(name_or_path)
        if Path(s).suffix.lower() == ".urdf":
            from kinestat.io.urdf import read_urdf  # lazy: XML and scipy only for URDF files

            if not Path(s).exists():
                raise InputError(f"URDF file {s!r} does not exist")
            return read_urdf(s, **urdf_opts)
    given = [k for k, v in urdf_opts.items() if v is not None]
    if given:
        raise InputError(f"{', '.join(given)}: options of URDF models, but {s or 'the model'!r} "
                         "is not a .urdf file")
    if s is None:
        return name_or_path
    model = _embedded_or_file(s, "model", "models", loads_model, read_model)
    if model is not None:
        return model
    raise InputError(
        f"unknown model {s!r}: not an embedded model ({', '.join(list_models())}) "
        "and not a TOML or URDF file path"
    )


@lru_cache(maxsize=1)
def prototype() -> Platform:
    """The embedded 2011 prototype platform (``kinestat/data/platforms/prototype-2011.toml``).

    Base side 120 mm, top side 60 mm, offsets 28 mm and 14 mm, home height 60 mm, top turned
    −60° at home, k = 2.627 N/mm; legs O, P, Q, R, S, T as in the thesis's code (Vibhute 2011,
    Appendix B).

    >>> p = prototype()
    >>> p.name, p.length_unit, round(float(p.home_pose[2, 3]), 6)
    ('vibhute-2011-prototype', 'mm', 60.0)
    """
    res = _data("platforms", "prototype-2011.toml")
    return loads_platform(res.read_text(encoding="utf-8"), source=str(res))


CALIBRATION_ALIASES = {"thesis": "thesis-2011"}
"""Short names of embedded calibrations (``--calibration thesis``)."""


def list_calibrations() -> list[str]:
    """Names of the embedded leg calibrations, sorted.

    >>> list_calibrations()
    ['thesis-2011']
    """
    return _embedded_names("calibrations")


def load_calibration(name_or_path: str | os.PathLike) -> CalibrationFile:
    """An embedded leg calibration by name (``"thesis"`` = ``"thesis-2011"``) or a TOML
    calibration file by path (schema: :mod:`kinestat.io.calibration_toml`).

    >>> c = load_calibration("thesis")
    >>> c.name, c.calibration.leg_names[:2], float(c.calibration.force_coeffs[0, 1])
    ('thesis-2011', ('O', 'S'), -0.029796)
    """
    from kinestat.io.calibration_toml import (  # lazy: start-up (a model load needs none)
        loads_calibration,
        read_calibration,
    )

    s = os.fspath(name_or_path)
    s = CALIBRATION_ALIASES.get(s, s)
    cal = _embedded_or_file(s, "calibration", "calibrations", loads_calibration, read_calibration)
    if cal is not None:
        return cal
    raise InputError(f"unknown calibration {s!r}: not an embedded calibration "
                     f"({', '.join(['thesis', *list_calibrations()])}) and not a TOML file path")
