"""The MuJoCo cell stepped in time: the arm's servos, the legs' true law, the contact's truth.

:class:`MujocoPlant` owns one ``MjData`` of a :class:`~kinestat.sim.mujoco_scene.Scene`. Every
step it

* applies each leg's TRUE law (:attr:`Cell.leg_law`, or the platform's linear springs) as the
  force of its tendon actuator, from the tendon's length (a leg bottoming out beyond
  :attr:`Cell.stroke` is an :class:`~kinestat.errors.UnreachableError`, as in the built-in
  simulator);
* drives each joint's position actuator towards the reference (a PI servo: the actuator's
  set point is the reference plus an integral of the error at
  :attr:`SceneParams.servo_integral_hz`, an industrial servo's integral action);
* calls ``mj_step``.

:meth:`MujocoPlant.track` follows a joint reference in time (a move's profile),
:meth:`MujocoPlant.settle` integrates until the platform and the arm are at rest
(:data:`REST_LEG_SPEED`, :data:`REST_JOINT_SPEED`, at most ``max_time``). What the cell's sensors
read is :meth:`joints` (the arm's encoders) and :meth:`leg_lengths` (the legs' encoders); the
contact's truth (``mj_contactForce``) is :meth:`truth`, for logs and reports only.
Lengths leave this module in mm, forces in N; MuJoCo runs in SI.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable

import numpy as np

from kinestat.errors import UnreachableError
from kinestat.hardware.leg_law import tensions_at_lengths
from kinestat.sim.mujoco_scene import M_PER_MM, Scene, length_scale, load_mujoco

__all__ = ["REST_LEG_SPEED", "REST_JOINT_SPEED", "SETTLE_MAX_TIME", "MujocoPlant"]

REST_LEG_SPEED = 0.01
"""At rest: every leg's length changes by at most this (mm/s), i.e. less than a leg count
(0.0254 mm) in 2.5 s."""
REST_JOINT_SPEED = 1e-5
"""At rest: every arm joint moves by at most this (rad/s; model length units/s for a slide)."""
SETTLE_MAX_TIME = 3.0
"""Longest settling after a move (simulated s); the plant reports when it was not at rest."""
_REST_HOLD = 0.02
"""The rest must hold this long (simulated s) to count (a damped ringing passes through zero
speed)."""


class MujocoPlant:
    """One MuJoCo cell in time (thread-safe through :attr:`lock`).

    ``scene``: the compiled cell (:func:`kinestat.sim.mujoco_scene.build_scene`). The arm
    starts at ``scene.q_start`` and the top at ``scene.top_pose_start``, at rest."""

    def __init__(self, scene: Scene) -> None:
        mj = load_mujoco()
        self._mj = mj
        self.scene = scene
        self.model = scene.model
        self.data = mj.MjData(self.model)
        self.lock = threading.RLock()
        ids = scene.ids
        self._qadr = ids["arm_qpos"]
        self._dadr = ids["arm_dof"]
        arm = scene.arm
        self._scale = np.where(arm.prismatic, length_scale(arm), 1.0)
        q0 = np.asarray(scene.q_start, dtype=float) * self._scale
        self.data.qpos[self._qadr] = q0
        T = scene.top_pose_start
        a = ids["top_qpos"]
        self.data.qpos[a:a + 3] = T[:3, 3] * M_PER_MM
        mj.mju_mat2Quat(self.data.qpos[a + 3:a + 7], np.ascontiguousarray(T[:3, :3]).ravel())
        self.ref = q0.copy()
        self._integ = np.zeros(6)
        self._wi = 2.0 * math.pi * scene.params.servo_integral_hz
        cell = scene.cell
        plat = cell.platform
        self._names = plat.leg_names
        self._law = cell.leg_law
        self._k = np.asarray(plat.stiffness, dtype=float)
        self._l0 = np.asarray(plat.free_lengths, dtype=float)
        self._stroke = float(cell.stroke)
        self.error: Exception | None = None
        self.steps = 0
        mj.mj_forward(self.model, self.data)
        self._apply_legs()

    # -- time
    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return float(self.data.time)

    def tensions(self, lengths_mm) -> np.ndarray:
        """The legs' TRUE tensions (N) at ``lengths_mm`` (platform leg order)."""
        L = np.asarray(lengths_mm, dtype=float)
        if self._law is None:
            return self._k * (L - self._l0)
        return tensions_at_lengths(self._law, L, self._names)

    def _apply_legs(self) -> None:
        L = self.data.ten_length[:6] / M_PER_MM
        defl = L - self._l0
        if np.abs(defl).max() > self._stroke:
            worst = int(np.abs(defl).argmax())
            raise UnreachableError(
                f"MuJoCo cell: leg {self._names[worst]} deflects {defl[worst]:+.3f} mm, beyond "
                f"the legs' stroke of ±{self._stroke:g} mm: the platform bottoms out")
        self.data.ctrl[:6] = -self.tensions(L)  # a tendon actuator's force lengthens it

    def step(self, n: int = 1) -> None:
        """``n`` steps with the legs' law and the servos applied (see the module docstring)."""
        mj, m, d = self._mj, self.model, self.data
        dt = m.opt.timestep
        with self.lock:
            for _ in range(int(n)):
                self._apply_legs()
                q = d.qpos[self._qadr]
                self._integ += dt * self._wi * (self.ref - q)
                d.ctrl[6:12] = self.ref + self._integ
                mj.mj_step(m, d)
                self.steps += 1

    def track(self, reference: Callable[[float], np.ndarray], duration: float) -> None:
        """Follow ``reference(t)`` (joints, model units, t from now in s) for ``duration`` s,
        then hold its end value."""
        dt = self.model.opt.timestep
        n = int(math.ceil(max(0.0, duration) / dt))
        for i in range(1, n + 1):
            self.ref = np.asarray(reference(min(i * dt, duration)), dtype=float) * self._scale
            self.step()
        self.ref = np.asarray(reference(duration), dtype=float) * self._scale

    def at_rest(self) -> bool:
        """Every leg's and arm joint's speed below the rest thresholds."""
        d = self.data
        legs = float(np.max(np.abs(d.ten_velocity[:6]))) / M_PER_MM
        joints = float(np.max(np.abs(d.qvel[self._dadr] / self._scale)))
        return legs <= REST_LEG_SPEED and joints <= REST_JOINT_SPEED

    def settle(self, max_time: float = SETTLE_MAX_TIME) -> tuple[float, bool]:
        """Integrate until at rest for :data:`_REST_HOLD` s (at most ``max_time``):
        (simulated seconds taken, at rest)."""
        dt = self.model.opt.timestep
        hold = max(1, int(round(_REST_HOLD / dt)))
        t0, quiet = self.time, 0
        while self.time - t0 < max_time:
            self.step()
            quiet = quiet + 1 if self.at_rest() else 0
            if quiet >= hold:
                return self.time - t0, True
        return self.time - t0, False

    # -- what the sensors read
    def joints(self) -> np.ndarray:
        """The arm's joints (radians; the model's length unit for a slide)."""
        with self.lock:
            return self.data.qpos[self._qadr] / self._scale

    def leg_lengths(self) -> np.ndarray:
        """The legs' lengths (mm, platform leg order)."""
        with self.lock:
            return self.data.ten_length[:6] / M_PER_MM

    def set_reference(self, q) -> None:
        """Hold the joints at ``q`` (model units) from now."""
        with self.lock:
            self.ref = np.asarray(q, dtype=float) * self._scale

    # -- truth (logs and reports only)
    def flange_pose(self) -> np.ndarray:
        """The flange frame in the fixed frame (4, 4), mm."""
        d, s = self.data, self.scene.ids["flange"]
        T = np.eye(4)
        T[:3, :3] = d.site_xmat[s].reshape(3, 3)
        T[:3, 3] = d.site_xpos[s] / M_PER_MM
        return T

    def contact(self) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        """(force of the tool on the workpiece (3,) N, contact point (3,) mm or None, outward
        unit normal of the workpiece or None), summed over the tip's contacts."""
        mj, m, d = self._mj, self.model, self.data
        tip, wp = self.scene.ids["tip"], self.scene.ids["workpiece"]
        total = np.zeros(3)
        point = normal = None
        f6 = np.zeros(6)
        for i in range(d.ncon):
            c = d.contact[i]
            if {int(c.geom1), int(c.geom2)} != {tip, wp}:
                continue
            mj.mj_contactForce(m, d, i, f6)
            frame = np.asarray(c.frame).reshape(3, 3)
            on_geom2 = frame.T @ f6[:3]  # the force geom1 exerts on geom2, fixed frame
            tip_is_1 = int(c.geom1) == tip
            total += on_geom2 if tip_is_1 else -on_geom2
            normal = -frame[0] if tip_is_1 else frame[0]
            point = np.asarray(c.pos) / M_PER_MM
        return total, point, normal

    def truth(self) -> dict:
        """The true state now: ``true_force`` (tool on workpiece, N), ``true_tip`` (mm),
        ``true_normal``, the tool's axis and point, the leg lengths, the simulated time."""
        with self.lock:
            f, point, normal = self.contact()
            T = self.flange_pose()
            tip_site = self.scene.ids["tip_site"]
            tip = self.data.site_xpos[tip_site] / M_PER_MM
            return {
                "plant": "mujoco",
                "true_force": f,
                "true_tip": point,
                "true_normal": normal,
                "tool_force": f,
                "tool_force_magnitude": float(np.linalg.norm(f)),
                "in_contact": point is not None,
                "tip": tip if point is None else point,
                "leg_lengths": self.leg_lengths(),
                "flange_pose": T,
                "sim_time": self.time,
            }
