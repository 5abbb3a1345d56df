"""Workspace and dexterity of a serial arm over a joint grid or joint samples.

For each configuration ``q`` (within the model's joint limits): the end point ``p`` (end pose
translation, base frame), the reach ``|p|`` (distance from the base origin), Yoshikawa's
manipulability ``w = sqrt(det(J_t J_tᵀ))`` (Yoshikawa 1985) and the condition number
``σ_max / σ_min`` of ``J_t``, the task Jacobian:

* ``full`` — all six rows ``[ω; v_p]`` with ``v_p`` the velocity of the end point
  (``v_p = v_O − p × ω``; for a 6-joint arm ``w = |det J|``, independent of the reference point);
* ``position`` — the three rows ``v_p``;
* ``planar`` — ``v_p``'s x and y rows (arms moving in the base xy plane).

``auto`` takes ``full`` for six or more joints, ``position`` for three to five, ``planar`` for
one or two. ``w`` is computed as the product of the singular values of ``J_t`` (the same number,
better conditioned). A configuration with ``σ_min ≤ 1e-12 σ_max`` counts as singular and is left
out of the condition-number statistics.

Revolute joints without limits range over [−π, π]; prismatic joints need limits.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

import kinestat
from kinestat.errors import InputError, KinestatWarning
from kinestat.io.model_toml import loads_model
from kinestat.studies import grids
from kinestat.studies import reduce as red
from kinestat.studies.base import ChunkedStudy

__all__ = ["WorkspaceStudy", "workspace_spec", "TASKS", "task_jacobian"]

TASKS = ("auto", "full", "position", "planar")
_TASK_ROWS = {"full": 6, "position": 3, "planar": 2}
SINGULAR_RATIO = 1e-12
DEFAULT_CHUNK = 1 << 16
_BINS = 64


def _load_model(spec: dict):
    if spec.get("model_text") is None:

        return kinestat.load(spec["model"])

    if "urdf" in spec:  # the loader's warnings were given when the spec was built
        from kinestat.io.urdf import from_urdf  # lazy: XML and scipy only for URDF models

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", KinestatWarning)
            return from_urdf(spec["model_text"], source=spec["model"], **spec["urdf"])
    return loads_model(spec["model_text"], source=spec["model"])


def workspace_spec(model: str, *, grid: int | None = None, samples: int | None = None,
                   seed: int = 0, chunk_size: int = DEFAULT_CHUNK, task: str = "auto",
                   arrays: bool = True, tip: str | None = None, base: str | None = None,
                   scale: float | None = None, length_unit: str | None = None) -> dict:
    """Check the inputs and build the spec of a workspace study.

    ``model`` is an embedded model name, a TOML file or a URDF file (its text goes into the
    spec; a URDF's chain is chosen by ``tip``/``base`` and its lengths by ``scale``/
    ``length_unit``, as :func:`kinestat.load`). Exactly one of ``grid`` (values per joint, both
    limits included) and ``samples`` (uniform within the limits, seeded) is given.
    """
    urdf = {k: v for k, v in (("tip", tip), ("base", base), ("scale", scale),
                              ("length_unit", length_unit)) if v is not None}
    # unknown names and bad files fail here, before any output
    m = kinestat.load(model, **urdf)
    text = None
    if model not in kinestat.list_models():
        text = Path(model).read_text(encoding="utf-8")
    inputs = grids.sampling(grid, samples, seed, m.n)
    if task not in TASKS:
        raise InputError(f"--task must be one of {list(TASKS)}, got {task!r}")
    spec = {"study": "workspace", "model": str(model), "model_text": text,
            "chunk_size": int(chunk_size), "task": task, "arrays": bool(arrays), **inputs}
    if Path(str(model)).suffix.lower() == ".urdf":
        spec["urdf"] = urdf  # only for URDF models: the specs of other runs stay as they were
    WorkspaceStudy(spec)  # limits, task/joint count and chunk size are checked here
    return spec


def task_jacobian(J: np.ndarray, p: np.ndarray, task: str) -> np.ndarray:
    """Task rows ``(..., m, n)`` of the space Jacobian ``J = [J_ω; J_v]`` at end points ``p``.

    ``J_v,p = J_v − [p]× J_ω`` (velocity of the end point instead of the origin point).
    """
    Jw, Jv = J[..., :3, :], J[..., 3:, :]
    px, py, pz = (p[..., k, None] for k in range(3))
    vp = np.stack([Jv[..., 0, :] - (py * Jw[..., 2, :] - pz * Jw[..., 1, :]),
                   Jv[..., 1, :] - (pz * Jw[..., 0, :] - px * Jw[..., 2, :]),
                   Jv[..., 2, :] - (px * Jw[..., 1, :] - py * Jw[..., 0, :])], axis=-2)
    if task == "full":
        return np.concatenate([Jw, vp], axis=-2)
    return vp if task == "position" else vp[..., :2, :]


class WorkspaceStudy(ChunkedStudy):
    """Reach, manipulability and condition number of an arm over joint grids or samples."""

    name = "workspace"
    ROW_BYTES = 2 << 10  # measured peak ~0.9 KiB per configuration (6 joints)

    def __init__(self, spec: dict) -> None:
        super().__init__(spec)
        self.model = m = _load_model(spec)
        lo, hi = np.array(m.lower, float), np.array(m.upper, float)
        for j, joint in enumerate(m.joints):
            if not (np.isfinite(lo[j]) and np.isfinite(hi[j])):
                if joint.kind == "prismatic":
                    raise InputError(f"model {m.name!r}: prismatic joint {j + 1} has no limits; "
                                     "a workspace study needs them")
                lo[j], hi[j] = -math.pi, math.pi
        self.lower, self.upper = lo, hi
        task = spec["task"]
        if task == "auto":
            task = "full" if m.n >= 6 else ("position" if m.n >= 3 else "planar")
        if _TASK_ROWS[task] > m.n:
            raise InputError(f"--task {task}: {_TASK_ROWS[task]} task rows need at least as "
                             f"many joints, model {m.name!r} has {m.n}; choose a smaller task "
                             "(position, planar)")
        self.task = task
        self._set_items(spec["grid"] ** m.n if spec["mode"] == "grid" else spec["samples"],
                        "configurations")
        self.bound = self.reach_bound()
        b = self.bound
        self.reach_edges = np.linspace(0.0, b, _BINS + 1)
        self.xy_edges = np.linspace(-b, b, _BINS + 1)
        self.manip_edges = red.log_edges(-8, 16)
        self.cond_edges = red.log_edges(0, 16)

    def reach_bound(self) -> float:
        """An upper bound on the reach: the sum of the constant offsets |t(C_i)| plus the
        largest prismatic (and screw) travel — the sum of the link lengths."""
        m = self.model
        b = float(np.sum(np.linalg.norm(m.constants[:, :3, 3], axis=-1)))
        for j, joint in enumerate(m.joints):
            travel = max(abs(self.lower[j]), abs(self.upper[j]))
            if joint.kind == "prismatic":
                b += travel
            elif joint.kind == "screw":
                b += abs(joint.pitch) * travel
        return b

    def configurations(self, i: int) -> np.ndarray:
        """Joint values ``(rows, n)`` of chunk ``i``."""
        return self.box_inputs(i, self.lower, self.upper)

    def evaluate(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """End points, reach, manipulability and condition number at configurations ``q``."""

        T = kinestat.fk(self.model, q)
        J = kinestat.jacobian(self.model, q)
        p = T[..., :3, 3]
        s = np.linalg.svd(task_jacobian(J, p, self.task), compute_uv=False)
        regular = s[..., -1] > SINGULAR_RATIO * s[..., 0]
        cond = np.where(regular, s[..., 0] / np.where(regular, s[..., -1], 1.0), np.nan)
        return {"x": p[..., 0], "y": p[..., 1], "z": p[..., 2],
                "reach": np.linalg.norm(p, axis=-1), "manipulability": np.prod(s, axis=-1),
                "condition": cond}

    def compute_chunk(self, i: int):
        q = self.configurations(i)
        r = self.evaluate(q)
        partial = {
            "points": int(q.shape[0]),
            "singular": int(np.sum(np.isnan(r["condition"]))),
            "reach": red.stats(r["reach"]),
            "manipulability": red.stats(r["manipulability"]),
            "condition": red.stats(r["condition"]),
            "hist_reach": red.histogram(r["reach"], self.reach_edges),
            "hist_manipulability": red.histogram(r["manipulability"], self.manip_edges),
            "hist_condition": red.histogram(r["condition"], self.cond_edges),
            "slice_xy": red.histogram2d(r["x"], r["y"], self.xy_edges, self.xy_edges),
            "slice_xz": red.histogram2d(r["x"], r["z"], self.xy_edges, self.xy_edges),
        }
        rows = {}
        if self.spec["arrays"]:
            rows = {f"q{j + 1}": q[:, j] for j in range(q.shape[1])}
            rows.update(r)
        return rows, partial

    def reduce(self, partials: list[dict]) -> dict:
        reach = red.finish_stats(red.merge_stats([p["reach"] for p in partials]))
        manip = red.finish_stats(red.merge_stats([p["manipulability"] for p in partials]))
        cond = red.finish_stats(red.merge_stats([p["condition"] for p in partials]))
        m = self.model
        return {
            "model": m.name, "joints": m.n, "length_unit": m.length_unit, "task": self.task,
            "mode": self.spec["mode"], "points": sum(p["points"] for p in partials),
            "reach_max": reach["max"], "reach_min": reach["min"], "reach_mean": reach["mean"],
            "reach_bound": self.bound,
            "manipulability": {k: manip[k] for k in ("min", "mean", "max")},
            "condition": {k: cond[k] for k in ("min", "mean", "max")},
            "singular": sum(p["singular"] for p in partials),
            "joint_lower": self.lower.tolist(), "joint_upper": self.upper.tolist(),
            "histograms": {k: red.merge_histograms([p[f"hist_{k}"] for p in partials])
                           for k in ("reach", "manipulability", "condition")},
            "slices": {"edges": self.xy_edges.tolist(),
                       "xy": red.merge_counts([p["slice_xy"] for p in partials]),
                       "xz": red.merge_counts([p["slice_xz"] for p in partials])},
        }

    def plot(self, summary: dict, directory: Path) -> list[str]:
        from kinestat.studies import plots  # lazy: matplotlib only when plotting

        u = summary["length_unit"]
        h = summary["histograms"]
        e = summary["slices"]["edges"]
        name = summary["model"]
        return [
            plots.histogram_png(h["reach"], directory / "reach.png", f"reach ({u})",
                                f"{name}: reach |p|"),
            plots.histogram_png(h["manipulability"], directory / "manipulability.png",
                                "Yoshikawa manipulability", f"{name}: task {self.task}",
                                log_x=True),
            plots.histogram_png(h["condition"], directory / "condition.png",
                                "condition number", f"{name}: task {self.task}", log_x=True),
            plots.slice_png(summary["slices"]["xy"], e, e, directory / "slice_xy.png",
                            f"x ({u})", f"y ({u})", f"{name}: end points projected on xy"),
            plots.slice_png(summary["slices"]["xz"], e, e, directory / "slice_xz.png",
                            f"x ({u})", f"z ({u})", f"{name}: end points projected on xz"),
        ]
