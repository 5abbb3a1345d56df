"""The follow task's control law: Griffis & Duffy's kinestatic decomposition on the estimate.

In the platform base frame, with ``K`` the platform stiffness at the measured top pose and the
contact's wrench line ``W = [ŵ; p × ŵ]`` through the measured tip ``p``, the base (flange) is
displaced by ``T = T_f + K⁻¹ δw`` (:func:`kinestat.parallel.kinestatic.compose_twist`):

* ``T_f``, a twist of freedom (reciprocal to W): the travel ``Δs t̂`` along the tangent plus a
  rotation ``ω`` about the tip, turning S6 onto the lean axis ``−cos θ n̂ + sin θ t̂`` (θ the
  lean past the normal towards the travel: 0 without friction, the friction cone's edge plus
  a margin while the tip slides, growing while a stuck tip holds the travel) and, on a curved
  path, by the surface's own turn ``κ Δs`` about ``n̂ × t̂``;
* ``δw = −Δλ W_c``, the twist of compliance that raises the normal force by
  ``Δλ = gain (|F_req| − F_n)``, ``W_c`` along the friction cone's edge ``n̂ − μ̂ t̂`` once μ̂
  is known (a sliding contact's force changes only along the edge); its tip motion is limited
  to ``max_correction`` along the normal;
* for a sliding contact, whose force stays on the cone's edge in space (it turns with the
  surface by ``ω_s = κ Δs``, not with the base), the wrench change the base's turn
  ``ω − ω_s`` would make in the platform's frame, ``(ω_s − ω) × f``, is compensated (the
  hold), so that the turn does not run the tip ahead in the platform's soft mode.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from kinestat.control.controller import Target
from kinestat.control.cycle import cross3, cycle_data
from kinestat.control.model import ControlModel
from kinestat.control.wrench import Measurement
from kinestat.parallel.kinestatic import compose_twist
from kinestat.spatial.se3 import twist_exp
from kinestat.spatial.transforms import apply_one, inv

if TYPE_CHECKING:
    from kinestat.control.follow.config import FollowConfig

__all__ = ["lean_axis", "lean_of", "turn_towards", "base_twist", "target_of", "accel_limit"]


def lean_axis(n: np.ndarray, t: np.ndarray, lean: float) -> np.ndarray:
    """S6 leaning ``lean`` rad from ``−n̂`` towards the travel ``t̂``."""
    return -math.cos(lean) * n + math.sin(lean) * t


def lean_of(v: np.ndarray, n: np.ndarray, t: np.ndarray) -> float:
    """The lean (rad) of the direction ``v`` from ``−n̂`` towards ``t̂`` (in their plane)."""
    return math.atan2(float(v @ t), -float(v @ n))


def turn_towards(s6: np.ndarray, axis: np.ndarray, limit: float) -> np.ndarray:
    """Rotation vector turning ``s6`` towards ``axis`` by at most ``limit`` rad."""
    c = cross3(s6, axis)
    s = float(np.linalg.norm(c))
    if s < 1e-15:
        return np.zeros(3)
    return c / s * min(math.atan2(s, float(s6 @ axis)), limit)


def base_twist(model: ControlModel, meas: Measurement, tip: np.ndarray, n: np.ndarray,
               omega: np.ndarray, travel: np.ndarray, dF: np.ndarray, limits: tuple,
               stuck: bool, hold: tuple | None) -> np.ndarray:
    """The base's twist (base frame, axis order ``[ω; v_O]``; module docstring).

    ``dF`` (fixed frame) is the change of the force on the workpiece the compliance twist
    makes; a stuck tip takes any force through it (its wrench space is the three forces
    through the tip, the twist of freedom a turn about it), a sliding one only along the
    normal line (``dF`` its normal part plus the friction the slide brings along). The
    compliance part is scaled so that it moves the tip by at most ``limits = (along the
    normal, in all)`` mm. ``hold`` is None or ``(force on the tool to keep, the surface's
    turn ω_s)`` (fixed frame)."""
    TB = meas.base_pose
    R = TB[:3, :3]
    p = R.T @ (tip - TB[:3, 3])
    nb = R.T @ n
    K = cycle_data(model, meas).K
    w = R.T @ omega
    Tf = np.concatenate([w, R.T @ travel - cross3(w, p)])  # the tip moves by `travel`
    df = _limited(K, p, nb, R.T @ dF, limits, stuck)
    dw = np.concatenate([df, cross3(p, df)])
    if stuck:
        basis = np.column_stack([np.concatenate([e, cross3(p, e)]) for e in np.eye(3)])
        T = compose_twist(K, basis, Tf, dw)
    else:
        fn = float(df @ nb)
        W = np.concatenate([nb, cross3(p, nb)])
        T = compose_twist(K, W, Tf, fn * W) + np.linalg.solve(K, dw - fn * W)
    if hold is not None:
        f_tool, w_surf = hold
        dh = cross3(R.T @ w_surf - w, R.T @ f_tool)
        T = T - np.linalg.solve(K, np.concatenate([dh, cross3(p, dh)]))
    return T


def _tip_motion(K: np.ndarray, p: np.ndarray, f: np.ndarray) -> np.ndarray:
    """The tip's motion (base frame) when the base moves by ``K⁻¹ [f; p × f]``."""
    tc = np.linalg.solve(K, np.concatenate([f, cross3(p, f)]))
    return tc[3:] + cross3(tc[:3], p)


def _limited(K: np.ndarray, p: np.ndarray, nb: np.ndarray, df: np.ndarray, limits: tuple,
             stuck: bool) -> np.ndarray:
    """The force change ``df`` (base frame) scaled so that the compliance twist moves the
    tip by at most ``limits[0]`` along the normal and ``limits[1]`` in all: as a whole for a
    sliding contact (its force changes along one line), its normal and tangential parts
    apart for a stuck one (the soft tangential direction would otherwise hold back the
    normal force's correction)."""
    fn = float(df @ nb)
    parts = ((fn * nb, df - fn * nb) if stuck else (df,))
    out = np.zeros(3)
    for f in parts:
        dp = _tip_motion(K, p, f)
        out += f / max(abs(float(dp @ nb)) / limits[0], float(np.linalg.norm(dp)) / limits[1],
                       1.0)
    return out


def target_of(model: ControlModel, meas: Measurement, T_base: np.ndarray) -> Target:
    """The end effector after displacing the base by ``T_base``."""
    TB_new = meas.base_pose @ twist_exp(T_base)
    T6 = TB_new @ inv(model.mount)
    return Target(apply_one(T6, model.tool_point_6), T6[:3, 2].copy(), T6[:3, 0].copy())


def accel_limit(config: FollowConfig, meas: Measurement, T_base: np.ndarray) -> float | None:
    """1/s²: the move's acceleration per unit of travel (:attr:`Command.accel_limit`) that
    keeps the top and the tool within :attr:`FollowTuning.tool_accel`: that over the largest
    displacement of the flange's origin and the tool point when the base moves by the twist
    ``T_base`` (a small rigid motion moves the points between them, the top and the tool, by
    no more); None for a massless top or no motion."""
    a = config.tuning.tool_accel
    if not math.isfinite(a):
        return None
    model = config.base.model
    now = meas.base_pose @ inv(model.mount)
    new = meas.base_pose @ twist_exp(T_base) @ inv(model.mount)
    d = max(float(np.linalg.norm(apply_one(new, p) - apply_one(now, p)))
            for p in (np.zeros(3), model.tool_point_6))
    return a / d if d > 0.0 else None

