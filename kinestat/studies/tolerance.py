"""Tolerance study: mounting and calibration errors → error of the wrench the platform measures.

The platform is a force/torque sensor (Vibhute 2011 ch. 4): encoders give the leg lengths, the
nominal model turns them into a pose (tracking forward kinematics from home) and a wrench
``w = j k (l − l0)`` (:func:`kinestat.parallel.wrench_from_leg_lengths`). Each Monte-Carlo sample
draws a *true* platform — the nominal one with every base and top attachment point moved by
``N(0, sigma_mount²)`` per coordinate (mounting), every spring constant scaled by
``1 + N(0, sigma_k²)`` (spring calibration) — and encoder zero errors ``N(0, sigma_offset²)``
per leg (length calibration), and a pose uniform in the motion range (Table 3-1). The true
wrench is the true platform's spring wrench at that pose; the measured one is the nominal
model's wrench from the true leg lengths plus the zero errors. Reported: |Δf| (force error)
and |Δm_c| (torque error about the top's centre at home, c), with their RMS, mean and maximum.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from kinestat.errors import InputError, KinestatError
from kinestat.parallel import Platform, leg_lengths, spring_wrench, wrench_from_leg_lengths
from kinestat.parallel.legs import top_points_in_base
from kinestat.studies import grids
from kinestat.studies import platform_common as pc
from kinestat.studies import reduce as red
from kinestat.studies.base import ChunkedStudy

__all__ = ["ToleranceStudy", "tolerance_spec"]

DEFAULT_CHUNK = 1024
_BINS = 50
_COMPONENTS = ("fx", "fy", "fz", "mx", "my", "mz")


def tolerance_spec(platform: str | None = None, *, samples: int = 10000, seed: int = 0,
                   sigma_mount: float = 0.05, sigma_k: float = 0.05,
                   sigma_offset: float = 0.01, range_mm=pc.TABLE_3_1["range_mm"],
                   range_deg=pc.TABLE_3_1["range_deg"], chunk_size: int = DEFAULT_CHUNK,
                   arrays: bool = True) -> dict:
    """Check the inputs and build the spec of a tolerance study.

    Defaults: 0.05 mm mounting error, 5 % spring constant error (the springs' linearity,
    Vibhute §3.1.3), 0.01 mm encoder zero error (the position resolution of Table 3-1).
    """
    samples, seed = grids.check_samples(samples), grids.check_seed(seed)
    for name, v in (("sigma-mount", sigma_mount), ("sigma-k", sigma_k),
                    ("sigma-offset", sigma_offset)):
        if not (np.isfinite(v) and v >= 0):
            raise InputError(f"--{name} must be a non-negative number, got {v}")
    spec = pc.platform_spec("tolerance", pc.platform_text(platform),
                            range_mm=range_mm, range_deg=range_deg, chunk_size=chunk_size,
                            arrays=arrays, mode="samples",
                            samples=samples, seed=seed, sigma_mount=float(sigma_mount),
                            sigma_k=float(sigma_k), sigma_offset=float(sigma_offset))
    ToleranceStudy(spec)
    return spec


class ToleranceStudy(ChunkedStudy):
    """Monte-Carlo of the wrench error due to mounting and calibration errors."""

    name = "tolerance"

    def __init__(self, spec: dict) -> None:
        super().__init__(spec)
        self.platform = pc.load_platform(spec["platform"], spec["platform_text"])
        self.box = pc.range_box(spec["range_mm"], spec["range_deg"])
        self._set_items(spec["samples"], "samples")
        p = self.platform
        self.centre = top_points_in_base(p, p.home_pose).mean(axis=0)
        self.force_edges = np.linspace(0.0, 10.0 * max(spec["sigma_k"], 1e-3) * 50.0 + 1.0,
                                       _BINS + 1)
        self.torque_edges = self.force_edges * p.scale

    def draws(self, i: int) -> dict[str, np.ndarray]:
        """The random inputs of chunk ``i`` (one stream per chunk, drawn in a fixed order)."""
        start, stop = self.chunk_rows(i)
        m, s = stop - start, self.spec
        rng = grids.chunk_rng(s["seed"], i)
        return {"d": rng.uniform(-self.box, self.box, size=(m, 6)),
                "db": rng.normal(0.0, s["sigma_mount"], size=(m, 6, 3)),
                "dt": rng.normal(0.0, s["sigma_mount"], size=(m, 6, 3)),
                "dk": rng.normal(0.0, s["sigma_k"], size=(m, 6)),
                "dl": rng.normal(0.0, s["sigma_offset"], size=(m, 6))}

    def errors(self, r: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """Wrench errors ``(m, 6)`` [Δf; Δm_c] and a failure mask ``(m,)`` for draws ``r``."""

        p = self.platform
        T = pc.displaced_poses(p, r["d"])
        m = T.shape[0]
        w_true = np.empty((m, 6))
        L = np.empty((m, 6))
        for j in range(m):
            true = Platform(base_points=p.base_points + r["db"][j],
                            top_points=p.top_points + r["dt"][j],
                            stiffness=p.stiffness * (1.0 + r["dk"][j]),
                            free_lengths=p.free_lengths, home_pose=p.home_pose)
            w_true[j] = spring_wrench(true, T[j])
            L[j] = leg_lengths(true, T[j])
        L += r["dl"]
        failed = np.zeros(m, dtype=bool)
        w_meas = np.full((m, 6), np.nan)
        try:
            _, w_meas = wrench_from_leg_lengths(p, L, p.home_pose)
        except KinestatError:  # one sample failed: redo one by one and flag it
            for j in range(m):
                try:
                    w_meas[j] = wrench_from_leg_lengths(p, L[j], p.home_pose)[1]
                except KinestatError:
                    failed[j] = True
        dw = w_meas - w_true
        dw[:, 3:] -= np.cross(self.centre, dw[:, :3])  # moment about the top's centre
        return dw, failed

    def compute_chunk(self, i: int):
        r = self.draws(i)
        dw, failed = self.errors(r)
        fe = np.linalg.norm(dw[:, :3], axis=-1)
        te = np.linalg.norm(dw[:, 3:], axis=-1)
        partial = {"samples": int(dw.shape[0]), "failed": int(failed.sum()),
                   "force_error": red.stats(fe), "torque_error": red.stats(te),
                   "components": [red.stats(dw[:, k]) for k in range(6)],
                   "hist_force": red.histogram(fe, self.force_edges),
                   "hist_torque": red.histogram(te, self.torque_edges)}
        rows = {}
        if self.spec["arrays"]:
            dd = pc.as_deg(r["d"])
            rows = {n: dd[:, j] for j, n in enumerate(("x", "y", "z", "rx_deg", "ry_deg",
                                                        "rz_deg"))}
            rows.update({f"d{c}": dw[:, k] for k, c in enumerate(_COMPONENTS)})
            rows.update(force_error=fe, torque_error=te, failed=failed)
        return rows, partial

    def reduce(self, partials: list[dict]) -> dict:
        p = self.platform
        out = {"platform": p.name, "length_unit": p.length_unit, "force_unit": p.force_unit,
               "samples": sum(q["samples"] for q in partials),
               "failed": sum(q["failed"] for q in partials),
               "sigma": {k: self.spec[k] for k in ("sigma_mount", "sigma_k", "sigma_offset")},
               "torque_about": self.centre.tolist()}
        for k in ("force_error", "torque_error"):
            s = red.finish_stats(red.merge_stats([q[k] for q in partials]))
            out[k] = {m: s[m] for m in ("mean", "rms", "max")}
        out["component_rms"] = {
            c: red.finish_stats(red.merge_stats([q["components"][k] for q in partials]))["rms"]
            for k, c in enumerate(_COMPONENTS)}
        out["histograms"] = {"force_error": red.merge_histograms([q["hist_force"]
                                                                  for q in partials]),
                             "torque_error": red.merge_histograms([q["hist_torque"]
                                                                   for q in partials])}
        return out

    def plot(self, summary: dict, directory: Path) -> list[str]:
        from kinestat.studies import plots  # lazy: matplotlib only when plotting

        u, f = summary["length_unit"], summary["force_unit"]
        h = summary["histograms"]
        return [plots.histogram_png(h["force_error"], directory / "force_error.png",
                                    f"|force error| ({f})", "measured vs true wrench"),
                plots.histogram_png(h["torque_error"], directory / "torque_error.png",
                                    f"|torque error| ({f} {u})", "measured vs true wrench")]
