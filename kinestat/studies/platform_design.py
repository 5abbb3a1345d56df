"""Design study of the special 6-6 platform, scored on Vibhute 2011 Table 3-1.

Designs are the tensor product of the values given for each parameter of
:func:`kinestat.parallel.special_6_6` — base and top triangle sides, base and top edge offsets,
home height, home twist and spring constant — (``grid`` mode; a range ``lo:hi`` takes ``--grid``
values) or random designs drawn uniformly between each parameter's smallest and largest value
(``samples`` mode). Parameters not swept keep the base platform's values (default the 2011
prototype), so the prototype is in the grid whenever each list includes its value.

Each design is scored on the same ``poses`` random displacements over Table 3-1's motion range:

* ``fraction_within`` — the fraction of them within the connector deflection and load limits
  (the score; ties go to the lower design index);
* ``meets_spec`` — each motion of Table 3-1 alone, to ± its full range, stays within the limits
  (:func:`platform_common.axis_check`) and the range holds no singular pose;
* ``min_singularity`` — the worst (smallest) singularity measure over the poses and home;
* ``lee`` — Lee's criterion (Vibhute §3.1.2): ``|det j|`` of the leg lines at home divided by
  the top side cubed (det j is a length³; so scaled it depends on the shape alone).

``score`` chooses what ``best`` maximises: ``"table-3-1"`` (``fraction_within``, the default)
or ``"lee"``. Lee's optimum for the octahedral 3-3 (edge offsets 0) is a base side twice the
top side, the home height equal to the top side and the top turned 60° (docs/sweeps.md).

Impossible or architecturally singular designs are counted as ``invalid`` with the reason.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from kinestat.errors import InputError, KinestatError
from kinestat.parallel import singularity_measure, special_6_6
from kinestat.parallel.statics import jacobian_det
from kinestat.studies import grids
from kinestat.studies import platform_common as pc
from kinestat.studies import reduce as red
from kinestat.studies.base import ChunkedStudy

__all__ = ["PlatformDesignStudy", "platform_design_spec", "PARAMETERS", "SCORES", "lee_score"]

#: swept parameters (CLI option names), each a single number (equal sides/offsets)
PARAMETERS = ("base_side", "top_side", "base_offset", "top_offset", "height", "twist_deg",
              "stiffness")
#: the parameters no design can have zero or below (offsets and the twist can)
POSITIVE = ("base_side", "top_side", "height", "stiffness")
DEFAULT_CHUNK = 16
_BINS = 20
#: ``--score`` names and the summary key each ranks designs by
SCORES = {"table-3-1": "fraction_within", "lee": "lee"}


def lee_score(platform) -> float:
    """Lee's criterion: ``|det j|`` of the leg lines at the home pose over the top side cubed
    (dimensionless; ``platform.design`` gives the top side)."""
    a = float(np.mean(platform.design.top_side))
    return float(abs(jacobian_det(platform, platform.home_pose))) / a ** 3


def _defaults(platform) -> dict[str, float]:
    d = platform.design
    if d is None:
        raise InputError(f"platform {platform.name!r} has no special 6-6 design parameters; "
                         "a design study needs a design-form platform file")

    def one(v, what):
        if max(v) - min(v) > 1e-12 * max(1.0, abs(max(v))):
            raise InputError(f"platform {platform.name!r}: the design study sweeps one value "
                             f"per parameter, but its {what} are {list(v)}")
        return float(v[0])

    return {"base_side": one(d.base_side, "base sides"), "top_side": one(d.top_side, "top sides"),
            "base_offset": one(d.base_offset, "base offsets"),
            "top_offset": one(d.top_offset, "top offsets"), "height": d.height,
            "twist_deg": round(math.degrees(d.twist), 12),
            "stiffness": one(d.stiffness, "spring constants")}


def platform_design_spec(platform: str | None = None, *, values: dict[str, str] | None = None,
                         grid: int | None = None, samples: int | None = None, seed: int = 0,
                         poses: int = 256, range_mm=pc.TABLE_3_1["range_mm"],
                         range_deg=pc.TABLE_3_1["range_deg"],
                         max_deflection: float = pc.TABLE_3_1["max_deflection"],
                         max_load: float = pc.TABLE_3_1["max_load"],
                         chunk_size: int = DEFAULT_CHUNK, arrays: bool = True,
                         score: str = "table-3-1") -> dict:
    """Check the inputs and build the spec of a design study.

    ``values`` maps parameter names (:data:`PARAMETERS`) to text: ``v``, ``v1,v2``, ``lo:hi``
    (``grid`` values) or ``lo:hi:n``. ``samples`` draws random designs instead of the grid.
    ``score``: what ``best`` maximises (:data:`SCORES`).
    """
    if score not in SCORES:
        raise InputError(f"--score must be one of {', '.join(SCORES)}, got {score!r}")
    label, text = pc.platform_text(platform)
    base = _defaults(pc.load_platform(label, text))
    values = dict(values or {})
    unknown = set(values) - set(PARAMETERS)
    if unknown:
        raise InputError(f"unknown design parameters {sorted(unknown)}; known: {PARAMETERS}")
    if grid is not None:
        if samples is not None:
            raise InputError("give --grid N (values per lo:hi range) or --samples N, not both")
        grids.check_grid_count(grid)
        if not any(":" in values[k] and values[k].count(":") == 1 for k in values):
            raise InputError(f"--grid {grid}: no parameter is given as a range lo:hi to take "
                             "the grid's values from (e.g. --base-side 100:140)")
    inputs = {"seed": grids.check_seed(seed)}
    inputs.update({"mode": "grid"} if samples is None else
                  {"mode": "samples", "samples": grids.check_samples(samples)})
    lists = {k: (grids.parse_values(values[k], k.replace("_", "-"), grid if samples is None
                                    else 2) if k in values else [base[k]])
             for k in PARAMETERS}
    for k in POSITIVE:
        bad = [v for v in lists[k] if not v > 0]
        if bad:
            raise InputError(f"--{k.replace('_', '-')} must be > 0 (no platform has a side, "
                             f"height or spring of zero or less), got {bad[0]:g}")
    if poses < 1:
        raise InputError(f"--poses must be at least 1, got {poses}")
    spec = pc.platform_spec("platform-design", (label, text),
                            range_mm=range_mm, range_deg=range_deg, chunk_size=chunk_size,
                            arrays=arrays, values=lists, reference=base,
                            poses=int(poses), max_deflection=float(max_deflection),
                            max_load=float(max_load), score=score, **inputs)
    PlatformDesignStudy(spec)
    return spec


class PlatformDesignStudy(ChunkedStudy):
    """Special 6-6 designs scored on Table 3-1."""

    name = "platform-design"

    def row_bytes(self) -> int:
        """Per design: its ``poses`` evaluations (measured peak ~1.8 KiB each, 256 poses)."""
        return (4 << 10) * int(self.spec["poses"])

    def __init__(self, spec: dict) -> None:
        super().__init__(spec)
        self.box = pc.range_box(spec["range_mm"], spec["range_deg"])
        self.lists = {k: np.asarray(spec["values"][k], float) for k in PARAMETERS}
        sizes = [len(v) for v in self.lists.values()]
        self._set_items(math.prod(sizes) if spec["mode"] == "grid" else spec["samples"],
                        "designs")
        base = pc.load_platform(spec["platform"], spec["platform_text"])
        self.names = (base.name, base.length_unit, base.force_unit)
        rng = grids.chunk_rng(spec["seed"], 0, grids.STREAM_POSES)
        self.displacements = rng.uniform(-self.box, self.box, size=(spec["poses"], 6))
        self.key = SCORES[spec.get("score", "table-3-1")]

    def designs(self, i: int) -> np.ndarray:
        """Design parameters ``(rows, 7)`` (order :data:`PARAMETERS`) of chunk ``i``."""
        vals = list(self.lists.values())
        if self.spec["mode"] == "samples":
            return self.uniform_inputs(i, [v.min() for v in vals], [v.max() for v in vals])
        start, stop = self.chunk_rows(i)
        idx = np.arange(start, stop, dtype=np.int64)
        out = np.empty((idx.size, len(vals)))
        for j in range(len(vals) - 1, -1, -1):
            out[:, j] = vals[j][idx % len(vals[j])]
            idx //= len(vals[j])
        return out

    def score(self, params) -> dict:
        """Build one design and score it (see the module docstring)."""

        b, a, bo, to, h, tw, k = (float(x) for x in params)
        name, lu, fu = self.names
        try:
            plat = special_6_6(base_side=b, top_side=a, base_offset=bo, top_offset=to,
                               height=h, twist=math.radians(tw), stiffness=k, name=name,
                               length_unit=lu, force_unit=fu)
        except KinestatError as exc:
            return {"valid": False, "reason": type(exc).__name__}
        lim = (self.spec["max_deflection"], self.spec["max_load"])
        r = pc.evaluate_poses(plat, pc.displaced_poses(plat, self.displacements), *lim)
        ax = pc.axis_check(plat, self.box, *lim)

        sing = min(float(r["singularity"].min()), ax["min_singularity"],
                   float(singularity_measure(plat, plat.home_pose)))
        return {"valid": True, "fraction_within": float(r["ok"].mean()),
                "meets_spec": bool(ax["meets"] and sing > pc.SINGULAR_TOL),
                "min_singularity": sing, "lee": lee_score(plat),
                "max_deflection": float(r["max_deflection"].max()),
                "max_force_z": float(r["force_z"].max()),
                "axis_max_deflection": ax["max_deflection"], "axis_max_force_z": ax["max_force_z"]}

    def _is_reference(self, params) -> bool:
        ref = np.array([self.spec["reference"][k] for k in PARAMETERS])
        return bool(np.all(np.abs(np.asarray(params) - ref) <= 1e-9 * np.maximum(1, abs(ref))))

    def compute_chunk(self, i: int):
        P = self.designs(i)
        start = i * self.chunk
        scores = [self.score(p) for p in P]
        valid = np.array([s["valid"] for s in scores])
        nan = float("nan")

        def col(key):
            return np.array([s.get(key, nan) for s in scores], dtype=float)

        frac, sing, lee = col("fraction_within"), col("min_singularity"), col("lee")
        meets = np.array([s.get("meets_spec", False) for s in scores])
        best = None
        for j, s in enumerate(scores):
            if s["valid"] and (best is None or s[self.key] > best[self.key]):
                best = {"index": start + j, "params": dict(zip(PARAMETERS, P[j].tolist(),
                                                               strict=True)), **s}
        ref = None
        for j, p in enumerate(P):
            if self._is_reference(p):
                ref = {"index": start + j, "params": dict(zip(PARAMETERS, p.tolist(),
                                                              strict=True)), **scores[j]}
                break
        reasons: dict[str, int] = {}
        for s in scores:
            if not s["valid"]:
                reasons[s["reason"]] = reasons.get(s["reason"], 0) + 1
        partial = {"designs": len(scores), "valid": int(valid.sum()),
                   "meets_spec": int(meets.sum()), "invalid_reasons": reasons,
                   "fraction_within": red.stats(frac), "min_singularity": red.stats(sing),
                   "lee": red.stats(lee),
                   "hist_fraction": red.histogram(frac, np.linspace(0, 1, _BINS + 1)),
                   "best": best, "reference": ref}
        rows = {}
        if self.spec["arrays"]:
            rows = {k: P[:, j] for j, k in enumerate(PARAMETERS)}
            rows.update(index=np.arange(start, start + len(P)), valid=valid, meets_spec=meets,
                        fraction_within=frac, min_singularity=sing, lee=lee,
                        max_deflection=col("max_deflection"), max_force_z=col("max_force_z"))
        return rows, partial

    def reduce(self, partials: list[dict]) -> dict:
        best = None
        for p in partials:  # chunk order: the first of equal scores wins
            b = p["best"]
            if b is not None and (best is None or b[self.key] > best[self.key]):
                best = b
        ref = next((p["reference"] for p in partials if p["reference"] is not None), None)
        reasons: dict[str, int] = {}
        for p in partials:
            for k, v in p["invalid_reasons"].items():
                reasons[k] = reasons.get(k, 0) + v
        frac = red.finish_stats(red.merge_stats([p["fraction_within"] for p in partials]))
        sing = red.finish_stats(red.merge_stats([p["min_singularity"] for p in partials]))
        lee = red.finish_stats(red.merge_stats([p["lee"] for p in partials]))
        return {"platform": self.names[0], "mode": self.spec["mode"],
                "score": self.spec.get("score", "table-3-1"),
                "designs": sum(p["designs"] for p in partials),
                "valid": sum(p["valid"] for p in partials),
                "meets_spec": sum(p["meets_spec"] for p in partials),
                "invalid_reasons": dict(sorted(reasons.items())),
                "poses_per_design": self.spec["poses"],
                "fraction_within": {k: frac[k] for k in ("min", "mean", "max")},
                "min_singularity": {k: sing[k] for k in ("min", "mean", "max")},
                "lee": {k: lee[k] for k in ("min", "mean", "max")},
                "best": best, "reference": ref,
                "histograms": {"fraction_within": red.merge_histograms(
                    [p["hist_fraction"] for p in partials])}}

    def plot(self, summary: dict, directory: Path) -> list[str]:
        from kinestat.studies import plots  # lazy: matplotlib only when plotting

        return [plots.histogram_png(summary["histograms"]["fraction_within"],
                                    directory / "fraction_within.png",
                                    "fraction of the motion range within spec",
                                    f"{summary['designs']} designs ({summary['valid']} valid)")]
