"""The compliant platform over its working range (Vibhute 2011 Table 3-1).

Poses displaced from home over the motion range box (a full tensor grid of ``--grid N`` values
per axis, both ends included, or ``--samples N`` uniform in the box): leg deflections and
forces, the load |F_z|, the spatial stiffness K (its normalised eigenvalues and their ratio) and
the singularity measure; counts of poses within the connector deflection and load limits. The
summary also carries K at home (ray order, model units) — what ``kinestat platform stiffness``
prints — and the axis-by-axis check of Table 3-1 (:func:`platform_common.axis_check`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from kinestat.errors import InputError
from kinestat.parallel import stiffness
from kinestat.studies import grids
from kinestat.studies import platform_common as pc
from kinestat.studies import reduce as red
from kinestat.studies.base import ChunkedStudy

__all__ = ["PlatformRangeStudy", "platform_range_spec"]

DEFAULT_CHUNK = 1 << 13
_BINS = 50
_MEASURES = ("max_deflection", "max_leg_force", "force_z", "singularity", "k_eig_min",
             "k_eig_max", "k_cond")


def platform_range_spec(platform: str | None = None, *, grid: int | None = None,
                        samples: int | None = None, seed: int = 0,
                        range_mm=pc.TABLE_3_1["range_mm"],
                        range_deg=pc.TABLE_3_1["range_deg"],
                        max_deflection: float = pc.TABLE_3_1["max_deflection"],
                        max_load: float = pc.TABLE_3_1["max_load"],
                        chunk_size: int = DEFAULT_CHUNK, arrays: bool = True) -> dict:
    """Check the inputs and build the spec of a platform-range study."""
    spec = pc.platform_spec("platform-range", pc.platform_text(platform),
                            range_mm=range_mm, range_deg=range_deg, chunk_size=chunk_size,
                            arrays=arrays,
                            max_deflection=float(max_deflection), max_load=float(max_load),
                            **grids.sampling(grid, samples, seed, 6))
    PlatformRangeStudy(spec)
    return spec


class PlatformRangeStudy(ChunkedStudy):
    """Deflection, load, stiffness and singularity of the platform over its motion range."""

    name = "platform-range"

    def __init__(self, spec: dict) -> None:
        super().__init__(spec)
        self.platform = pc.load_platform(spec["platform"], spec["platform_text"])
        self.box = pc.range_box(spec["range_mm"], spec["range_deg"])
        for key in ("max_deflection", "max_load"):
            if not spec[key] > 0:
                raise InputError(f"--{key.replace('_', '-')} must be positive, got {spec[key]}")
        self._set_items(spec["grid"] ** 6 if spec["mode"] == "grid" else spec["samples"], "poses")
        lim_d, lim_f = spec["max_deflection"], spec["max_load"]
        self.edges = {"max_deflection": np.linspace(0.0, 2 * lim_d, _BINS + 1),
                      "force_z": np.linspace(0.0, 2 * lim_f, _BINS + 1),
                      "singularity": np.linspace(0.0, 1.0, _BINS + 1)}

    def displacements(self, i: int) -> np.ndarray:
        """Displacements ``(rows, 6)`` (x, y, z, rx, ry, rz; radians) of chunk ``i``."""
        return self.box_inputs(i, -self.box, self.box)

    def compute_chunk(self, i: int):
        d = self.displacements(i)
        p = self.platform
        r = pc.evaluate_poses(p, pc.displaced_poses(p, d), self.spec["max_deflection"],
                              self.spec["max_load"])
        partial = {"poses": int(d.shape[0]),
                   "within_deflection": int(r["within_deflection"].sum()),
                   "within_load": int(r["within_load"].sum()),
                   "within_both": int(r["ok"].sum())}
        partial.update({k: red.stats(r[k]) for k in _MEASURES})
        partial.update({f"hist_{k}": red.histogram(r[k], e) for k, e in self.edges.items()})
        rows = {}
        if self.spec["arrays"]:
            dd = pc.as_deg(d)
            rows = {n: dd[:, j] for j, n in enumerate(("x", "y", "z", "rx_deg", "ry_deg",
                                                        "rz_deg"))}
            rows.update({k: r[k] for k in (*_MEASURES, "ok")})
        return rows, partial

    def home(self) -> dict:
        """K at home (ray order, model units) and its normalised eigenvalues."""

        p = self.platform
        r = pc.evaluate_poses(p, p.home_pose, self.spec["max_deflection"], self.spec["max_load"])
        return {"stiffness_home": stiffness(p, p.home_pose).tolist(),
                "k_eig_home": [float(r["k_eig_min"]), float(r["k_eig_max"])],
                "singularity_home": float(r["singularity"])}

    def reduce(self, partials: list[dict]) -> dict:
        n = sum(p["poses"] for p in partials)
        counts = {k: sum(p[k] for p in partials)
                  for k in ("within_deflection", "within_load", "within_both")}
        p = self.platform
        out = {"platform": p.name, "length_unit": p.length_unit, "force_unit": p.force_unit,
               "mode": self.spec["mode"], "poses": n, **counts,
               "fraction_within": counts["within_both"] / n,
               "limits": {"max_deflection": self.spec["max_deflection"],
                          "max_load": self.spec["max_load"],
                          "range_mm": self.spec["range_mm"],
                          "range_deg": self.spec["range_deg"]}}
        for k in _MEASURES:
            s = red.finish_stats(red.merge_stats([q[k] for q in partials]))
            out[k] = {m: s[m] for m in ("min", "mean", "max")}
        out.update(self.home())
        out["axis_check"] = pc.axis_check(p, self.box, self.spec["max_deflection"],
                                          self.spec["max_load"])
        out["histograms"] = {k: red.merge_histograms([q[f"hist_{k}"] for q in partials])
                             for k in self.edges}
        return out

    def plot(self, summary: dict, directory: Path) -> list[str]:
        from kinestat.studies import plots  # lazy: matplotlib only when plotting

        u, f = summary["length_unit"], summary["force_unit"]
        h = summary["histograms"]
        return [
            plots.histogram_png(h["max_deflection"], directory / "deflection.png",
                                f"largest leg deflection ({u})", "platform over its range"),
            plots.histogram_png(h["force_z"], directory / "force_z.png",
                                f"|F_z| ({f})", "platform over its range"),
            plots.histogram_png(h["singularity"], directory / "singularity.png",
                                "singularity measure |det j|", "platform over its range"),
        ]
