"""Composition root of ``kinestat control --sim mujoco``: the cell on MuJoCo's physics.

:func:`mujoco_plant` builds the MuJoCo scene of a prepared simulated cell
(:mod:`kinestat.sim.mujoco_scene`: the arm of the controller's model, the platform with its
TRUE leg law, the workpiece) at the start pose, the top resting at its unloaded pose.
:class:`MujocoIO` is the loop's :class:`~kinestat.control.loop.CellIO` on it, sensing only as
the real cell senses:

* a move is planned as the Galil runs it (:func:`kinestat.devices.motion.move_plan` under
  ``--move-rule``: per-axis speeds and accelerations in counts) and followed in time as the
  controller's trapezoidal profiles (:func:`kinestat.sim.dmc.trapezoid`) by the joints' position
  servos; then the plant integrates until the platform and the arm are at rest
  (:meth:`~kinestat.sim.mujoco_plant.MujocoPlant.settle`);
* the robot's counts are its joints through the encoder scales (the arm's axis convention and
  ``axis_deg_per_count``); the leg counts are the tendons' lengths through the leg encoders
  (:class:`~kinestat.sim.sensor.Sensor`: quantised, optional noise) — the controller never
  reads a force from MuJoCo;
* the truth (``mj_contactForce``: ``true_force``, ``true_tip``, ``true_normal``) goes to the
  log and report only.

In process the robot has no axis 4 → 5 coupling (its encoders read its joints): the coupling
and its compensation run on the devices path (:class:`MujocoHarness`, ``--galil/--serial``).
"""

from __future__ import annotations

import math

import numpy as np

from kinestat.control.model import ControlModel
from kinestat.devices.cell_io import SensorSample
from kinestat.devices.galil import THESIS_ACCEL, THESIS_SPEED_MAX
from kinestat.devices.motion import MoveRule, limit_accel, move_plan
from kinestat.errors import DeviceError, KinestatError
from kinestat.robots.puma762.axes import AXIS_DEG_PER_COUNT
from kinestat.serial.fk import fk
from kinestat.sim.contact import Cell
from kinestat.sim.dmc import trapezoid
from kinestat.sim.mujoco_plant import SETTLE_MAX_TIME, MujocoPlant
from kinestat.sim.mujoco_scene import SceneParams, build_scene
from kinestat.sim.sensor import Sensor

__all__ = ["axis_limits", "mujoco_plant", "MujocoIO"]


def axis_limits(model: ControlModel) -> tuple[np.ndarray, np.ndarray]:
    """Per-axis speed and acceleration maxima (counts/s, counts/s²) of the arm's moves: the
    thesis's ``galil_control.m`` maxima for the PUMA 762; for another arm the same angular
    rates as the PUMA's axis A (10 °/s, 10 °/s²) in that arm's counts."""
    res = np.asarray(model.axis_deg_per_count, dtype=float)
    if np.array_equal(res, AXIS_DEG_PER_COUNT):
        return np.asarray(THESIS_SPEED_MAX, float), np.asarray(THESIS_ACCEL, float)
    rate = THESIS_SPEED_MAX[0] * AXIS_DEG_PER_COUNT[0]  # deg/s
    acc = THESIS_ACCEL[0] * AXIS_DEG_PER_COUNT[0]  # deg/s^2
    return rate / res, acc / res


def _into(x: np.ndarray, lo: np.ndarray, hi: np.ndarray, turn: float) -> np.ndarray:
    """Angles ``x`` moved by whole turns into ``[lo, lo + turn)`` where the range is less than
    a turn (a joint that cannot turn fully has one angle for each position)."""
    short = np.isfinite(lo) & np.isfinite(hi) & (hi - lo < turn)
    return np.where(short, lo + np.mod(x - lo, turn), x)


def counts_to_q(model: ControlModel, counts) -> np.ndarray:
    """Joints (radians) of axis ``counts`` through the arm's axis convention, in the chain's
    joint ranges."""
    axis = np.radians(np.asarray(counts, dtype=float) * model.axis_deg_per_count)
    q = np.asarray(model.arm.q_from_axis(axis), dtype=float)
    chain = model.arm.model
    rev = ~np.asarray(chain.prismatic, dtype=bool)
    return np.where(rev, _into(q, chain.lower, chain.upper, 2.0 * np.pi), q)


def q_to_counts(model: ControlModel, q) -> np.ndarray:
    """Axis counts (whole) the encoders read at joints ``q`` (radians), in the axes' ranges."""
    axis = np.degrees(np.asarray(model.arm.axis_from_q(np.asarray(q, dtype=float))))
    lim = np.asarray(model.limits_deg, dtype=float)
    axis = _into(axis, lim[:, 0], lim[:, 1], 360.0)
    return np.rint(axis / model.axis_deg_per_count).astype(np.int64)


def mujoco_plant(cell: Cell, model: ControlModel, start_counts, *,
                 params: SceneParams | None = None, workpiece_stiffness=None) -> MujocoPlant:
    """The MuJoCo plant of ``cell`` carried by ``model.arm`` at ``start_counts``, the top at
    its unloaded pose there."""
    q = counts_to_q(model, start_counts)
    chain = model.arm.model
    T_top = fk(chain, q) @ cell.mount @ cell.platform.home_pose
    scene = build_scene(cell, chain, q, T_top, params=params,
                        workpiece_stiffness=workpiece_stiffness)
    plant = MujocoPlant(scene)
    plant.settle()
    return plant


class MujocoIO:
    """The loop's :class:`~kinestat.control.loop.CellIO` on a :class:`MujocoPlant` (module
    docstring). ``model``: the controller's model (the arm's axis convention and encoder
    scales); ``guard(sent, now)`` checks every command before anything moves;
    ``settle_max``: the longest settling after a move (simulated s)."""

    def __init__(self, plant: MujocoPlant, model: ControlModel, sensor: Sensor, *,
                 move_rule: MoveRule = "coordinated", guard=None, seed: int | None = 0,
                 settle_max: float = SETTLE_MAX_TIME) -> None:
        self.plant = plant
        self.model = model
        self.sensor_model = sensor
        self.move_rule = move_rule
        self._guard = guard
        self._rng = np.random.default_rng(seed)
        self.settle_max = float(settle_max)
        self._vmax, self._amax = axis_limits(model)
        lo, hi = model.limits_deg[:, 0], model.limits_deg[:, 1]
        self._lo, self._hi = lo, hi
        self.stopped = False
        self.moves = 0
        self.move_time = 0.0
        self.settle_time = 0.0
        self.unsettled = 0
        self.t0 = plant.time

    def robot_counts(self) -> np.ndarray:
        """The axis counts the encoders read now."""
        return q_to_counts(self.model, self.plant.joints())

    def _profile(self, now: np.ndarray, plan) -> tuple[callable, float]:
        """The joints' reference in time along the plan's per-axis trapezoids."""
        segs = [trapezoid(float(plan.target[i] - now[i]), float(plan.speed[i]),
                          float(plan.accel[i]), float(plan.decel[i])) for i in range(6)]
        duration = max((sum(s[0] for s in sg) for sg in segs if sg), default=0.0)
        start = now.astype(float)

        def counts_at(t: float) -> np.ndarray:
            out = start.copy()
            for i, sg in enumerate(segs):
                x = v = 0.0
                tau = t
                for dur, a in sg:
                    h = min(tau, dur)
                    x += v * h + 0.5 * a * h * h
                    v += a * h
                    tau -= h
                    if tau <= 0:
                        break
                out[i] += x
            return out

        def reference(t: float) -> np.ndarray:
            c = plan.target.astype(float) if t >= duration else counts_at(t)
            return counts_to_q(self.model, c)

        return reference, duration

    def move(self, axis_counts, accel_limit: float | None = None) -> dict:
        """Plan the move as the Galil would (its accelerations capped by ``accel_limit``,
        :func:`~kinestat.devices.motion.limit_accel`), follow it in time, settle; the plan
        for the log with the simulated seconds of motion and settling."""
        new = np.asarray(axis_counts, dtype=np.int64)
        now = self.robot_counts()
        if self._guard is not None:
            self._guard(new, now)
        axis_deg = new * self.model.axis_deg_per_count
        bad = np.flatnonzero((axis_deg < self._lo - 1e-9) | (axis_deg > self._hi + 1e-9))
        if bad.size:
            i = int(bad[0])
            raise DeviceError(f"MuJoCo cell: axis {i + 1} commanded to {axis_deg[i]:.3f} deg, "
                              f"outside its limits [{self._lo[i]:g}, {self._hi[i]:g}] deg; "
                              "not moved")
        plan = limit_accel(move_plan(self.move_rule, now, new, self._vmax, self._amax), now,
                           accel_limit)
        reference, duration = self._profile(now, plan)
        try:
            self.plant.track(reference, duration)
            t_settle, rested = self.plant.settle(self.settle_max)
        except KinestatError as exc:
            raise DeviceError(f"the MuJoCo cell failed ({type(exc).__name__}): {exc}") from exc
        self.moves += 1
        self.move_time += duration
        self.settle_time += t_settle
        self.unsettled += 0 if rested else 1
        return {"delta_counts": (new - now).tolist(), "speed": plan.speed.tolist(),
                "accel": plan.accel.tolist(), "rule": self.move_rule,
                "sim_move_s": duration, "sim_settle_s": t_settle, "at_rest": rested}

    def sensor(self) -> SensorSample:
        """Leg counts at the present state, through the leg encoders."""
        L = self.plant.leg_lengths()
        try:
            c = self.sensor_model.counts(self.plant.scene.cell.platform, L, self._rng)
        except KinestatError as exc:
            raise DeviceError(f"simulated sensor failed: {exc}") from exc
        return SensorSample(counts=c)

    def stop(self) -> str:
        """Hold the joints where they are."""
        self.stopped = True
        self.plant.set_reference(self.plant.joints())
        return "stopped (MuJoCo, in-process)"

    def truth(self) -> dict:
        """The true state (MuJoCo's contact force; logs and reports only)."""
        t = self.plant.truth()
        T = t.pop("flange_pose")
        t["tool_axis"] = T[:3, 2].copy()
        t["tool_point"] = T[:3, :3] @ self.model.tool_point_6 + T[:3, 3]
        t["joints_deg"] = np.degrees(self.plant.joints())
        t["normal"] = t["true_normal"]
        return t

    def figures(self) -> dict:
        """Simulated time: total, per move, in motion and settling (s)."""
        total = self.plant.time - self.t0
        return {"sim_time_s": total, "sim_move_s": self.move_time,
                "sim_settle_s": self.settle_time, "moves_unsettled": self.unsettled,
                "sim_seconds_per_cycle": total / self.moves if self.moves else math.nan}
