"""The unoptimised per-cycle computations the compiled fast path replaced, kept as the
reference: the tests replay recorded cycles through both and require the same commands
(tests/control/test_cycle_fast.py), and ``benchmarks/control_cycle.py`` times both side by side.

:func:`solve_counts_reference` is the vernier as first written: the forward analysis of all
9·9·9·3·3 = 6561 count vectors with NumPy and ``argmin`` of the cost. The fast path
(:func:`kinestat.control.controller._solve_counts`) searches the same grid with the same cost
in a compiled kernel; both pick the same count vector unless two candidates' costs agree to
the last few bits (the two formulations round differently, ~1e-13 mm).
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator

import numpy as np
from scipy.spatial.transform import Rotation

from kinestat.control import controller, cycle, envelope, follow, predict
from kinestat.control.contact_estimate import cone_normal, friction_sample, path_curvature
from kinestat.control.controller import Target
from kinestat.control.model import ControlModel
from kinestat.control.vernier import q_to_axis_counts, vernier_costs
from kinestat.parallel.kinestatic import compose_twist
from kinestat.parallel.stiffness import stiffness, tip_compliance
from kinestat.serial import puma762
from kinestat.spatial.se3 import twist_exp
from kinestat.spatial.transforms import inv

__all__ = ["solve_counts_reference", "vernier_costs_reference", "UncachedCycleData",
           "reference_cycle"]


def vernier_costs_reference(model: ControlModel, target: Target, c0, counts_now,
                            vernier: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The candidates ``c0 + OFFSETS`` (or ``c0`` alone), their cost and offset along S6: every
    candidate through the NumPy forward analysis (:func:`kinestat.control.vernier.vernier_costs`,
    the formulation the compiled search reproduces)."""
    return vernier_costs(model, target, c0, counts_now, vernier)


def solve_counts_reference(model: ControlModel, target: Target, q_now, counts_now,
                           vernier: bool) -> tuple[np.ndarray, float]:
    """:func:`kinestat.control.controller._solve_counts` as first written (NumPy, all
    candidates): (counts, residual along S6 in mm)."""
    res = puma762.reverse(target.tool_point, target.s6, target.a67, model.tool_point_6)
    sel = puma762.select(res, q_now, model.limits_deg)
    c0 = q_to_axis_counts(model, sel.axis)
    cand, cost, along = vernier_costs_reference(model, target, c0, counts_now, vernier)
    k = int(np.argmin(cost))
    return cand[k], float(along[k])


class UncachedCycleData(cycle.CycleData):
    """:class:`~kinestat.control.cycle.CycleData` that recomputes the stiffness on every use
    (as the decision did before the per-cycle data: once for ``tip_stiffness``, twice in the
    envelope's prediction, once in the follow law)."""

    @property
    def K(self) -> np.ndarray:  # type: ignore[override]
        return stiffness(self.model.platform, self.meas.top_pose, twist_order="axis")

    @property
    def C_tip(self) -> np.ndarray:  # type: ignore[override]
        return tip_compliance(self.model.platform, self.meas.top_pose, self.tip_base,
                              stiffness_axis=self.K)


@contextlib.contextmanager
def reference_cycle() -> Iterator[None]:
    """Run :func:`~kinestat.control.controller.decide` and
    :func:`~kinestat.control.follow.decide_follow` on the unoptimised path inside the block:
    the NumPy vernier and selection (:func:`solve_counts_reference`), the NumPy forward
    analysis for the flange pose, the NumPy stiffness recomputed on every use, the batched
    ``compose_twist`` and ``twist_exp`` in the follow law (not its compiled base twist),
    NumPy's solves and SciPy's rotations in the prediction (and NumPy's in the press's sliding
    prediction of a turn), NumPy's tip compliance and SciPy's
    rotation vector on every motion check; in the follow task's estimator and law the batched
    NumPy ``cone_normal``,
    ``friction_sample`` and ``path_curvature`` (``lstsq``), ``numpy.linalg.norm`` and
    ``numpy.linalg.solve``, ``dataclasses.replace`` and the mount's inverse on every use. Not
    thread-safe (it swaps module attributes)."""
    saved = [(controller, "_puma_move", lambda *a: None),
             (controller, "_solve_counts", solve_counts_reference),
             (controller, "_flange_pose", lambda model, q: puma762.forward(q).pose),
             (predict, "cycle_data", UncachedCycleData),
             (follow, "cycle_data", UncachedCycleData),
             (follow, "_base_twist_fast", lambda *a: None),
             (follow, "compose_twist_line", compose_twist),
             (follow, "twist_exp_one", twist_exp),
             (follow, "cone_normal_one", cone_normal),
             (follow, "friction_sample_one", friction_sample),
             (follow, "path_curvature_one", path_curvature),
             (follow, "norm3", np.linalg.norm),
             (follow, "solve_one", np.linalg.solve),
             (follow, "replace", dataclasses.replace),
             (follow, "mount_inverse", lambda model: inv(model.mount)),
             (predict, "rotvec_matrix_one",
              lambda r: Rotation.from_rotvec(r).as_matrix()),
             (envelope, "_rotation_clear", lambda *a: False),
             (predict, "_predict_fast", lambda *a: None),
             (predict, "_slide_fast", lambda *a: None),
             (envelope, "_measurement_clear", lambda *a: False),
             (envelope, "_command_clear", lambda *a: False)]
    old = [(mod, name, getattr(mod, name)) for mod, name, _ in saved]
    try:
        for mod, name, new in saved:
            setattr(mod, name, new)
        yield
    finally:
        for mod, name, value in old:
            setattr(mod, name, value)
