"""A simulated position-controlled arm: any 6-joint :class:`~kinestat.mechanism.chain.ChainModel`
whose joints are set directly (radians), for the in-process cell of ``kinestat control --arm``.

The stand-in for an arm's own motion controller, not for the PUMA 762's hardware (that is
:mod:`kinestat.sim.dmc`: counts, the axis 4 → 5 coupling, homing): a commanded joint vector is
reached exactly, and one outside the model's joint limits is refused (a
:class:`~kinestat.errors.DeviceError`, as a real controller's fault) — the arm never moves
there. The flange pose is the model's forward kinematics (``T_cell_flange``, lengths in the
model's unit).
"""

from __future__ import annotations

import numpy as np

from kinestat.errors import DeviceError, ModelError
from kinestat.mechanism.chain import ChainModel
from kinestat.serial.fk import fk

__all__ = ["LIMIT_SLACK", "SimulatedArm"]

LIMIT_SLACK = 1e-9
"""Joint-limit tolerance (radians, or model lengths for prismatic joints) of the simulated arm:
rounding of a command that sits exactly on a limit is accepted, nothing more."""


class SimulatedArm:
    """An arm that reaches its commanded joints exactly, within its limits (mutable state).

    >>> import kinestat
    >>> arm = SimulatedArm(kinestat.load("puma560"), np.zeros(6))
    >>> arm.move_to([0.1, 0.2, -0.3, 0.0, 0.5, 0.0]).round(2).tolist()
    [0.1, 0.2, -0.3, 0.0, 0.5, 0.0]
    >>> try:
    ...     arm.move_to([0.0, 0.0, 0.0, 0.0, 3.0, 0.0])
    ... except DeviceError as exc:
    ...     print(str(exc).split(": ")[1])
    joint 5 commanded to 171.887 deg, outside its limits [-100, 100] deg; not moved
    >>> arm.q[4]  # not moved
    np.float64(0.5)
    """

    def __init__(self, model: ChainModel, q_start) -> None:
        if not isinstance(model, ChainModel) or model.n != 6:
            raise ModelError("SimulatedArm: a 6-joint ChainModel is needed")
        self.model = model
        self._q = self._checked(q_start, "placed")

    def _checked(self, q, verb: str) -> np.ndarray:
        q = np.array(q, dtype=float)
        if q.shape != (6,) or not np.all(np.isfinite(q)):
            raise DeviceError(f"simulated arm {self.model.name!r}: expected 6 finite joint "
                              f"values, got {q.tolist()}")
        lo, hi = self.model.lower, self.model.upper
        bad = np.flatnonzero((q < lo - LIMIT_SLACK) | (q > hi + LIMIT_SLACK))
        if bad.size:
            i = int(bad[0])
            rev = not bool(self.model.prismatic[i])
            f = (lambda v: f"{np.degrees(v):g}") if rev else (lambda v: f"{v:g}")
            unit = "deg" if rev else self.model.length_unit
            val = np.degrees(q[i]) if rev else q[i]
            raise DeviceError(f"simulated arm {self.model.name!r}: joint {i + 1} {verb} to "
                              f"{val:.3f} {unit}, outside its limits [{f(lo[i])}, {f(hi[i])}] "
                              f"{unit}; not moved")
        return q

    @property
    def q(self) -> np.ndarray:
        """The joints now (radians; a copy)."""
        return self._q.copy()

    def move_to(self, q) -> np.ndarray:
        """Reach ``q`` (6,) exactly; refuse (DeviceError, nothing moves) outside the limits."""
        self._q = self._checked(q, "commanded")
        return self.q

    def flange_pose(self, q=None) -> np.ndarray:
        """``T_cell_flange`` (4, 4) at ``q`` (default: the joints now)."""
        return fk(self.model, self._q if q is None else np.asarray(q, dtype=float))
