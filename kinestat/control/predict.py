"""The plant model the controller chooses its steps with: predictions of the platform's state
after a flange move (the load, the leg deflections, the top's pose), from the measured pose's
stiffness.

:func:`predict` assumes the worst case for a step — the tip pinned where it is (a sticking
contact; a sliding one loads the platform less) — and maps the flange's displacement at the tip
through the platform's point stiffness at the tip, ``K_tip``, the inverse of the tip's
translational compliance computed from the spatial stiffness at the measured pose
(:func:`kinestat.parallel.stiffness.stiffness`, which includes the load terms), plus the
moment of the present load about the moved point of application. Out of contact the same
prediction is the load if the workpiece were met at the very start of the step.
:func:`predict_sliding` lets the tip slide freely instead (a frictionless contact), and
:func:`sliding_force` / :func:`sliding_push` give its force and the force's rate along a push
(the press's step after a turn, :mod:`kinestat.control.align`).

The envelope (:mod:`kinestat.control.envelope`) judges a :class:`Prediction`; it does not make
one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from kinestat.control.cycle import cross3, cycle_data
from kinestat.control.model import ControlModel
from kinestat.control.wrench import Measurement
from kinestat.parallel.stiffness import tip_compliance as platform_tip_compliance
from kinestat.spatial.transforms import apply, apply_one, inv, skew

__all__ = [
    "Prediction",
    "tip_compliance",
    "tip_stiffness",
    "predict",
    "predict_sliding",
    "sliding_force",
    "sliding_push",
]


@dataclass(frozen=True, eq=False)
class Prediction:
    """Predicted state after a command (worst case: the tip pinned where it is).

    Attributes:
        force: (3,) force the tool would apply to the workpiece, fixed frame (N).
        deflections: (6,) leg deflections ``l − l0`` (mm).
        tip_motion: (3,) displacement of the flange-carried point at the tip (mm, fixed frame).
        top_pose: (4, 4) the predicted top pose in the base frame (first order), or None.
    """

    force: np.ndarray
    deflections: np.ndarray
    tip_motion: np.ndarray
    top_pose: np.ndarray | None = None

    @property
    def force_magnitude(self) -> float:
        return float(np.linalg.norm(self.force))


def _tip_base(model: ControlModel, meas: Measurement) -> np.ndarray:
    return apply_one(meas.top_pose, model.tool_tip_top)


def tip_compliance(model: ControlModel, meas: Measurement) -> np.ndarray:
    """Translational compliance of the tool tip (3, 3), base frame, mm/N, at the measured pose:
    :func:`kinestat.parallel.stiffness.tip_compliance` (Vibhute eq. 2-16/2-17)."""
    return platform_tip_compliance(model.platform, meas.top_pose, _tip_base(model, meas))


def tip_stiffness(model: ControlModel, meas: Measurement) -> np.ndarray:
    """Point stiffness of the platform at the tool tip (3, 3), FIXED frame, N/mm.

    The inverse of :func:`tip_compliance` rotated into the fixed frame
    (:func:`kinestat.parallel.stiffness.tip_stiffness`): moving the flange by ``δ`` (at the
    tip) with the tip held changes the tool's force by ``K_tip δ``.
    """
    R = np.asarray(meas.base_pose, dtype=float)[:3, :3]
    # platform_tip_stiffness's R C_tip⁻¹ Rᵀ, with the cycle's C_tip (shared with predict)
    return R @ np.linalg.inv(cycle_data(model, meas).C_tip) @ np.swapaxes(R, -1, -2)


def predict(model: ControlModel, meas: Measurement, flange_pose_new) -> Prediction:
    """Predict force and leg deflections after moving the flange to ``flange_pose_new``.

    Worst case for the load: the tip stays where it is in the fixed frame (pinned, as by a
    sticking contact) while the top may turn about it. In the new base frame the tip sits at
    ``p' = p + u``; the springs must then carry ``[F + δF; p' × (F + δF)]`` with the top's tip at
    ``p'``. To first order, with ``K`` the platform stiffness at the measured pose and ``D`` the
    top's small twist: ``K D = [δF; p × δF + u × F]`` and ``[−[p]×, I] D = u``, so
    ``δF = C_tip⁻¹ (u − [−[p]×, I] K⁻¹ [0; u × F])`` and the legs change by ``jᵀ D``. The
    force on the workpiece, fixed frame, is ``−R' (F + δF)``.
    """
    Tn = np.asarray(flange_pose_new, dtype=float)
    TB_new = Tn @ model.mount
    data = cycle_data(model, meas)  # K, the tip and C_tip at the measured pose, made once
    tip_F = data.tip_fixed
    p = data.tip_base
    u = apply(inv(TB_new), tip_F) - p
    R = meas.base_pose[:3, :3]
    F = -(R.T @ meas.estimate("point"))  # external force on the tip, base frame
    K = data.K
    A = np.vstack([np.eye(3), skew(p)])
    B = np.hstack([-skew(p), np.eye(3)])
    C_tip = data.C_tip
    b = np.concatenate([np.zeros(3), cross3(u, F)])
    dF = np.linalg.solve(C_tip, u - B @ np.linalg.solve(K, b))
    D = np.linalg.solve(K, A @ dF + b)  # top twist [δφ; δx_O] relative to the base
    return _prediction(model, meas, data, Tn, TB_new, F + dF, D)


def _prediction(model: ControlModel, meas: Measurement, data, Tn: np.ndarray,
                TB_new: np.ndarray, F_new: np.ndarray, D: np.ndarray) -> Prediction:
    """The :class:`Prediction` of a move to the flange pose ``Tn`` (base ``TB_new``) after
    which the springs carry the external force ``F_new`` (base frame) and the top has turned
    by the small twist ``D = [δφ; δx_O]`` relative to the base (:func:`predict`,
    :func:`predict_sliding`)."""
    S, _ = data.leg_directions
    dl = np.cross(model.platform.base_points, S) @ D[:3] + S @ D[3:]
    top = np.eye(4)
    Rd = Rotation.from_rotvec(D[:3]).as_matrix()
    top[:3, :3] = Rd @ meas.top_pose[:3, :3]
    top[:3, 3] = Rd @ meas.top_pose[:3, 3] + D[3:]
    tip_F = data.tip_fixed
    return Prediction(force=-(TB_new[:3, :3] @ F_new),
                      deflections=meas.deflections(model) + dl,
                      tip_motion=apply(Tn @ inv(meas.flange_pose), tip_F) - tip_F,
                      top_pose=top)


def _slide(model: ControlModel, meas: Measurement, Tn: np.ndarray, push=None):
    """The first-order frictionless slide of :func:`predict_sliding`: ``(f + δf, n', v, F,
    TB_new, data, rate)``, or None out of contact (|F| ≤ 1e-9 N). ``rate`` is ``d(f + δf)/ds``
    (N/mm) for a further translation ``s`` of the flange along the unit vector ``push`` (fixed
    frame; None: not computed): the slide is linear in the tip's motion ``u``, which such a
    translation changes by ``−s R'ᵀ push``."""
    est = meas.estimate("point")  # force on the workpiece, fixed frame
    f = math.sqrt(float(est @ est))
    if not f > 1e-9:
        return None
    R = meas.base_pose[:3, :3]
    F = -(R.T @ est)  # external force on the tip, base frame
    TB_new = Tn @ model.mount
    Rn = TB_new[:3, :3]
    data = cycle_data(model, meas)
    p = data.tip_base
    u = Rn.T @ (data.tip_fixed - TB_new[:3, 3]) - p  # the pinned tip's motion, new base frame
    n_new = Rn.T @ (-est / f)  # the normal (fixed frame) in the new base frame
    KiZ = np.linalg.solve(data.K, np.vstack([np.zeros((3, 3)), skew(F)]))
    M = np.eye(3) + KiZ[3:] - skew(p) @ KiZ[:3]  # M v = v − B K⁻¹ [0; v × F]
    pick = np.zeros(3)
    pick[int(np.argmin(np.abs(n_new)))] = 1.0
    t1 = cross3(n_new, pick)
    t1 = t1 / math.sqrt(float(t1 @ t1))
    t2 = cross3(n_new, t1)
    C_tip = data.C_tip
    lhs = np.empty((3, 3))
    lhs[:, 0], lhs[:, 1], lhs[:, 2] = M @ t1, M @ t2, -(C_tip @ n_new)
    rhs = C_tip @ (f * n_new - F) - M @ u
    if push is None:
        sol = np.linalg.solve(lhs, rhs)
        rate = None
    else:
        both = np.linalg.solve(lhs, np.stack([rhs, M @ (Rn.T @ push)], axis=1))
        sol, rate = both[:, 0], float(both[2, 1])
    return f + float(sol[2]), n_new, u + sol[0] * t1 + sol[1] * t2, F, TB_new, data, rate


def sliding_force(model: ControlModel, meas: Measurement, flange_pose_new) -> float:
    """|F| (N) after moving the flange to ``flange_pose_new`` with the tip sliding freely:
    :func:`predict_sliding`'s force magnitude without the rest of the prediction (the press's
    step, :func:`kinestat.control.align.turned_force`). Out of contact, :func:`predict`'s."""
    Tn = np.asarray(flange_pose_new, dtype=float)
    out = _slide(model, meas, Tn)
    if out is None:
        return predict(model, meas, Tn).force_magnitude
    return abs(out[0])


def sliding_push(model: ControlModel, meas: Measurement, flange_pose_new,
                 axis) -> tuple[float, float] | None:
    """``(f, k)``: the force magnitude (N) :func:`predict_sliding` gives after moving the flange
    to ``flange_pose_new``, and its rate ``k = df/ds`` (N/mm) for a further translation ``s``
    of the flange along the unit vector ``axis`` (fixed frame): with the tip sliding freely the
    force after the move and a push ``s`` is ``f + k s`` to first order. None out of contact.
    The press's step after a turn (:func:`kinestat.control.align.contact_move`)."""
    Tn = np.asarray(flange_pose_new, dtype=float)
    push = np.asarray(axis, dtype=float)
    out = _slide(model, meas, Tn, push=push)
    if out is None:
        return None
    return out[0], out[6]


def predict_sliding(model: ControlModel, meas: Measurement, flange_pose_new) -> Prediction:
    """Predict the state after moving the flange to ``flange_pose_new`` with the tip SLIDING
    freely (a frictionless contact) on the surface whose normal is the measured force's
    direction: the force stays along that normal in the fixed frame, the tip moves only in the
    tangent plane. (:func:`predict` pins the tip: the worst case for the load of a sticking
    contact; on a frictionless surface met far off the tool axis it overstates the load of a
    turn several times, and understates the top's motion.)

    To first order, with ``M v = v + B K⁻¹ [0; [F]× v]`` the map from the tip's displacement
    ``v`` relative to the top (base frame) to ``C_tip δF`` (:func:`predict`'s relation
    ``M u = C_tip δF``): the tip's displacement is ``u + T τ`` (``u`` as for the pinned tip,
    ``T`` (3, 2) the tangent plane of the normal ``n'`` in the new base frame) and the force
    ``(f + δf) n'``, so ``[M T, −C_tip n'] [τ; δf] = C_tip (f n' − F) − M u``. Out of contact
    (|F| below 1e-9 N) it returns :func:`predict`'s (pinned) prediction.
    """
    Tn = np.asarray(flange_pose_new, dtype=float)
    out = _slide(model, meas, Tn)
    if out is None:
        return predict(model, meas, Tn)
    f_new, n_new, v, F, TB_new, data, _ = out
    p = data.tip_base
    dF = f_new * n_new - F
    A = np.vstack([np.eye(3), skew(p)])
    D = np.linalg.solve(data.K, A @ dF + np.concatenate([np.zeros(3), cross3(v, F)]))
    return _prediction(model, meas, data, Tn, TB_new, F + dF, D)
