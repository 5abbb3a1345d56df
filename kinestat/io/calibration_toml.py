"""TOML leg-calibration files: per-leg maps from encoder counts to leg length and leg force.

The controller turns the platform's leg counts into lengths (for the platform's forward
kinematics) and forces (for the wrench) through a calibration
(:class:`kinestat.hardware.leg_calibration.LegCalibration`). A file holds six ``[[legs]]``
tables, sensor legs 1..6 in order; each gives its two maps as ascending polynomial
coefficients in the count ``e`` (``l(e) = Σ length[k]·e^k``), or as calibration data that are
fitted by least squares (:func:`kinestat.hardware.leg_calibration.fit_polynomial`)::

    name = "thesis-2011"
    description = "..."              # optional
    source = "..."                   # optional: where the numbers come from
    length_unit = "mm"               # required; mm only
    force_unit = "N"                 # required; N only
    force_sense = "tension"          # optional: "tension" (default, positive when stretched)
                                     # or "compression" (the thesis's own sign)

    [[legs]]
    sensor = 1                       # optional check: the table's position, 1..6
    leg = "O"                        # the platform leg this sensor measures
    length = [91.9216, -0.025771]    # mm:  l = 91.9216 − 0.025771 e
    force = [14.25, -0.029796]       # N:   F = 14.25 − 0.029796 e (tension)
    index_count = 0                  # optional: the count the box sets at the leg's index
                                     # mark (default 0: the maps count from the index)

    [[legs]]                         # data instead of coefficients (any degree >= 1)
    leg = "S"
    length_counts = [0, 500, 1000, 1500]
    lengths = [79.29, 66.57, 53.84, 41.11]
    length_degree = 1                # default 1
    force_counts = [0, 250, 500, 750, 1000]
    forces = [13.41, 6.3, -0.8, -7.9, -15.0]
    force_degree = 3                 # default 1: a non-linear leg law

The embedded ``thesis-2011`` file (``kinestat/data/calibrations``) holds the 2011 prototype's
maps (Vibhute App. D.7 ``leg_to_T10.m``) with the signs the OCR lost restored
(docs/seed-errata.md); load it with :func:`kinestat.io.library.load_calibration`.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kinestat.errors import InputError, ParseError
from kinestat.hardware.leg_calibration import LegCalibration, fit_polynomial
from kinestat.io._fields import number, refuse_unknown, string
from kinestat.io.textfile import parse_toml, read_text_file

__all__ = ["CalibrationFile", "loads_calibration", "read_calibration"]

_TOP_KEYS = {"name", "description", "source", "length_unit", "force_unit", "force_sense",
             "legs"}
_LEG_KEYS = {"sensor", "leg", "length", "force", "length_counts", "lengths", "length_degree",
             "force_counts", "forces", "force_degree", "index_count"}


class CalibrationFile:
    """A parsed calibration file: ``name``, ``description``, ``source`` and the
    :class:`LegCalibration` (``calibration``), tensions positive."""

    def __init__(self, name: str, calibration: LegCalibration, description: str = "",
                 source: str = "") -> None:
        self.name = name
        self.calibration = calibration
        self.description = description
        self.source = source


def loads_calibration(text: str, source: str = "<string>") -> CalibrationFile:
    """Parse a TOML leg calibration (``source`` names it in error messages)."""
    doc = parse_toml(text, source)
    refuse_unknown(doc, _TOP_KEYS, source, "top-level keys")
    for key, unit in (("length_unit", "mm"), ("force_unit", "N")):
        if key not in doc:
            raise ParseError(f"missing required {key!r}: units must be explicit", file=source,
                             field=key)
        if string(doc[key], source, key) != unit:
            raise ParseError(f"{key} must be {unit!r} (the controller works in mm and N), got "
                             f"{doc[key]!r}", file=source, field=key)
    sense = string(doc.get("force_sense", "tension"), source, "force_sense")
    if sense not in ("tension", "compression"):
        raise ParseError(f"force_sense must be 'tension' or 'compression', got {sense!r}",
                         file=source, field="force_sense")
    legs = doc.get("legs")
    if not isinstance(legs, list) or len(legs) != 6:
        raise ParseError("a calibration needs six [[legs]] tables (sensor legs 1..6)",
                         file=source, field="legs")
    names, lengths, forces, index = [], [], [], []
    for i, leg in enumerate(legs):
        where = f"legs[{i}]"
        if not isinstance(leg, dict):
            raise ParseError("expected a table", file=source, field=where)
        refuse_unknown(leg, _LEG_KEYS, source, "keys", field=where)
        if "sensor" in leg and number(leg["sensor"], source, f"{where}.sensor") != i + 1:
            raise ParseError(f"sensor {leg['sensor']} is table {i + 1}: list the legs in "
                             "sensor order 1..6", file=source, field=f"{where}.sensor")
        names.append(string(leg.get("leg", ""), source, f"{where}.leg"))
        lengths.append(_map(leg, "length", source, where))
        f = _map(leg, "force", source, where)
        forces.append(-f if sense == "compression" else f)
        index.append(number(leg.get("index_count", 0), source, f"{where}.index_count"))
    try:
        cal = LegCalibration(length_coeffs=_pad(lengths), force_coeffs=_pad(forces),
                             leg_names=tuple(names), index_counts=index)
    except InputError as exc:
        raise ParseError(str(exc), file=source) from exc
    return CalibrationFile(name=string(doc.get("name", Path(source).stem), source, "name"),
                           calibration=cal,
                           description=string(doc.get("description", ""), source, "description"),
                           source=string(doc.get("source", ""), source, "source"))


def _map(leg: dict, kind: str, source: str, where: str) -> np.ndarray:
    """One leg's ``kind`` map ("length" or "force"): coefficients, or data fitted."""
    counts_key, values_key = f"{kind}_counts", f"{kind}s"
    has_coeffs = kind in leg
    has_data = counts_key in leg or values_key in leg
    if has_coeffs == has_data:
        raise ParseError(f"give either {kind} = [coefficients] or {counts_key} and "
                         f"{values_key} (data to fit)", file=source, field=f"{where}.{kind}")
    if has_coeffs:
        c = leg[kind]
        if not isinstance(c, list) or not c:
            raise ParseError("expected a list of ascending polynomial coefficients", file=source,
                             field=f"{where}.{kind}")
        return np.array([number(x, source, f"{where}.{kind}[{k}]") for k, x in enumerate(c)])
    x, y = leg.get(counts_key), leg.get(values_key)
    for key, v in ((counts_key, x), (values_key, y)):
        if not isinstance(v, list):
            raise ParseError("expected a list of numbers", file=source, field=f"{where}.{key}")
    xs = [number(v, source, f"{where}.{counts_key}[{k}]") for k, v in enumerate(x)]
    ys = [number(v, source, f"{where}.{values_key}[{k}]") for k, v in enumerate(y)]
    deg = number(leg.get(f"{kind}_degree", 1), source, f"{where}.{kind}_degree")
    if deg != int(deg) or deg < 1:
        raise ParseError(f"{kind}_degree must be a whole number >= 1", file=source,
                         field=f"{where}.{kind}_degree")
    try:
        return np.asarray(fit_polynomial(xs, ys, int(deg)).coefficients)
    except InputError as exc:
        raise ParseError(str(exc), file=source, field=f"{where}.{values_key}") from exc


def _pad(rows: list[np.ndarray]) -> np.ndarray:
    n = max(r.size for r in rows)
    return np.stack([np.concatenate([r, np.zeros(n - r.size)]) for r in rows])


def read_calibration(path: str | os.PathLike) -> CalibrationFile:
    """Read a TOML leg-calibration file."""
    return loads_calibration(read_text_file(path, "calibration file"), source=str(Path(path)))
